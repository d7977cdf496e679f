"""Dense-regime parts (issue 9 item 2–3, 5): jamming RDF, EKT dissipation, uniform shear, `dense`, `ktgf shear`."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from ktgf import get_model
from ktgf.cli import app
from ktgf.closures.dissipation import CorrelationLength, NoDissipationCorrection, ekt_j
from ktgf.closures.rdf import CarnahanStarling, ChialvoSundaresan, JammingPowerLaw
from ktgf.data import FRICTION_SHEAR, shipped, uniform_shear_records
from ktgf.shear.steady import ETA0_DEM, SHEAR_PER_ASTAR, steady_shear

jax = pytest.importorskip("jax")
runner = CliRunner()
PHI = np.array([0.02, 0.1, 0.3, 0.45, 0.5, 0.55, 0.6, 0.63])


# --- jamming power-law RDF -------------------------------------------------------------------
@pytest.mark.analytic
@pytest.mark.parametrize("b", [0.5, 1.0, 1.5, 2.0, 3.0])
def test_jamming_power_law_slope_matches_autodiff(b):
    r = JammingPowerLaw(a=0.2, exponent=b)
    auto = np.array([jax.grad(r.chi)(float(p)) for p in PHI])
    np.testing.assert_allclose(r.dchi(PHI), auto, rtol=1e-12)


@pytest.mark.analytic
def test_jamming_power_law_reductions():
    """a = 0 is Carnahan–Starling; b = 1.5 is Chialvo–Sundaresan (2013); χ → 1 at φ → 0."""
    assert np.array_equal(JammingPowerLaw(a=0.0).chi(PHI), CarnahanStarling().chi(PHI))
    np.testing.assert_allclose(JammingPowerLaw(a=0.58, exponent=1.5).chi(PHI), ChialvoSundaresan().chi(PHI), rtol=1e-15)
    assert JammingPowerLaw(a=0.3, exponent=2.2).chi(0.0) == 1.0


@pytest.mark.analytic
@pytest.mark.parametrize("b", [1.0, 1.5, 2.5])
def test_jamming_power_law_diverges_with_its_exponent(b):
    r = JammingPowerLaw(a=0.1, phi_c=0.64, exponent=b)
    gap = np.array([1e-5, 1e-6])
    excess = r.chi(0.64 - gap) - CarnahanStarling().chi(0.64 - gap)
    assert math.log(excess[1] / excess[0]) / math.log(gap[1] / gap[0]) == pytest.approx(-b, rel=1e-4)


# --- EKT dissipation correction ---------------------------------------------------------------
@pytest.mark.analytic
def test_ekt_j_elastic_dense_limit():
    """At e = 1 and large G: J → 1 + (π/32)(8G)(8G)/(24G²) = 1 + π/12 (by hand)."""
    assert ekt_j(1.0, 1e8) == pytest.approx(1.0 + math.pi / 12, rel=1e-6)


@pytest.mark.analytic
@pytest.mark.parametrize("e", [1.0, 0.9, 0.7, 0.3])
def test_ekt_j_is_the_garzo_dufty_viscosity_without_the_sonine_correction(e):
    """J is the shear viscosity of Garzó & Dufty (1999) with c* = 0 in units of (8/(5√π)) ρ_s d φ G √T.

    An independent check of the J formula (its denominator 24 − 6(1 − e)² − 5(1 − e²) included)
    against the RET viscosity of model.md §3, whose numbers are checked against oracles elsewhere;
    at e = 1 it is the Enskog viscosity.
    """
    model = get_model("ret", sonine=False)
    phi = np.array([0.05, 0.2, 0.4, 0.55, 0.6])
    d, rho_s, theta = 1.3, 1.7, 2.0
    eta = model.coefficients(phi, e, np.full(phi.size, theta), d=d, rho_s=rho_s, check=False).eta
    G = phi * model.chi(phi)
    np.testing.assert_allclose(eta / (8 / (5 * math.sqrt(math.pi)) * rho_s * d * math.sqrt(theta) * phi * G),
                               ekt_j(e, G), rtol=1e-12)


@pytest.mark.analytic
def test_ekt_reduces_to_standard_theory_without_shear_and_when_l_equals_d():
    base = get_model("ret")
    ekt = base.replace(dissipation=CorrelationLength(c=1.0))
    for field in base.reduced(PHI, 0.8)._fields:
        assert np.array_equal(getattr(base.reduced(PHI, 0.8), field), getattr(ekt.reduced(PHI, 0.8), field))
    # L = d when Λ s ≤ 1: tiny shear, or a tiny constant c
    r0, r1 = base.reduced(PHI, 0.8), ekt.reduced(PHI, 0.8, shear=1e-6)
    np.testing.assert_array_equal(r0.zeta0, r1.zeta0)
    tiny = base.replace(dissipation=CorrelationLength(c=1e-9))
    np.testing.assert_array_equal(tiny.reduced(PHI, 0.8, shear=10.0).zeta0, r0.zeta0)
    # strong shear reduces the dissipation by exactly d/L
    lam = ekt.dissipation.coefficient(PHI, 0.8, base.chi(PHI))
    r2 = ekt.reduced(PHI, 0.8, shear=100.0)
    np.testing.assert_allclose(r2.zeta0, r0.zeta0 / np.maximum(1.0, 100.0 * lam), rtol=1e-14)
    assert NoDissipationCorrection().factor(PHI, 0.8, 1.0, 5.0) == 1.0


@pytest.mark.analytic
def test_ekt_uniform_shear_dilute_limit_is_standard():
    base = get_model("ret")
    ekt = base.replace(dissipation=CorrelationLength(c=3.0))
    phi = np.array([1e-4, 1e-3, 0.01])
    s0, s1 = steady_shear(base, phi, 0.8), steady_shear(ekt, phi, 0.8)
    np.testing.assert_array_equal(s1.L_over_d, 1.0)
    np.testing.assert_array_equal(s0.T, s1.T)


@pytest.mark.analytic
@pytest.mark.parametrize("c", [1.5, 3.0, 10.0])
def test_ekt_uniform_shear_solves_the_energy_balance_consistently(c):
    """a*² η* (L/d) = (3/2) ζ0* with L/d = max(1, Λ s), s = dγ̇/√θ evaluated at the returned state."""
    m = get_model("ret").replace(dissipation=CorrelationLength(c=c))
    phi = np.array([0.3, 0.45, 0.5, 0.55, 0.6])
    s = steady_shear(m, phi, 0.7)
    shear = 1.0 / np.sqrt(s.T)  # dγ̇/√θ
    np.testing.assert_allclose(shear, SHEAR_PER_ASTAR * phi * s.astar, rtol=1e-12)
    r = m.reduced(phi, 0.7, shear=shear)  # ζ0* with the correlation length at this state
    np.testing.assert_allclose(s.astar**2 * r.eta, 1.5 * r.zeta0, rtol=1e-10)
    lam = m.dissipation.coefficient(phi, 0.7, m.chi(phi))
    np.testing.assert_allclose(s.L_over_d, np.maximum(1.0, lam * shear), rtol=1e-12)
    assert np.any(s.L_over_d > 1.0)


@pytest.mark.analytic
def test_ekt_at_e_one_is_harmless():
    m = get_model("ret").replace(dissipation=CorrelationLength())
    r = m.reduced(PHI, 1.0, shear=5.0)
    assert np.all(np.isfinite(r.zeta0)) and np.all(r.zeta0 == 0)


# --- uniform shear in the DEM file's columns ------------------------------------------------
@pytest.mark.analytic
@pytest.mark.parametrize("name", ["enskog", "ret", "visc-div", "proposed", "dense"])
def test_shear_state_matches_model_md_closed_forms(name):
    """T = 25π η*/(13824 φ² ζ0*) and |P_xy|/p = √(3η*ζ0*/2)/p* (model.md §9) without a dissipation correction
    and, for ``dense``, without the sheared part of χ (those closed forms are of a χ(φ); the sheared χ's steady state is
    tested in tests/closures/test_sheared_chi.py)."""
    m = get_model(name, dissipation="none", **({"shear_amplitude": 0.0} if name == "dense" else {}))
    phi = np.array([0.1, 0.3, 0.5, 0.6])
    r = m.reduced(phi, 0.8)
    s = steady_shear(m, phi, 0.8)
    np.testing.assert_allclose(s.T, 25 * math.pi * r.eta / (13824 * phi**2 * r.zeta0), rtol=1e-13)
    np.testing.assert_allclose(s.tau_over_p, np.sqrt(1.5 * r.eta * r.zeta0) / r.p, rtol=1e-13)
    np.testing.assert_allclose(s.astar, np.sqrt(1.5 * r.zeta0 / r.eta), rtol=1e-13)
    us = steady_shear(m, phi, 0.8)
    np.testing.assert_allclose(us.T, s.T, rtol=1e-13)


@pytest.mark.dem
def test_column_definitions_agree_with_the_dem_file_header(data_dir):
    """The DEM's own columns obey our conversions: eta_star/eta_over_eta0 = 5/(16√π), T = 25π/(9216 φ² a*²)."""
    rows = uniform_shear_records(data_dir / "dem_uniform_shear.csv")
    np.testing.assert_allclose(rows["eta_star"] / rows["eta_over_eta0"], ETA0_DEM, rtol=2e-4)
    np.testing.assert_allclose(25 * math.pi / (9216 * rows["phi"] ** 2 * rows["astar"] ** 2), rows["T"], rtol=1e-3)


@pytest.mark.contract
def test_cli_shear_json_matches_library():
    result = runner.invoke(app, ["shear", "--model", "proposed", "--phi", "0.3,0.5", "--e", "0.9", "--format", "json"])
    assert result.exit_code == 0, result.output
    rows = json.loads(result.output)
    s = steady_shear(get_model("proposed"), np.array([0.3, 0.5]), 0.9)
    assert [r["phi"] for r in rows] == [0.3, 0.5]
    for i, r in enumerate(rows):
        for col in ("T", "eta_star", "eta_over_eta0", "p_over_nT"):
            assert r[col] == pytest.approx(float(getattr(s, col)[i]), rel=1e-12)


@pytest.mark.contract
def test_cli_shear_options_and_csv():
    result = runner.invoke(app, ["shear", "-m", "ret", "--phi", "0.55", "--e", "0.7", "--format", "csv",
                                 "-O", "dissipation=jenkins-berzi-2010", "-O", "c=2"])
    assert result.exit_code == 0, result.output
    header, line = result.output.strip().splitlines()
    assert header.split(",")[:7] == ["model", "phi", "e", "T", "eta_star", "eta_over_eta0", "p_over_nT"]
    assert float(dict(zip(header.split(","), line.split(",")))["L_over_d"]) > 1


@pytest.mark.contract
@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--model", "ret", "--phi", "0.5", "--e", "1"], "0 < e < 1"),
        (["--model", "ret", "--phi", "", "--e", "0.9"], "gives no value"),
        (["--model", "ret", "--phi", "1.2", "--e", "0.9"], "phi < 1"),
        (["--model", "proposed", "--phi", "0.3", "--e", "0.9", "-O", "phi_c=1.5"], "option phi_c = 1.5"),
        (["--model", "ret", "--phi", "0.3", "--e", "0.9", "-O", "sonine"], "KEY=VALUE"),
    ],
)
def test_cli_shear_errors_exit_2_with_one_line(args, fragment):
    result = runner.invoke(app, ["shear", *args])
    assert result.exit_code == 2
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and fragment in lines[0], result.output


# --- the recommended dense model ---------------------------------------------------------------
@pytest.mark.dem
def test_dense_fit_reproduces_the_registered_parameters():
    """a, b, c, A of ``dense`` refit from the shipped frictionless uniform shear (base + extra file, e = 0.9), the
    cooling states' p/(nT) and Torquato's static χ near jamming (21 + 10 + 3 points)."""
    from ktgf.calibration.registry_fits import fit_sheared_structure
    from ktgf.closures.dense import DENSE_PARAMETERS

    fit = fit_sheared_structure()
    assert fit.success and fit.n_points == 34 and fit.points_per_parameter == 8.5
    for name, value in DENSE_PARAMETERS.items():
        assert fit.values[name] == pytest.approx(value, rel=2e-4), name
    rdf = get_model("dense").rdf
    assert (rdf.a, rdf.exponent, get_model("dense").dissipation.c, rdf.shear_amplitude) == (
        DENSE_PARAMETERS["a"], DENSE_PARAMETERS["exponent"], DENSE_PARAMETERS["c"], DENSE_PARAMETERS["shear_amplitude"])
    # the divergence is the published frictionless jamming fraction 6/(6 + 2√3) = 63.4 % (not fitted)
    assert get_model("dense").phi_max == pytest.approx(0.634, abs=5e-4)


@pytest.mark.dem
def test_dense_predicts_the_couette_wall_stresses_within_15_percent(data_dir):
    """Goal of issues 9 and 33: the Couette file is not fitted; wall shear stress and pressure within 15 %, valid profile.

    Route: the bumpy-wall condition, no wall parameter fitted (the DEM's wall spheres from the file's header,
    e_w = e, the cell = the layer the sphere centres reach).  Measured −7.4 % and −2.5 %; Johnson–Jackson walls
    fitted to the slip on the slab to the tangent planes miss it (−22.2 %, −24.7 %): docs/dense.md §5.1, which
    also shows how much the stresses depend on where the continuum cell ends.
    """
    pytest.importorskip("ktgf.couette")
    from ktgf.couette.compare import compare_with_dem

    (dense,), _ = compare_with_dem(data_dir / "dem_couette_e0.9_phi0.50.csv", ["dense"], n_cells=100, wall="bumpy")
    assert dense["valid"], dense
    assert abs(dense["tau_error"]) < 0.15 and abs(dense["p_error"]) < 0.15, dense


GOALS = {"T": 0.15, "p_over_nT": 0.10, "tau_over_p": 0.10}  # issue 33: uniform shear


@pytest.mark.dem
def test_dense_meets_the_uniform_shear_goals_at_every_frictionless_state():
    """Issue 33 goal, frictionless φ 0.3–0.6 (e = 0.9, the fit set): T within 15 %, p/(nT) and τ/p within 10 %;
    the paper's ``proposed`` misses it (so the test can fail)."""
    from ktgf.calibration.registry_fits import OBSERVABLES, frictionless_states

    states = frictionless_states()
    assert states["phi"].min() == 0.3 and states["phi"].max() == 0.6
    for name, ok in (("dense", True), ("proposed", False)):
        s = steady_shear(get_model(name), states["phi"], 0.9)
        within = all(np.all(np.abs(getattr(s, k) / states[k] - 1.0) < GOALS[k]) for k in OBSERVABLES)
        assert within is ok, name


@pytest.mark.dem
def test_dense_cross_validated_errors_meet_the_goals():
    """Leave-one-state-out refits of a, b, c, A (cooling and static points kept) predict each left-out frictionless
    state within the issue's goals."""
    from ktgf.calibration.registry_fits import OBSERVABLES, cooling_states, fit_sheared_structure, frictionless_states
    from ktgf.calibration.registry_fits import leave_one_out

    states, cooling = frictionless_states(), cooling_states()
    loo = leave_one_out(lambda s: fit_sheared_structure(s, cooling).values, states)
    for k, name in enumerate(OBSERVABLES):
        assert np.all(np.abs(loo[k]) < GOALS[name]), (name, loo[k])


@pytest.mark.dem
def test_dense_predicts_the_held_out_e07_row():
    """The frictionless e = 0.7 row (never fitted): p/(nT) within 10 % and T within 15 % (issue 33's goals).

    η* misses the 10 % of issue 9's check: measured +15.4 % (T +9.7 %, τ/p +10.5 %: the dissipation fitted at
    e = 0.9 does not carry over, docs/dense.md §4); pinned at its measured value so that a change shows.
    """
    held_out = uniform_shear_records(shipped(FRICTION_SHEAR), where={"mu": 0.0})
    assert held_out.size == 1 and held_out["e"][0] == 0.7
    s = steady_shear(get_model("dense"), held_out["phi"], 0.7)
    for q, tol in (("p_over_nT", 0.10), ("T", 0.15)):
        assert abs(float(getattr(s, q)[0]) / held_out[q][0] - 1.0) < tol, q
    assert float(s.eta_over_eta0[0]) / held_out["eta_over_eta0"][0] - 1.0 == pytest.approx(0.154, abs=0.005)


@pytest.mark.contract
def test_load_uniform_shear_errors(tmp_path):
    from ktgf import InputError

    with pytest.raises(InputError, match="does not exist"):
        uniform_shear_records(tmp_path / "none.csv")
    bad = tmp_path / "bad.csv"
    bad.write_text("# header\nphi,e,T\n0.3,0.9,1.0\n")
    with pytest.raises(InputError, match="missing column"):
        uniform_shear_records(bad)
    nan = tmp_path / "nan.csv"
    nan.write_text("phi,e,T,eta_over_eta0,p_over_nT\n0.3,0.9,nan,1,1\n")
    with pytest.raises(InputError, match="NaN"):
        uniform_shear_records(nan)
