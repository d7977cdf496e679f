"""Steady inclined layer (chute): force balance, first integral, grid convergence, input errors, Jacobian."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf.closures import list_models
from ktgf.couette.chute import InclinedLayer, bagnold_start, build_chute, solve_chute
from ktgf.couette.run import Material
from ktgf.couette.walls import Wall
from ktgf.errors import InputError

MAT = Material(d=1e-3, rho_s=2500.0, e=0.9)
ANGLE = 19.0
TAN = math.tan(math.radians(ANGLE))


def _layer(model, n, **kw):
    return solve_chute(model, depth=0.03, angle_deg=ANGLE, mean_phi=0.3, material=MAT, n_cells=n, **kw)


def _first_integral_error(ds):
    """max |τ − tan ζ (p − p(H))| / (tan ζ p(0)) over the interior nodes (τ = η du/dy at the nodes)."""
    r = np.abs(ds["shear_stress"].values - TAN * (ds["p"].values - ds["p"].values[-1])) / (TAN * ds["p"].values[0])
    return float(r[1:-1].max())


# Frictionless models: `frictional` (stress ratio 0.6-0.7 in dense flow, above tan 19° = 0.34) has
# no steady layer found at this angle (Newton and pseudo-transient both fail; docs/chute.md).
@pytest.mark.analytic
@pytest.mark.parametrize("model", [m.name for m in list_models() if m.friction.key == "none"])
def test_column_carries_its_weight(model):
    """Base traction = ρ_s g sin ζ × solid depth, p(0) − p(H) = ρ_s g cos ζ × solid depth, energy closes."""
    ds = _layer(model, 32)
    a = ds.attrs
    weight = MAT.rho_s * 9.81 * a["solid_depth"]
    assert a["solid_depth"] == pytest.approx(0.3 * 0.03, rel=1e-12)  # inventory held
    assert ds["wall_shear_stress"].values[0] == pytest.approx(weight * math.sin(math.radians(ANGLE)), rel=1e-9)
    assert ds["p"].values[0] - ds["p"].values[-1] == pytest.approx(weight * math.cos(math.radians(ANGLE)), rel=1e-9)
    assert abs(ds["wall_shear_stress"].values[1]) < 1e-12 * weight  # free surface: no shear traction
    assert a["energy_budget_relative_error"] < 1e-9
    assert _first_integral_error(ds) < 0.03  # τ/(p − p(H)) = tan ζ, to the O(h²) error of 32 cells


@pytest.mark.analytic
def test_first_integral_and_fields_converge_at_second_order():
    """τ/(p − p(H)) → tan ζ pointwise, and u, θ, φ converge at second order on nested grids (RET)."""
    runs = {n: _layer("ret", n) for n in (16, 32, 64, 128)}
    err = [_first_integral_error(runs[n]) for n in (32, 64, 128)]
    assert err[2] < 5e-4
    assert math.log2(err[0] / err[2]) / 2 > 1.5
    for name in ("u", "theta", "phi"):
        ref = runs[128][name].values
        e = [np.abs(runs[n][name].values - ref[:: 128 // n]).max() / np.abs(ref).max() for n in (16, 32)]
        assert math.log2(e[0] / e[1]) > 1.7, (name, e)


@pytest.mark.contract
def test_bad_inputs_name_the_field():
    with pytest.raises(InputError, match="angle_deg"):
        InclinedLayer(0.03, 90.0)
    with pytest.raises(InputError, match="column depth"):
        InclinedLayer(-1.0, 20.0)
    with pytest.raises(InputError, match="free surface"):
        build_chute("ret", InclinedLayer(0.03, 20.0), 0.3, MAT, top=Wall(momentum="prescribed", energy="adiabatic"))
    with pytest.raises(InputError, match="mean_phi"):
        build_chute("ret", InclinedLayer(0.03, 20.0), 1.2, MAT)


@pytest.mark.analytic
def test_chute_jacobian_matches_directional_derivatives():
    """The coloured Jacobian also sees the body force and the difference form of the normal balance."""
    pr = build_chute("proposed", InclinedLayer(0.03, 20.0), 0.3, MAT, n_cells=24)
    rng = np.random.default_rng(3)
    X = bagnold_start(pr) + 0.05 * rng.standard_normal(3 * pr.n)
    J = pr.jacobian(X, pr.residual(X))
    for _ in range(3):
        v = rng.standard_normal(X.size)
        fd = (pr.residual(X + 1e-5 * v) - pr.residual(X - 1e-5 * v)) / 2e-5
        np.testing.assert_allclose(J @ v, fd, rtol=1e-4, atol=1e-6 * np.abs(fd).max())


@pytest.mark.contract
def test_cli_writes_the_layer_and_refuses_bad_input(tmp_path):
    """``ktgf chute`` writes a netCDF whose base traction is the weight; a bad angle exits 2 with the field named."""
    import xarray as xr
    from typer.testing import CliRunner

    from ktgf.cli import app

    runner = CliRunner()
    out = tmp_path / "chute.nc"
    res = runner.invoke(app, ["chute", "--model", "proposed,enskog", "--depth", "0.02", "--angle", "20", "--mean-phi",
                              "0.3", "--cells", "24", "--out", str(out), "--format", "json"])
    assert res.exit_code == 0, res.output
    weight = 2500.0 * 9.81 * math.sin(math.radians(20.0)) * 0.3 * 0.02
    for name in ("proposed", "enskog"):
        with xr.open_dataset(tmp_path / f"chute_{name}.nc") as ds:
            assert ds.attrs["model"] == name
            assert float(ds["wall_shear_stress"][0]) == pytest.approx(weight, rel=1e-9)
    bad = runner.invoke(app, ["chute", "--depth", "0.02", "--angle", "0", "--mean-phi", "0.3"])
    assert bad.exit_code == 2 and "angle_deg" in bad.output


@pytest.mark.analytic
def test_deep_layers_approach_bagnold_scaling():
    """u(H) ∝ H^{3/2} in deep layers (uniform-shear interior, docs/chute.md): the local exponent
    d ln u(H)/d ln H of RET falls towards 3/2 with depth (1.64 at 30 d, within 0.01 of 1.5 beyond 90 d).
    About 2 s (7 depths, each continued from the previous one).
    """
    ds, rows, H = None, [], 30.0
    while H < 120.0:
        ds = solve_chute("ret", depth=H * 1e-3, angle_deg=ANGLE, mean_phi=0.3, material=MAT, n_cells=int(max(64, 2 * H)),
                         start=ds)
        rows.append((H, ds.attrs["surface_velocity"]))
        H *= 1.25
    r = np.array(rows)
    slopes = np.diff(np.log(r[:, 1])) / np.diff(np.log(r[:, 0]))
    assert np.all(np.diff(slopes) < 0)
    assert slopes[0] > 1.6
    assert abs(slopes[-1] - 1.5) < 0.01 and abs(slopes[-2] - 1.5) < 0.01
