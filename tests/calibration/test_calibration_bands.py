"""Prediction bands (delta method): the JAX Jacobian against central differences, σ = √(J C Jᵀ), the commands.

Oracles: central differences of the closed forms at re-built models (not the JAX code), the
covariance written by ``ktgf calibrate``, and for Couette cells re-solved cells.
"""

from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest
from typer.testing import CliRunner

from ktgf import get_model
from ktgf.calibration import read_data
from ktgf.calibration.bands import SHEAR_BAND_COLUMNS, couette_bands, delta_sigma, shear_bands
from ktgf.calibration.model_file import load_model_file
from ktgf.cli import app
from ktgf.shear.steady import steady_shear

runner = CliRunner()


def _columns(model, phi, e):
    """The banded columns point by point (a friction part solves its rotational balance for one e at a time)."""
    out = []
    for p, q in zip(phi, e):
        s = steady_shear(model, np.array([p]), float(q))
        out.append([s.T[0], s.eta_star[0], s.eta_over_eta0[0], s.p_over_nT[0], s.astar[0], s.tau_over_p[0], s.L_over_d[0],
                    p * s.p_over_nT[0] * s.T[0]])
    return np.array(out).T


@pytest.mark.analytic
def test_delta_sigma_is_the_diagonal_of_j_c_jt():
    rng = np.random.default_rng(3)
    J = rng.normal(size=(5, 3))
    A = rng.normal(size=(3, 3))
    C = A @ A.T
    np.testing.assert_allclose(delta_sigma(J, C), np.sqrt(np.diag(J @ C @ J.T)), rtol=1e-12)


@pytest.mark.parametrize("method", ["jax", "differences"])
@pytest.mark.parametrize("model, names", [("dense", ["exponent", "c"]), ("proposed", ["phi_f", "phi_c", "beta"]),
                                          ("frictional", ["c"])])
@pytest.mark.analytic
def test_shear_band_matches_central_differences(model, names, method):
    m = get_model(model)
    phi, e = np.array([0.3, 0.5, 0.55]), np.array([0.7, 0.9])
    rng = np.random.default_rng(0)
    A = rng.normal(size=(len(names), len(names))) * 1e-3
    C = A @ A.T
    bands, used = shear_bands(m, names, C, phi, e, method=method)
    assert used == method
    phis, es = (a.ravel() for a in np.meshgrid(phi, e, indexing="ij"))
    x = {n: float(m.options()[n]) for n in names}
    J = np.empty((len(SHEAR_BAND_COLUMNS), phis.size, len(names)))
    for j, n in enumerate(names):
        h = 1e-6 * abs(x[n])
        J[:, :, j] = (_columns(m.with_options(**{n: x[n] + h}), phis, es) - _columns(m.with_options(**{n: x[n] - h}), phis, es)) / (2 * h)
    for i, k in enumerate(SHEAR_BAND_COLUMNS):
        np.testing.assert_allclose(bands[k], delta_sigma(J[i], C), rtol=1e-5, atol=1e-12, err_msg=k)


@pytest.fixture(scope="module")
def fitted(tmp_path_factory, data_dir):
    d = tmp_path_factory.mktemp("bands")
    out = d / "fit.toml"
    r = runner.invoke(app, ["calibrate", "--model", "dense", "--data", str(data_dir / "dem_uniform_shear.csv"), "--data",
                            str(data_dir / "dem_uniform_shear_extra.csv"), "--fit", "exponent,c", "--out", str(out)])
    assert r.exit_code == 0, r.output
    return out


@pytest.mark.contract
def test_model_file_holds_the_covariance(fitted):
    fit = tomllib.loads(fitted.read_text())["fit"]
    se, corr, cov = np.array(fit["standard_errors"]), np.array(fit["correlation"]), np.array(fit["covariance"])
    np.testing.assert_allclose(cov, corr * np.outer(se, se), rtol=1e-10)
    names, c = load_model_file(fitted).covariance()
    assert names == ["exponent", "c"]
    np.testing.assert_allclose(c, cov)


@pytest.mark.contract
def test_older_model_file_without_covariance_rebuilds_it(fitted, tmp_path):
    text = "\n".join(ln for ln in fitted.read_text().splitlines() if not ln.startswith("covariance"))
    f = tmp_path / "old.toml"
    f.write_text(text)
    fit = tomllib.loads(fitted.read_text())["fit"]
    _, c = load_model_file(f).covariance()
    np.testing.assert_allclose(c, np.array(fit["covariance"]), rtol=1e-10)


@pytest.mark.contract
def test_shear_prints_bands_for_the_model_file_rows(fitted):
    r = runner.invoke(app, ["shear", "--model", "dense", "--model-file", str(fitted), "--phi", "0.5,0.58", "--e", "0.9",
                            "--format", "json"])
    assert r.exit_code == 0, r.output
    rows = json.loads(r.stdout)
    assert [row["model"] for row in rows] == ["dense", "dense", "dense-calibrated", "dense-calibrated"]
    assert all(row["T_sd"] is None for row in rows[:2])  # registered model: no covariance, NaN -> null
    names, C = load_model_file(fitted).covariance()
    m = load_model_file(fitted).model
    x = {n: float(m.options()[n]) for n in names}
    phi = np.array([0.5, 0.58])
    J = np.empty((phi.size, len(names)))
    for j, n in enumerate(names):
        h = 1e-6 * x[n]
        J[:, j] = (steady_shear(m.with_options(**{n: x[n] + h}), phi, 0.9).p_over_nT
                   - steady_shear(m.with_options(**{n: x[n] - h}), phi, 0.9).p_over_nT) / (2 * h)
    np.testing.assert_allclose([row["p_over_nT_sd"] for row in rows[2:]], delta_sigma(J, C), rtol=1e-5)
    assert all(row["p_over_nT_sd"] > 0 for row in rows[2:])
    assert "delta method" in r.stderr


@pytest.mark.analytic
def test_couette_band_matches_resolved_cells(data_dir):
    """∂(τ_w, p_w)/∂β of the DEM cell with the specularity re-fitted to the slip: against re-solved, re-fitted cells.

    Holding the specularity fixed instead gives a derivative ~15 % smaller, so the tolerance separates the two.
    """
    from ktgf.couette.compare import calibrate_specularity, wall_stresses

    dem = read_data(data_dir / "dem_couette_e0.9_phi0.50.csv")
    m = get_model("proposed", beta=2.0)  # the viscosity-divergence RDF of the issue-9 dense, β as option
    n = 80
    spec, _ = calibrate_specularity(m, dem, n_cells=n)
    sd = couette_bands(m, ["beta"], np.array([[1.0]]), dem, specularity=spec, slip_fitted=True, n_cells=n)
    h = 0.02
    out = []
    for b in (2.0 + h, 2.0 - h):
        mb = get_model("proposed", beta=b)
        _, ds = calibrate_specularity(mb, dem, n_cells=n)
        out.append(wall_stresses(ds))
    d_tau, d_p = (np.array(out[0]) - np.array(out[1])) / (2 * h)
    assert sd["tau_wall"] == pytest.approx(abs(d_tau), rel=2e-3)
    assert sd["p"] == pytest.approx(abs(d_p), rel=2e-3)
    fixed = couette_bands(m, ["beta"], np.array([[1.0]]), dem, specularity=spec, slip_fitted=False, n_cells=n)
    assert fixed["tau_wall"] != pytest.approx(sd["tau_wall"], rel=0.05)
    assert math.isfinite(sd["tau_wall"]) and sd["tau_wall"] > 0


@pytest.mark.contract
def test_couette_compare_prints_bands_for_the_model_file(fitted, data_dir, tmp_path):
    dem = data_dir / "dem_couette_e0.9_phi0.50.csv"
    r = runner.invoke(app, ["couette", "compare", "--dem", str(dem), "--model", "ret", "--model-file", str(fitted),
                            "--cells", "60", "-o", str(tmp_path / "c.png"), "--format", "json"])
    assert r.exit_code == 0, r.output
    ret, own = json.loads(r.stdout)
    assert ret["tau_wall_sd"] is None and ret["p_sd"] is None
    names, C = load_model_file(fitted).covariance()
    sd = couette_bands(load_model_file(fitted).model, names, C, read_data(dem), specularity=own["specularity"],
                       slip_fitted=True, n_cells=60)
    assert own["tau_wall_sd"] == pytest.approx(sd["tau_wall"], rel=1e-6) and own["tau_wall_sd"] > 0
    assert own["p_sd"] == pytest.approx(sd["p"], rel=1e-6)
    assert "specularity follows the parameters" in r.stderr


@pytest.mark.analytic
def test_fallback_through_the_rows_gives_the_same_jacobian(monkeypatch):
    """A model the vectorised paths cannot evaluate falls back to checked evaluations, one e at a time (mixed e)."""
    from ktgf.calibration import bands

    m = get_model("frictional")
    phi, e = np.array([0.3, 0.5, 0.4]), np.array([0.7, 0.9, 0.7])
    J, used = bands.shear_jacobian(m, ["c"], phi, e)
    assert used == "jax"

    def fail(*args, **kwargs):
        raise TypeError("not traceable")

    monkeypatch.setattr(bands, "_vectorised_jacobian", fail)
    Jf, used = bands.shear_jacobian(m, ["c"], phi, e)
    assert used == "central differences, point by point"
    np.testing.assert_allclose(Jf, J, rtol=1e-6, atol=1e-12)
