"""Stability maps: values, structure, metadata, netCDF, and identical results on executors (process pool, Dask)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ktgf import InputError, get_model
from ktgf.closures import PAPER_MODELS
from ktgf.hcs import critical_box_size, critical_wavenumbers_eig, stability_map
from ktgf.io import write_netcdf

PHI = np.linspace(0.02, 0.68, 34)
E = np.linspace(0.5, 0.99, 9)


@pytest.fixture(scope="module")
def in_process():
    return stability_map(PAPER_MODELS, PHI, E)


def _values(ds):
    return {name: ds[name].values for name in ("k_perp", "k_par", "L_perp", "L_par")}


def _assert_same(a, b):
    for name, v in _values(a).items():
        np.testing.assert_array_equal(v, b[name].values, err_msg=name)
    assert list(a["model"].values) == list(b["model"].values)


@pytest.mark.contract
def test_map_structure_and_metadata(in_process):
    ds = in_process
    assert ds["L_perp"].dims == ("model", "phi", "e")
    assert ds.sizes == {"model": 4, "phi": PHI.size, "e": E.size}
    assert list(ds["model"].values) == list(PAPER_MODELS)
    assert ds["L_par"].attrs["units"] == "1" and "particle diameters" in ds["L_par"].attrs["long_name"]  # CF: "d" is a day
    assert ds.attrs["ktgf_version"]
    params = json.loads(ds.attrs["parameters"])
    assert params["phi"]["n"] == PHI.size and params["models"] == list(PAPER_MODELS)
    models = json.loads(ds.attrs["models"])
    assert models["visc-div"]["rdf"].startswith("torquato") and "model_options" in models["ret"]


@pytest.mark.analytic
def test_map_values_match_the_eigenvalue_thresholds(in_process):
    """Spot checks of the vectorised closed form against root-finding on the eigenvalues."""
    for name in PAPER_MODELS:
        sel = in_process.sel(model=name)
        phi = PHI[[1, 10, 18]]
        e = E[[0, 4, 8]]
        k_perp, k_par = critical_wavenumbers_eig(get_model(name).reduced(phi, e))
        np.testing.assert_allclose(
            [float(sel["L_perp"].sel(phi=p, e=x)) for p, x in zip(phi, e)], critical_box_size(phi, k_perp), rtol=1e-10
        )
        np.testing.assert_allclose(
            [float(sel["L_par"].sel(phi=p, e=x)) for p, x in zip(phi, e)], critical_box_size(phi, k_par), rtol=1e-10
        )


@pytest.mark.contract
def test_states_beyond_the_packing_limit_are_nan(in_process):
    for name in PAPER_MODELS:
        beyond = PHI >= get_model(name).phi_max
        assert beyond.any() == (get_model(name).phi_max < 1)
        l_perp = in_process["L_perp"].sel(model=name).values
        assert np.isnan(l_perp[beyond]).all() and np.isfinite(l_perp[~beyond]).all()
    assert np.isnan(in_process["L_par"].sel(model="visc-div", phi=0.68).values).all()


@pytest.mark.contract
def test_chunked_with_progress_is_identical(in_process):
    calls = []
    ds = stability_map(PAPER_MODELS, PHI, E, progress=lambda done, total: calls.append((done, total)), phi_chunks=5)
    _assert_same(in_process, ds)
    assert calls[-1] == (20, 20) and len(calls) == 20  # 4 models x 5 blocks


@pytest.mark.contract
def test_process_pool_gives_identical_results(in_process):
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as ex:
        ds = stability_map(PAPER_MODELS, PHI, E, executor=ex)
    _assert_same(in_process, ds)


@pytest.mark.contract
def test_dask_local_cluster_gives_identical_results(in_process):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            ds = stability_map(PAPER_MODELS, PHI, E, executor=client, phi_chunks=4)
    _assert_same(in_process, ds)


@pytest.mark.contract
def test_netcdf_round_trip(in_process, tmp_path):
    import xarray as xr

    back = xr.load_dataset(write_netcdf(in_process, tmp_path / "sub" / "map.nc"))
    _assert_same(in_process, back)
    assert back.attrs["models"] == in_process.attrs["models"]
    assert list(back["model_label"].values) == ["Enskog", "RET", "Visc.div.", "Proposed"]


@pytest.mark.analytic
def test_unstable_everywhere_and_elastic_states_are_marked():
    ds = stability_map(["ret"], [0.1], [0.1, 1.0]).squeeze()
    assert float(ds["L_par"].sel(e=0.1)) == 0.0 and np.isinf(float(ds["k_par"].sel(e=0.1)))
    assert np.isinf(float(ds["L_perp"].sel(e=1.0))) and np.isinf(float(ds["L_par"].sel(e=1.0)))


@pytest.mark.contract
@pytest.mark.parametrize(
    "args,match",
    [
        ((PAPER_MODELS, [0.0, 0.1], E), "phi = 0 is out of range"),
        ((PAPER_MODELS, [0.1, 1.2], E), "phi = 1.2"),
        ((PAPER_MODELS, PHI, [0.0]), "e = 0 is out of range"),
        (([], PHI, E), "at least one model"),
        ((PAPER_MODELS, [[0.1]], E), "1-D"),
    ],
)
def test_bad_input(args, match):
    with pytest.raises(InputError, match=match):
        stability_map(*args)


@pytest.mark.contract
def test_unknown_model_is_named():
    from ktgf import UnknownModelError

    with pytest.raises(UnknownModelError, match="'nope'"):
        stability_map(["nope"], PHI, E)


@pytest.mark.contract
def test_user_model_objects_run_on_a_process_pool():
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from ktgf.closures import Lun1984, MaAhmadi, Model

    mine = Model("lun-omega-ma", Lun1984(omega="lun"), MaAhmadi())
    local = stability_map([mine, "ret"], PHI[:10], E)
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as ex:
        _assert_same(local, stability_map([mine, "ret"], PHI[:10], E, executor=ex))
    assert "ma-ahmadi" in json.loads(local.attrs["models"])["lun-omega-ma"]["rdf"]
