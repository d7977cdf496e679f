"""Frictional walls AND frictional particles in the Couette cell from the naive start (docs/friction.md §8).

Wall conditions are checked against the Johnson & Jackson (1987) formulas written out here (not the code's
functions): momentum τ_w = (π√3/6) φ' (φ/φ_pk) χ √θ u_sl + p_f tan δ_w u_sl/√(u_sl² + (ε_w U)²), energy
q·n = G − D with the collisional slip work G only (the frictional wall work is dissipated at the contacts).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.friction_couette import (
    PREVIOUS_CHI,
    SCALE,
    SHEARED_CHI_WITHOUT_STATIC,
    frictional_wall_problem,
    halving_changes,
)

from ktgf import get_model
from ktgf.couette.equations import RATE_SENSITIVE_FD_STEP
from ktgf.couette.run import Material, to_dataset
from ktgf.couette.solver import _wall_friction_continuation, naive_start, solve
from ktgf.errors import InputError

SQ3PI = math.sqrt(3.0) * math.pi


def check_wall_conditions(pr, X, tol=1e-8):
    """Both walls satisfy the JJ momentum (collisional + frictional) and energy conditions; the budget closes."""
    t = pr.terms(X)
    u, theta, phi = pr.unpack(X)
    ds = to_dataset(pr, X, Material(1.0, SCALE, pr.e))
    U = abs(pr.u_wall[1] - pr.u_wall[0])
    tau_scale = np.abs(t["F"]).max()
    for k, i in ((0, 0), (1, -1)):
        w = pr.walls[k]
        chi = float(pr.model.chi(phi[i]))
        slip = u[i] - pr.u_wall[k]
        c = SQ3PI / 6 * w.specularity * phi[i] / w.packing_limit * chi * math.sqrt(theta[i])
        pf = float(pr.model.friction.frictional_pressure(phi[i], pr.phi_max)) / SCALE
        tau = c * slip + pf * math.tan(math.radians(w.friction_angle)) * slip / math.hypot(slip, w.slip_regularisation * U)
        # the wall half-cell carries no momentum source: its face flux is the wall traction (sign: n into the medium)
        face = t["F"][0] if k == 0 else -t["F"][-1]
        assert face == pytest.approx(tau, abs=tol * tau_scale), (k, face, tau)
        D = SQ3PI / (4 * w.packing_limit) * (1 - w.restitution**2) * phi[i] * chi * theta[i] ** 1.5
        G = c * slip**2
        heat_in = float(ds["wall_heat_flux"].values[k]) / SCALE  # ρ_s V³ with V = 1
        assert heat_in == pytest.approx(G - D, abs=tol * max(abs(G), abs(D))), (k, heat_in, G - D)
    assert ds.attrs["energy_budget_relative_error"] < tol
    return t, ds


@pytest.mark.analytic
def test_frictional_wall_case_converges_from_the_naive_start_and_meets_its_wall_conditions():
    """μ = 0.5, φ̄ = 0.55, Schaeffer, δ_w = 25°: Newton fails from the naive start; the solver continues tan δ_w from
    the δ_w = 0 solution (its δ_w = 0 start by natural continuation; without the tangential stress Newton finds that
    start; the generic homotopies reach the same solution to 1e-12 at several times the cost).  With the sheared χ,
    7.5 s CPU since the Jacobian's profiles are stacked (44.3 s before, same machine, 8 December 2026)."""
    pr = frictional_wall_problem(0.5, 0.55, 25.0)
    X, info = solve(pr)
    assert info["residual"] < 1e-8
    assert info["path"].startswith("delta_w-continuation")
    t, _ = check_wall_conditions(pr, X)
    assert np.all(t["p_frictional"][[0, -1]] > 0.0)  # the wall friction acts
    base = frictional_wall_problem(0.5, 0.55, 0.0)
    Xb, _ = solve(base, X)  # the frictionless-wall state, from this one (Newton, < 1 s)
    assert abs(t["slip"][0]) < abs(base.terms(Xb)["slip"][0])  # the wall friction holds the medium back


@pytest.mark.analytic
def test_a_wall_rougher_than_the_bulk_sticks_with_a_slip_set_by_the_regularisation():
    """μ = 0, φ̄ = 0.6, Srivastava–Sundaresan, δ_w = 30°: p_f tan δ_w at the wall exceeds the traction the medium
    transmits, so the wall sticks (Coulomb: no sliding below the friction limit); the regularised slip is then
    O(ε_w U) and halves with ε, while profiles and wall stress change by less than the §8 tolerance."""
    pr = frictional_wall_problem(0.0, 0.6, 30.0, "srivastava-sundaresan")
    X, info = solve(pr)
    t, _ = check_wall_conditions(pr, X)
    pf = t["p_frictional"][0]
    assert abs(t["F"][0]) < pf * math.tan(math.radians(30.0))  # below the wall's friction limit
    assert abs(t["slip"][0]) < 3 * pr.walls[0].slip_regularisation  # stuck: slip ~ ε_w U (U = 1)
    c = halving_changes(0.0, 0.6, 1e-3, 30.0, "srivastava-sundaresan", X)
    assert c["du"] < 1.5e-3 and c["dphi"] < 1e-4 and c["dtau"] < 4e-3


@pytest.mark.analytic
@pytest.mark.slow
def test_a_wall_that_sticks_beyond_a_fold_is_reached_by_arclength_in_the_wall_friction():
    """μ = 0, φ̄ = 0.6, Schaeffer, δ_w = 30°, continued from δ_w = 0 in s = tan δ_w / tan 30°: the sliding branch
    ends at a turning point (s ≈ 0.94) and the stuck branch begins at another (s ≈ 0.82), an S-shaped curve.  Natural
    steps stall at the first fold; arclength passes both and lands on the stuck wall (Coulomb: traction below
    p_f tan δ_w, slip ~ ε_w U), which meets the wall conditions.  Before, the solver's path here depended on the BLAS
    kernel's round-off (it failed with OpenBLAS's Haswell kernels, docs/friction.md §8).  The S is that of the χ(φ)
    registered before 7 December 2026 (``PREVIOUS_CHI``); with the registered sheared χ natural steps reach δ_w = 30°
    (measured), so the fold-passing this test checks needs the older model."""
    pr = frictional_wall_problem(0.0, 0.6, 30.0, "schaeffer", **PREVIOUS_CHI)
    X, info = _wall_friction_continuation(pr, naive_start(pr), 1e-10, 60, 400, "natural")
    assert info["path"].startswith("delta_w-continuation by arclength")
    folds = info["wall_friction_folds"]
    assert max(folds) < 1.0 and min(folds) < max(folds) - 0.05  # the sliding branch's end, above the stuck one's
    t, _ = check_wall_conditions(pr, X)
    assert abs(t["F"][0]) < t["p_frictional"][0] * math.tan(math.radians(30.0))
    assert abs(t["slip"][0]) < 3 * pr.walls[0].slip_regularisation


@pytest.mark.analytic
def test_halving_the_regularisation_with_a_sliding_frictional_wall():
    """μ = 0.5, φ̄ = 0.55, Schaeffer, δ_w = 25° (sliding, u_sl ≈ 0.27 U, creeping core): ε and ε_w halved together
    change the profiles by O(ε), within the §8 tolerance of the default (measured 8.7e-4, 5.6e-5, 5.1e-4)."""
    c = halving_changes(0.5, 0.55, 1e-3, 25.0)
    assert c["du"] < 1.5e-3 and c["dphi"] < 1e-4 and c["dtau"] < 4e-3


@pytest.mark.contract
def test_an_inventory_above_the_jamming_fraction_is_refused_in_one_line():
    phi_j = get_model("frictional", mu=0.5).phi_max  # φ_J(0.5) of the model's jamming law
    with pytest.raises(InputError, match=rf"mean_phi = 0.6 is out of range: valid 0 < mean_phi < {phi_j:.6g} .*no steady state") as e:
        frictional_wall_problem(0.5, 0.6, 25.0)
    assert "\n" not in str(e.value)


@pytest.mark.analytic
@pytest.mark.slow(minutes=0.7)  # 237 s on 7159d18; 90 s here 8 Dec (2.2x slower host)
def test_frictional_wall_map_from_a_naive_start():
    """Schaeffer and Srivastava–Sundaresan × μ {0, 0.25, 0.5} × δ_w {15°, 25°, 30°} × φ̄ {0.3, 0.4, 0.5, 0.55, 0.6}:
    every case below the model's jamming fraction φ_J(μ) (0.634, 0.610, 0.596) converges from the naive start and
    meets its wall conditions to the solver tolerance; φ̄ ≥ φ_J(μ) (0.6 at μ = 0.5) is refused as having no steady
    state.  Residual bound: the solver tolerance, 1e-10 (μ = 0, φ̄ = 0.6 with Schaeffer stopped at 1e-6 while the
    Jacobian's step was 1e-5; with the rate-sensitive step, 1e-7, it converges)."""
    failures, refused, expected = [], [], []
    for stress in ("schaeffer", "srivastava-sundaresan"):
        for mu in (0.0, 0.25, 0.5):
            phi_j = get_model("frictional", mu=mu).phi_max
            for angle in (15.0, 25.0, 30.0):
                for mean_phi in (0.3, 0.4, 0.5, 0.55, 0.6):
                    case = (stress, mu, angle, mean_phi)
                    if mean_phi >= phi_j:
                        expected.append(case)
                    try:
                        pr = frictional_wall_problem(mu, mean_phi, angle, stress)
                    except InputError as exc:
                        assert "no steady state" in str(exc)
                        refused.append(case)
                        continue
                    try:
                        X, info = solve(pr)
                        assert info["residual"] < 1e-10, info["residual"]
                        check_wall_conditions(pr, X)
                    except Exception as exc:  # noqa: BLE001 - collect, report all at once
                        failures.append((case, str(exc)[:120]))
    assert not failures, failures
    assert refused == expected and len(refused) == 6  # φ̄ = 0.6 at μ = 0.5, both stresses, three angles


@pytest.mark.analytic
@pytest.mark.slow(minutes=0.5)
def test_a_sheared_chi_converges_quadratically_in_a_creeping_core():
    """Schaeffer, μ = 0.25, δ_w = 30°, φ̄ = 0.6 with the sheared-χ fit without its static part: the walls slide
    (u_sl ≈ 0.46 U) round a creeping core (γ̇ ~ 1e-4 U/H), where χ ∝ |γ̇| varies on the scale of γ̇ itself.  The
    Jacobian's difference step in u is then 1e-7 instead of 1e-5: with 1e-5 the solver stalled here; with 1e-7 it
    converges to a residual of 2e-14, and the state meets the wall conditions."""
    pr = frictional_wall_problem(0.25, 0.6, 30.0, **SHEARED_CHI_WITHOUT_STATIC)
    assert pr.fd_step == RATE_SENSITIVE_FD_STEP == 1e-7
    X, info = solve(pr)
    assert info["residual"] < 1e-12, info["residual"]
    t, _ = check_wall_conditions(pr, X)
    assert abs(t["slip"][0]) > 0.4  # a sliding wall


@pytest.mark.analytic
@pytest.mark.slow
def test_the_solution_curve_approaches_the_jamming_fraction_without_a_fold():
    """μ = 0.5, δ_w = 25°, Srivastava–Sundaresan: continuing φ̄ towards the model's φ_J(0.5) the wall pressure rises
    monotonically and diverges (no turning point): there is no state at or beyond φ_J."""
    X, pressures = None, []
    phi_j = get_model("frictional", mu=0.5).phi_max
    for gap in (0.015, 0.005, 0.0025, 0.001, 0.0005, 0.0001):  # φ̄ = φ_J − gap: to 1e-4 short of jamming
        pr = frictional_wall_problem(0.5, phi_j - gap, 25.0, "srivastava-sundaresan")
        X, info = solve(pr, X)
        assert info["residual"] < 1e-8
        pressures.append(pr.terms(X)["p"][0])
    assert np.all(np.diff(pressures) > 0) and pressures[-1] > 1e3 * pressures[0]
    assert pr.phi_max - pr.unpack(X)[2].max() < 2e-4  # the densest layer is at φ_J


CONFIG = """
model = "frictional"
model_options = {stress = "schaeffer"}
mean_solid_fraction = 0.55
restitution = 0.7
particle_diameter = 1e-3
particle_density = 2500.0

[geometry]
kind = "planar"
gap = 0.02
wall_speed = 1.0

[walls]
type = "johnson-jackson"
specularity = 0.2
restitution = 0.85

[numerics]
n_cells = 80
"""


@pytest.mark.contract
def test_cli_sets_particle_and_wall_friction(tmp_path):
    """``ktgf couette run --mu 0.5 --wall-friction-angle 25``: the naive start converges; the file records δ_w and μ."""
    import json

    from typer.testing import CliRunner

    from ktgf.cli import app
    from ktgf.io import read_dataset

    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG)
    out = tmp_path / "c.nc"
    r = CliRunner().invoke(app, ["couette", "run", str(cfg), "--mu", "0.5", "--wall-friction-angle", "25", "-o", str(out),
                                 "--format", "json"])
    assert r.exit_code == 0, r.output
    row = json.loads(r.stdout)[0]
    assert row["converged"] and row["energy_budget_error"] < 1e-8
    ds = read_dataset(out, ("u",), "Couette profile")
    walls = json.loads(ds.attrs["parameters"])["walls"]
    assert walls["bottom"]["friction_angle"] == walls["top"]["friction_angle"] == 25.0
    assert json.loads(ds.attrs["model_options"])["friction"]["mu"] == 0.5
    assert json.loads(ds.attrs["solver_state"])["path"].startswith("delta_w-continuation")


@pytest.mark.contract
@pytest.mark.parametrize("args,words", [
    (["--wall-friction-angle", "90"], ["--wall-friction-angle = 90", "< 90"]),
    (["--wall-friction-angle", "-5"], ["--wall-friction-angle = -5", "0 <="]),
    (["--mu", "-0.1"], ["--mu = -0.1", "0 <= --mu"]),
])
def test_cli_bad_friction_is_a_one_line_error(tmp_path, args, words):
    from typer.testing import CliRunner

    from ktgf.cli import app

    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG)
    r = CliRunner().invoke(app, ["couette", "run", str(cfg), *args, "-o", str(tmp_path / "c.nc")])
    assert r.exit_code == 2
    msg = r.output.strip()
    assert all(w in msg for w in words), msg
    assert len(msg.splitlines()) == 1, msg


@pytest.mark.analytic
@pytest.mark.slow
def test_a_wall_rougher_than_the_bulk_has_a_stuck_and_a_sliding_state():
    """Schaeffer, μ = 0.25, φ̄ = φ_J(0.25) − 0.04, δ_w = 30° (tan δ_w > sin φ_fr: the wall can hold more
    than the bulk yields): Newton from the naive start reaches a stuck wall (slip ~ ε_w U, dense wall layer);
    continuing δ_w from the sliding 25° state keeps a sliding wall.  Two steady states, both meeting the wall
    conditions (docs/friction.md §8).  Which state the naive start reaches changes with φ̄ (docs/dense_physics.md
    §8: stuck at φ_J − 0.04 and − 0.03, sliding at − 0.02 … − 0.005 with the registered sheared χ), so φ̄ is taken
    where Newton reaches the stuck one."""
    mean_phi = get_model("frictional", mu=0.25).phi_max - 0.04
    pr = frictional_wall_problem(0.25, mean_phi, 30.0)
    Xs, info = solve(pr)
    assert info["path"] == "newton"
    X, _ = solve(frictional_wall_problem(0.25, mean_phi, 25.0))
    for angle in np.linspace(25.0, 30.0, 6)[1:]:
        X, info = solve(frictional_wall_problem(0.25, mean_phi, angle), X)
    stuck, _ = check_wall_conditions(pr, Xs)
    sliding, _ = check_wall_conditions(pr, X)
    assert abs(stuck["slip"][0]) < 5e-3 and abs(sliding["slip"][0]) > 0.2
    # Coulomb: the stuck wall holds its traction below the friction limit p_f tan δ_w, on a denser wall layer
    assert abs(stuck["F"][0]) < stuck["p_frictional"][0] * math.tan(math.radians(30.0))
    assert pr.unpack(Xs)[2][0] > pr.unpack(X)[2][0] + 0.02
