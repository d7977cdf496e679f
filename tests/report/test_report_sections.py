"""The report's sections against independent numbers, and the Couette/3D plumbing through their contracts.

Oracles: oracles.md (RET critical box sizes), the DEM file's own Enskog-with-Sonine ratio column
(README: A_E equals ζ0 = ν0ζ0* of RET with CS χ), the closed-form thresholds against the
eigenvalues of the full matrix, and manufactured solver outputs whose errors are known exactly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from ktgf import get_model
from ktgf.hcs import stability_map
from ktgf.hcs.haff import haff_temperature
from ktgf.report import ReportSettings, build_report, check_report, cooling_gas, couette, locate_data_dir
from ktgf.data import COUETTE, HCS_COOLING, read_table
from ktgf.report.hcs import compare_pair, cooling_comparison, dispersion, ret_proposed_sentence


@pytest.fixture(scope="module")
def dem_dir():
    found, why = locate_data_dir(None)
    if found is None:
        pytest.skip(why)
    return found


# oracles.md, "HCS critical box sizes, RET with CS χ"
ORACLE_RET = {(0.9, 0.1): (28.499, 51.216), (0.9, 0.2): (15.485, 30.262), (0.9, 0.3): (12.101, 23.987),
              (0.9, 0.4): (10.846, 21.029), (0.7, 0.1): (17.400, 28.084), (0.7, 0.3): (6.847, 12.354),
              (0.7, 0.5): (5.741, 9.853)}



def copy_of(report, tmp_path):
    import shutil

    shutil.copytree(report.out, tmp_path / "r")
    return tmp_path / "r"


@pytest.mark.published
def test_report_stability_data_reproduce_oracle_box_sizes(quick_report) -> None:
    """The netCDF behind the report's stability map holds the oracle critical sizes (grid step 0.01 hits them)."""
    rep = quick_report
    assert rep.results and ReportSettings.preset(quick=True).stability_e == (0.7, 0.9)
    hcs = next(r for r in rep.results if r.key == "hcs")
    nc = next(f.data for f in hcs.figures if f.file.endswith("stability_map.png"))
    with xr.open_dataset(rep.out / nc) as ds:
        for (e, phi), (lp, ll) in ORACLE_RET.items():
            got = ds.sel(model="ret", e=e).sel(phi=phi, method="nearest")
            assert float(got.phi) == pytest.approx(phi, abs=1e-12)
            assert float(got.L_perp) == pytest.approx(lp, abs=1.5e-3)
            assert float(got.L_par) == pytest.approx(ll, abs=1.5e-3)


@pytest.mark.analytic
def test_eigenvalue_threshold_matches_closed_form() -> None:
    ds = dispersion(("enskog", "ret", "visc-div", "proposed"), 0.3, 0.9, 60)
    np.testing.assert_allclose(ds.k_par_eigen, ds.k_par, rtol=1e-9)
    np.testing.assert_allclose(ds.k_perp_eigen, ds.k_perp, rtol=1e-9)
    # transverse rate at k = 0 is ζ0*/2 (model.md §8)
    for i, n in enumerate(ds.model.values):
        assert float(ds.s_perp[i, 0]) == pytest.approx(0.5 * float(get_model(str(n)).reduced(0.3, 0.9).zeta0))


@pytest.mark.dem
def test_ret_cooling_rate_matches_the_dem_files_enskog_column(dem_dir) -> None:
    t = read_table(dem_dir / HCS_COOLING).as_dict()
    cmp = cooling_comparison(("ret",), t)
    # ratio_early = A_DEM/A_E with A_E = ζ0 of RET with CS χ (data README) → A_RET/A_DEM − 1 = 1/ratio_early − 1
    np.testing.assert_allclose(cmp.error_early.sel(model="ret"), 1.0 / t["ratio_early"] - 1.0, atol=3e-4)


@pytest.mark.analytic
def test_ret_and_proposed_critical_sizes_agree_where_their_rdfs_do() -> None:
    ds = stability_map(("ret", "proposed"), np.linspace(0.02, 0.6, 59), [0.7, 0.9])  # φ step 0.01
    c = compare_pair(ds, "ret", "proposed")
    phi_f = get_model("proposed").rdf.phi_f  # χ_vd equals Carnahan–Starling below φ_f (model.md §2)
    assert c["L_perp"]["first_phi_differing"] >= phi_f - 0.011
    assert c["L_par"]["first_phi_differing"] >= phi_f - 0.011
    assert c["proposed_all_finite"] and c["proposed_vortex_first"]
    assert "keeps the ability to predict the instabilities" in ret_proposed_sentence(c, [0.02, 0.6], [0.7, 0.9])
    broken = {**c, "proposed_all_finite": False}
    sentence = ret_proposed_sentence(broken, [0.02, 0.6], [0.7, 0.9])
    assert "keeps" not in sentence and "does not predict" in sentence


# -- Couette and 3D sections through their contracts (manufactured solver outputs) ---------------
def _enable(monkeypatch, key: str, fake) -> None:
    """Replace the solver entry point a section calls by ``fake`` (the sections import it by name)."""
    if key == "couette":
        monkeypatch.setattr(couette, "report_profiles", fake)
    else:
        from ktgf.report import cooling_gas

        monkeypatch.setattr(cooling_gas, "report_cooling_run", fake)


@pytest.mark.analytic
def test_couette_section_errors_of_a_known_solution(monkeypatch, tmp_path, dem_dir, quick_report) -> None:
    dem = read_table(dem_dir / COUETTE).as_dict()
    calls = []
    shift = 0.05  # the manufactured velocity is the DEM's plus 5 % of U: RMS(u − u_DEM)/U = 0.05 exactly

    def fake(model, *, phi_mean, e, height, wall_speed, d, rho_s, n_cells, dem_path=None):
        calls.append(dict(phi_mean=phi_mean, e=e, height=height, wall_speed=wall_speed, d=d, rho_s=rho_s, n_cells=n_cells))
        return xr.Dataset({"u": ("y", dem["ux"] + shift * wall_speed), "phi": ("y", dem["phi"]), "theta": ("y", dem["theta"])},
                          coords={"y": dem["y"]}, attrs={"wall": "manufactured", "valid": 1})

    _enable(monkeypatch, "couette", fake)
    out = copy_of(quick_report, tmp_path)
    (out / ".cache" / "couette.json").unlink(missing_ok=True)  # the real solver's result is cached there
    rep = build_report(ReportSettings.preset(quick=True, out=out))
    assert rep.statuses["couette"] == "computed" and rep.problems == []
    assert rep.statuses["hcs"] == "cached"
    assert calls[0] == dict(phi_mean=0.5, e=0.9, height=19.0, wall_speed=10.0, d=1.0, rho_s=6 / math.pi, n_cells=40)
    errs = next(r for r in rep.results if r.key == "couette").numbers["couette_errors"]
    for n in ("enskog", "ret", "visc-div", "proposed"):
        assert errs[n]["u_rms_over_U"] == pytest.approx(shift, rel=1e-12)
        assert errs[n]["phi_rms"] == pytest.approx(0.0, abs=1e-15)
        assert errs[n]["theta_rms_rel"] == pytest.approx(0.0, abs=1e-15)
    assert "couette_profiles.png" in (rep.out / "index.html").read_text()


@pytest.mark.contract
def test_cooling_gas_section_through_its_contract(monkeypatch, tmp_path, quick_report) -> None:
    calls = []

    def fake(model, *, phi, e, box, n_cells, t_end, seed, d, rho_s, theta0):
        calls.append((model.name, box))
        t = np.linspace(0.0, t_end, 30)
        zeta = float(model.reduced(phi, e).zeta0)
        x = (np.arange(n_cells) + 0.5) * box / n_cells
        return xr.Dataset(
            {"theta_mean": ("time", theta0 * haff_temperature(t, 1.0, 2.0 / zeta)), "flow_energy": ("time", 1e-3 * np.exp(-t / t_end)),
             "phi_std": ("time", 1e-3 + 0 * t), "phi_slice": (("x", "y"), phi + 0.01 * np.sin(x)[:, None] + 0 * x[None, :]),
             "ux_slice": (("x", "y"), np.zeros((n_cells, n_cells))), "uy_slice": (("x", "y"), np.ones((n_cells, n_cells)))},
            coords={"time": t, "x": x, "y": x},
        )

    _enable(monkeypatch, "cooling_gas", fake)
    out = copy_of(quick_report, tmp_path)
    (out / ".cache" / "cooling_gas.json").unlink(missing_ok=True)  # the real solver's result is cached there
    s = ReportSettings.preset(quick=True, out=out)
    rep = build_report(s)
    assert rep.statuses["cooling_gas"] == "computed" and rep.problems == [], rep.problems
    assert check_report(rep.out) == []
    for name in ("ret", "proposed"):
        b = cooling_gas.boxes(name, s)
        assert (name, b["below"]) in calls and (name, b["above"]) in calls
        from ktgf.hcs import critical_box_size, critical_wavenumbers

        kp, kl = critical_wavenumbers(get_model(name).reduced(s.cooling_phi, s.cooling_e))
        assert b["below"] == pytest.approx(0.7 * float(critical_box_size(s.cooling_phi, kp)))
        assert b["above"] == pytest.approx(1.4 * float(critical_box_size(s.cooling_phi, kl)))
    runs = next(r for r in rep.results if r.key == "cooling_gas").numbers["cooling_runs"]
    assert all(v["haff_max_dev"] < 1e-12 for v in runs.values())  # the manufactured θ is Haff's law exactly
    assert all(v["flow_growth"] == pytest.approx(math.exp(-1.0), rel=1e-12) for v in runs.values())
