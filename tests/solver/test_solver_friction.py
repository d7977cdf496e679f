"""Frictional models in the 3D solver (``ktgf.solver.friction``, ``docs/friction.md`` §7).

Oracles from outside the 3D solver: the frictional Haff law of :mod:`ktgf.hcs.haff` (the HCS
dissipation of the friction part), the closed-form frictional uniform shear of ``ktgf shear --mu``
(:func:`ktgf.shear.steady.steady_shear`), and the frictionless solver itself
(μ = 0 and a frictional stress that vanishes must give the same bits).
"""

from __future__ import annotations

import tomllib

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.closures.models import Model
from ktgf.errors import InputError
from ktgf.hcs.haff import cooling_time, haff_temperature
from ktgf.shear.steady import steady_shear
from ktgf.solver.boundaries import Boundaries
from ktgf.solver.cases import get_case
from ktgf.solver.config import parse_config
from ktgf.solver.flows import add_base_flow, stress_tensor
from ktgf.solver.friction import FrictionalReduced, cell_coefficients
from ktgf.solver.grid import Grid
from ktgf.solver.initial import uniform_fields
from ktgf.solver.physics import Physics
from ktgf.solver.state import conservative, primitive, primitive_fields
from ktgf.solver.stepping import Numerics, advance, rhs

D, RHO_S, E, RATE, THETA0 = 1e-3, 2500.0, 0.7, 50.0, 1e-4


def _physics(model: Model, kind: str, grid: Grid) -> Physics:
    return get_case(kind).physics(Physics(model, E, D, RHO_S, 0.99 * model.phi_max), grid)


def _shear_grid(n: int = 4) -> Grid:
    return Grid((n, n), (n * D, n * D), Boundaries(("periodic", "lees-edwards"), shear_rate=RATE, flow=0))


# --- 1. the case's dissipation ---------------------------------------------------------------------

@pytest.mark.analytic
@pytest.mark.parametrize("scheme, order", [("imex", 2), ("ssprk3", 3)])
def test_frictional_cooling_box_follows_the_frictional_haff_law_at_the_scheme_order(scheme: str, order: int) -> None:
    """The cooling case takes the HCS dissipation: θ(t) is ktgf.hcs's frictional Haff law, the error
    falling at the scheme's order (the steady-shear dissipation would cool 1.5x faster)."""
    m = get_model("frictional")
    grid = Grid((4,), (0.05,))
    phys = _physics(m, "cooling", grid)
    assert phys.hcs
    phi0 = 0.3
    t0 = float(cooling_time(m, phi0, E, THETA0, d=D))  # the oracle: ktgf.hcs.haff with the same model
    shear_t0 = 2.0 / float(m.coefficients(phi0, E, THETA0, d=D, rho_s=RHO_S).zeta0)
    assert shear_t0 < 0.8 * t0  # the two dissipations differ: the test can tell them apart
    U0 = conservative(*uniform_fields(grid, phys, phi0, THETA0))
    t_end = 3.0 * t0
    errors = []
    for c in (0.2, 0.1, 0.05):
        U, t, _, status, _ = advance(U0, 0.0, t_end, 10**6, grid, phys,
                                     Numerics(cfl=c, cfl_diffusion=c, cfl_source=c, scheme=scheme))
        assert int(status) == 0 and float(t) == t_end
        theta = np.asarray(primitive(U))[4]
        errors.append(abs(theta[0] / float(haff_temperature(t_end, THETA0, t0)) - 1.0))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[-1] < 0.005 and np.all(orders > order - 0.2), (errors, orders)


@pytest.mark.contract
def test_sheared_cases_take_the_steady_shear_dissipation_and_the_shear_rate_scale() -> None:
    m = get_model("frictional")
    phys = _physics(m, "uniform-shear", _shear_grid())
    assert not phys.hcs and phys.shear_rate_scale == RATE
    assert _physics(m, "cooling", Grid((4,), (0.05,))).shear_rate_scale == 0.0


# --- 2. reductions, bit for bit -------------------------------------------------------------------

def _sheared_run(model: Model, phi: float, scheme: str, steps: int = 6) -> np.ndarray:
    grid = _shear_grid()
    phys = _physics(model, "uniform-shear", grid)
    rng = np.random.default_rng(3)
    U = conservative(jnp.asarray(RHO_S * phi * (1 + 0.01 * rng.standard_normal(grid.cells))),
                     jnp.asarray(0.01 * rng.standard_normal((3, *grid.cells))), jnp.full(grid.cells, 4e-4))
    U, _, n, status, _ = advance(add_base_flow(U, grid), 0.0, 1.0, steps, grid, phys, Numerics(scheme=scheme))
    assert int(status) == 0 and int(n) == steps
    return np.asarray(U)


# IMEX variants are ``slow`` (their compile dominates); the explicit ones cover the same closures.
@pytest.mark.analytic
@pytest.mark.parametrize("scheme", [pytest.param("imex", marks=pytest.mark.slow), "ssprk3"])
def test_mu_zero_is_bit_for_bit_the_frictionless_run(scheme: str) -> None:
    """``frictional`` at μ = 0 and the same composition without a friction part: identical states."""
    frictional = get_model("frictional", mu=0.0)
    frictionless = frictional.with_options(friction="none")
    assert frictionless.friction.key == "none"
    np.testing.assert_array_equal(_sheared_run(frictional, 0.4, scheme), _sheared_run(frictionless, 0.4, scheme))


@pytest.mark.analytic
@pytest.mark.parametrize("scheme", [pytest.param("imex", marks=pytest.mark.slow), "ssprk3"])
def test_a_frictional_stress_that_vanishes_changes_nothing_but_round_off(scheme: str) -> None:
    """Below φ_min the Johnson–Jackson p_f (and so μ_f and its work) is 0: the run is the one without a stress.

    The compiled step differs by the zero terms, which XLA fuses differently, so the two runs agree to
    round-off, not bit for bit (IMEX, jaxlib 0.10.2 on this machine: 56 of 80 densities one ulp apart,
    1.1e-13 kg/m³ at ~1e3; a stress that did not vanish would change them by many orders more)."""
    with_stress = get_model("frictional", stress="schaeffer")
    assert with_stress.friction.jj_phi_min == 0.5
    a, b = _sheared_run(with_stress, 0.4, scheme), _sheared_run(get_model("frictional"), 0.4, scheme)
    np.testing.assert_allclose(a, b, rtol=1e-14, atol=1e-14 * np.abs(b).max())


# --- 3. uniform shear: the closed form of ktgf shear --mu ----------------------------------------------

# φ 0.52 with a stress: there the frictional part is most of the pressure (77 % with the refitted model, whose
# φ_J(0.5) = 0.596; at φ 0.5 it is 47 %), so the test sees it
CASES = [({}, 0.4), ({}, 0.5), ({"stress": "schaeffer", "jj_phi_min": 0.45}, 0.52),
         ({"stress": "srivastava-sundaresan", "jj_phi_min": 0.45}, 0.52)]


def _closed_form(m: Model, phi: float) -> tuple[float, float, float]:
    """(θ [m²/s²], τ [Pa], p [Pa]) of ``ktgf shear --mu`` (the DEM file's definitions times the scales)."""
    scale = RHO_S * D**2 * RATE**2
    s = steady_shear(m, np.atleast_1d(phi), E, stress_scale=scale if m.friction.has_stress else None)
    p = float(s.p_star[0]) * scale
    return float(s.T[0]) * (RATE * D) ** 2, float(s.tau_over_p[0]) * p, p


@pytest.mark.analytic
@pytest.mark.parametrize("options, phi", CASES)
def test_closed_form_frictional_uniform_shear_is_a_steady_state_with_its_stresses(options: dict, phi: float) -> None:
    m = get_model("frictional", mu=0.5, **options)
    grid = _shear_grid(8)
    phys = _physics(m, "uniform-shear", grid)
    theta, tau, p = _closed_form(m, phi)
    U = add_base_flow(conservative(jnp.full(grid.cells, RHO_S * phi), jnp.zeros((3, *grid.cells)),
                                   jnp.full(grid.cells, theta)), grid)
    dU = [np.asarray(x) for x in jax.jit(rhs)(tuple(U), grid, phys, Numerics(), 0.21)]
    assert np.max(np.abs(dU[4])) < 1e-10 * tau * RATE  # heating = dissipation (frictional work not in θ)
    assert np.max(np.abs(dU[1])) < 1e-10 * tau / D
    P = np.asarray(stress_tensor(U, 0.0, grid, phys))
    # ε = 1e-3 regularises the rate-independent viscosity: τ_f is 1/√(1 + 4ε²) (Schaeffer) of its value.
    np.testing.assert_allclose(-P[3], tau, rtol=3e-6)
    np.testing.assert_allclose(P[:3], p, rtol=1e-12)
    r = cell_coefficients(primitive_fields(tuple(U)), grid, phys)
    assert isinstance(r, FrictionalReduced) == bool(options)
    if options:  # the frictional part is most of the stress there: the test sees it
        assert float(np.mean(r.p_f)) > 0.5 * p


# IMEX is not here: its steady θ is biased by O(ζΔt) (0.8 % at cfl 0.4, measured), because the EKT factor
# of ζ0 is frozen at the stage-start θ (docs/friction.md §7, what is missing).
@pytest.mark.analytic
@pytest.mark.parametrize("options, phi, scheme", [({}, 0.5, "ssprk3"), ({"stress": "schaeffer", "jj_phi_min": 0.45}, 0.5, "ssprk3")])
def test_homogeneous_frictional_shear_relaxes_to_the_closed_form(options: dict, phi: float, scheme: str) -> None:
    """From 1.3 θ the homogeneous sheared box relaxes to the closed-form θ, τ and p (to 1e-6)."""
    m = get_model("frictional", mu=0.5, **options)
    grid = _shear_grid(4)
    phys = _physics(m, "uniform-shear", grid)
    theta, tau, p = _closed_form(m, phi)
    U = add_base_flow(conservative(jnp.full(grid.cells, RHO_S * phi), jnp.zeros((3, *grid.cells)),
                                   jnp.full(grid.cells, 1.3 * theta)), grid)
    U, t, _, status, _ = advance(U, 0.0, 30.0 / RATE, 10**6, grid, phys, Numerics(scheme=scheme))
    assert int(status) == 0
    th = np.asarray(primitive(U))[4]
    P = np.asarray(stress_tensor(U, t, grid, phys))
    assert abs(float(th.mean()) / theta - 1.0) < 1e-6, th.mean() / theta - 1
    assert abs(-P[3] / tau - 1.0) < 5e-6 and abs(P[:3].mean() / p - 1.0) < 1e-6, (P, tau, p)


# --- 4. planar Couette: the 1D solver with the same frictional model and walls --------------------------

@pytest.mark.analytic
@pytest.mark.slow
def test_frictional_couette_keeps_the_1d_solution_within_one_percent() -> None:
    """``frictional`` (μ = 0.5, e = 0.7) with a Schaeffer stress at φ̄ = 0.5 (p_f is 98 % of the pressure),
    JJ walls, 10 d gap, 128 cells, started from the 1D steady profile: after strain 10 the 3D profiles are
    the 1D ones within 1 % in u, φ, the wall stress within 1 %, θ within 2 %: with the registered sheared χ θ's error
    is 5.24, 1.15, 0.53 % at 64, 128, 256 cells (it falls with the grid: a discretisation error, as the 2 % of
    the δ_w = 30° cell below; with the χ(φ) registered before it was 0.92 % at 128 cells).  ~140 s wall at load 8."""
    from helpers.couette_case import couette_case as _couette
    from helpers.couette_case import parse as _parse
    from helpers.couette_case import run_from_profile_within_one_percent

    from ktgf.solver.cases.couette import couette_reference
    from ktgf.solver.run import Simulation

    n, phi0 = 128, 0.5
    text = _couette([n], 10.0).replace('name = "ret"\nrestitution = 0.9', 'name = "frictional"\nrestitution = 0.7\n'
                                        'options = { mu = 0.5, stress = "schaeffer" }')
    sim = Simulation(_parse(text.replace("solid_fraction = 0.3", f"solid_fraction = {phi0}")))
    ref = couette_reference(sim.phys, sim.grid, phi0)
    assert float(ref["p_frictional"].max()) > 0.9 * float(ref["p"].max())
    run_from_profile_within_one_percent(sim, ref, phi0, theta_tol=0.02)


@pytest.mark.analytic
@pytest.mark.slow(minutes=2.3)
def test_frictional_walls_keep_the_1d_solution_of_a_dense_cell() -> None:
    """JJ walls with δ_w = 30° (``frictional`` μ = 0.5, e = 0.7, Schaeffer, φ̄ = 0.57), 128 cells, IMEX, strain 2
    from the 1D profile: the wall traction raises the 1D wall stress by more than 15 % over δ_w = 0; the 3D run keeps
    the 1D profile and stress.  With the registered sheared χ (docs/dense_physics.md §8) at 128 cells: u 0.25 %,
    φ 0.27 %, θ 0.96 %, wall stress 1.2 % after strain 10, the same to 0.05 points from strain 2 on, hence strain 2;
    with the χ(φ) registered before: θ 4.4 / 1.6 / 0.54 %, stress 1.95 / 1.29 / 0.65 % at 64 / 128 / 256 cells (θ
    second order at most, the stress first), so 2 % in θ and stress at 128 cells, 1 % in u, φ.  Without the static
    part of the sheared χ the shear gathered in a wall band thinner than a cell of the 1D reference and the run left
    it within strain 0.1 (u 15 %, θ 66 % at strain 10).  113 s wall idle at strain 4."""
    import dataclasses

    from helpers.couette_case import couette_case as _couette
    from helpers.couette_case import parse as _parse

    from ktgf.couette.geometry import PlanarCell
    from ktgf.couette.run import Material, run
    from ktgf.solver.cases.couette import couette_reference
    from ktgf.solver.run import Simulation

    n, phi0 = 128, 0.57
    text = _couette([n], 2.0).replace('name = "ret"\nrestitution = 0.9', 'name = "frictional"\nrestitution = 0.7\n'
                                       'options = { mu = 0.5, stress = "schaeffer" }')
    text = text.replace("solid_fraction = 0.3", f"solid_fraction = {phi0}").replace(
        "restitution = 0.9 }", "restitution = 0.9, friction_angle = 30.0 }")
    sim = Simulation(_parse(text))
    ref = couette_reference(sim.phys, sim.grid, phi0)
    smooth = dataclasses.replace(sim.grid.boundaries.walls[0][0].wall, friction_angle=0.0)
    material = Material(float(sim.phys.diameter), float(sim.phys.material_density), float(sim.phys.restitution))
    ref0 = run(sim.phys.model, PlanarCell(sim.grid.lengths[0], 1.0), smooth, smooth, phi0, material, n_cells=400,
               stretch=1.5)
    tau_ref, tau_smooth = float(ref["wall_shear_stress"].values[1]), float(ref0["wall_shear_stress"].values[1])
    assert tau_ref > 1.15 * tau_smooth
    y = sim.grid.centres(0) - 0.5 * sim.grid.lengths[0]
    u = np.zeros((3, n))
    u[1] = np.interp(y, ref["y"].values, ref["u"].values)
    with sim.precision():
        rho_s = sim.phys.material_density
        U0 = conservative(jnp.asarray(rho_s * np.interp(y, ref["y"].values, ref["phi"].values)), jnp.asarray(u),
                          jnp.asarray(np.interp(y, ref["y"].values, ref["theta"].values)))
        U0 = U0 * (phi0 * rho_s * n / float(U0[0].sum()))
    sim.initial_state = lambda: sim.place(U0)
    sim.run(progress=False, write_files=False)
    err, tau = sim.verification["max_rel_error"], sim.verification["wall_shear_stress_Pa"]["run"]
    assert err["u"] < 0.01 and err["phi"] < 0.01 and err["theta"] < 0.02, err
    assert all(abs(t / tau_ref - 1.0) < 0.02 for t in tau), (tau, tau_ref)


# --- 5. configs --------------------------------------------------------------------------------------

def _config(case: str, options: str = "", extra: str = "") -> dict:
    if case == "cooling":
        boundaries = ""
    else:
        boundaries = '[boundaries]\ny = { kind = "lees-edwards", shear_rate = 50.0, flow = "x" }\n'
    return tomllib.loads(f"""
[case]
kind = "{case}"
[model]
name = "frictional"
restitution = 0.7
options = {{ {options} }}
[initial]
solid_fraction = 0.4
temperature = 1e-4
[grid]
cells = [4, 4]
length_d = 4.0
{boundaries}
[time]
end = 1.0
unit = "s"
{extra}
""")


@pytest.mark.analytic
def test_frictional_shear_example_runs_to_the_closed_form() -> None:
    from pathlib import Path

    from ktgf.solver.config import load_config
    from ktgf.solver.run import Simulation

    sim = Simulation(load_config(Path(__file__).resolve().parents[2] / "examples" / "frictional_shear.toml"))
    sim.run(progress=False, write_files=False)
    err = sim.verification["max_rel_error"]
    assert max(err.values()) < 1e-5, err


@pytest.mark.contract
def test_frictional_models_are_accepted_by_the_3d_solver() -> None:
    assert parse_config(_config("cooling")).model.name == "frictional"
    assert parse_config(_config("uniform-shear", 'stress = "schaeffer"')).case.kind == "uniform-shear"


@pytest.mark.contract
@pytest.mark.parametrize("case, options, field", [
    ("cooling", 'stress = "schaeffer"', "model.options.stress"),  # no shear-rate scale for ε
    ("cooling", "mu = 0.2", "model.options.mu"),  # Walton's rule has no HCS at weak friction (e = 0.7)
])
def test_what_the_3d_solver_still_refuses_is_one_line_naming_it(case: str, options: str, field: str) -> None:
    with pytest.raises(InputError) as exc:
        parse_config(_config(case, options))
    msg = str(exc.value)
    assert "\n" not in msg and field in msg, msg


def _rough_wall_config(options: str, momentum: str = "johnson-jackson") -> dict:
    return tomllib.loads(f"""
[case]
kind = "couette"
[model]
name = "frictional"
restitution = 0.7
options = {{ {options} }}
[initial]
solid_fraction = 0.4
temperature = 1e-3
perturbation = "none"
[grid]
cells = [8]
length_d = 10.0
[boundaries]
x = {{ kind = "wall", flow = "y", wall_speed = 1.0, walls = {{ type = "{momentum}", specularity = 0.1, restitution = 0.9, friction_angle = 20.0 }} }}
[time]
end = 1.0
unit = "strain"
""")


@pytest.mark.contract
@pytest.mark.parametrize("options, momentum", [("", "johnson-jackson"), ('stress = "schaeffer"', "zero-flux")])
def test_a_frictional_wall_needs_a_frictional_stress_and_a_johnson_jackson_wall(options: str, momentum: str) -> None:
    """The wall traction p_f tan δ_w acts on the frictional normal stress, as in the 1D Couette solver."""
    with pytest.raises(InputError) as exc:
        parse_config(_rough_wall_config(options, momentum))
    msg = str(exc.value)
    assert "\n" not in msg and "friction_angle = 20" in msg and "model.options.stress" in msg, msg
    walls = parse_config(_rough_wall_config('stress = "schaeffer"')).boundaries.x.walls.build_pair()
    assert [w.friction_angle for w in walls] == [20.0, 20.0]


@pytest.mark.analytic
@pytest.mark.parametrize("slip_components", [1, 2])
def test_the_frictional_wall_ghost_makes_the_wall_stress_the_johnson_jackson_traction(slip_components: int) -> None:
    """With δ_w > 0 the central viscous flux through each wall face is c u_sl + p_f tan δ_w u_sl/√(|u_sl|² + s²)
    (s = ε_w U) at the face slip, the collisional part c and the traction from ktgf.couette.walls, the 1D solver's
    functions; the heat flux keeps D − c|u_sl|² (the frictional work is lost at the wall contacts).  Two slip
    components: the traction is along the slip vector.  The wall layers are dense (φ ≈ 0.53), so p_f > 0."""
    from ktgf.couette.walls import Wall, jj_dissipation, jj_friction, jj_frictional_wall_stress
    from ktgf.solver.boundaries import WallSide, pad, wall_terms
    from ktgf.solver.run import _x64

    m = get_model("frictional", mu=0.5, stress="schaeffer")
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max)
    wall = Wall(specularity=0.3, restitution=0.8, friction_angle=25.0, slip_regularisation=0.005)
    speed = 0.5
    walls = (WallSide(wall, (0.0, -speed, 0.0)), WallSide(wall, (0.0, speed, 0.0)))
    grid = Grid((8,), (8 * D,), Boundaries(("wall",), flow=1, walls=(walls,)))
    x = grid.centres(0) / (8 * D)
    phi = 0.53 - 0.04 * x * (1.0 - x)
    theta = 1e-4 * (1.0 + x)
    u = np.zeros((3, 8))
    u[1] = 0.8 * (x - 0.5) + 0.1 * x**3
    if slip_components == 2:
        u[2] = 0.3 * np.cos(3.0 * x)
    with _x64(True):
        rho = jnp.asarray(RHO_S * phi)
        transport = phys.transport(rho, jnp.asarray(theta), phys.reduced(rho))
        T = wall_terms(rho, [jnp.asarray(v) for v in u], jnp.asarray(theta), transport, grid, phys)
        P = [np.asarray(f) for f in pad((rho, *(jnp.asarray(v) for v in u), jnp.asarray(theta)), grid, 2,
                                        velocity=1, theta=4, walls=T)]
        Pk = [np.asarray(f) for f in pad(transport, grid, 2)]
        p_f = [float(m.friction.frictional_pressure(w, m.phi_max)) for w in (1.5 * phi[0] - 0.5 * phi[1],
                                                                              1.5 * phi[-1] - 0.5 * phi[-2])]
    h, s = grid.spacing[0], wall.slip_regularisation * 2.0 * speed
    for side, (c, g) in enumerate(((2, 1), (-3, -2))):  # (wall cell, ghost) in the padded arrays
        i = 0 if side == 0 else -1
        phi_w = 1.5 * phi[i] - 0.5 * phi[i - 1 if side else 1]
        theta_w = 1.5 * theta[i] - 0.5 * theta[i - 1 if side else 1]
        chi = float(m.chi(phi_w))
        c_jj = RHO_S * jj_friction(wall, phi_w, chi, theta_w)
        slip = np.array([0.5 * (P[1 + j][c] + P[1 + j][g]) - walls[side].velocity[j] for j in (1, 2)])
        size = float(np.hypot(*slip))
        assert p_f[side] > 0.0 and size > s
        eta, kap = (0.5 * (Pk[k][c] + Pk[k][g]) for k in (0, 2))
        stress = np.array([eta * (P[1 + j][c] - P[1 + j][g]) / h for j in (1, 2)])
        traction = jj_frictional_wall_stress(wall, p_f[side], size, s) / size * slip
        np.testing.assert_allclose(stress, c_jj * slip + traction, rtol=1e-10, atol=1e-12 * abs(stress).max())
        assert np.abs(traction).max() > 0.1 * np.abs(stress).max()  # the traction matters here
        heat_out = kap * (P[4][c] - P[4][g]) / h
        np.testing.assert_allclose(heat_out, RHO_S * jj_dissipation(wall, phi_w, chi, theta_w) - c_jj * size**2,
                                   rtol=1e-10)


@pytest.mark.analytic
@pytest.mark.parametrize("mu", [0.0, 0.5])
def test_closed_form_uniform_shear_with_a_sheared_chi_is_a_steady_state_of_the_3d_equations(mu: float) -> None:
    """χ(φ, s) of FrictionalPowerLaw Eq. (3): the 3D cells see it through their shear measure d√(2S:S)/√θ, and
    the closed form of ``ktgf shear`` (a fixed point in s) is their steady state, with its pressure."""
    m = get_model("frictional", mu=mu, shear_amplitude=0.4)
    assert m.shear_dependent
    grid = _shear_grid(8)
    phys = _physics(m, "uniform-shear", grid)
    theta, tau, p = _closed_form(m, 0.5)
    U = add_base_flow(conservative(jnp.full(grid.cells, RHO_S * 0.5), jnp.zeros((3, *grid.cells)),
                                   jnp.full(grid.cells, theta)), grid)
    dU = [np.asarray(x) for x in jax.jit(rhs)(tuple(U), grid, phys, Numerics(), 0.21)]
    assert np.max(np.abs(dU[4])) < 1e-10 * tau * RATE
    P = np.asarray(stress_tensor(U, 0.0, grid, phys))
    np.testing.assert_allclose(-P[3], tau, rtol=1e-10)
    np.testing.assert_allclose(P[:3], p, rtol=1e-10)
    # and the sheared χ is seen: without it the pressure differs by far more than the tolerance
    assert abs(_closed_form(m.with_options(shear_amplitude=0.0), 0.5)[2] / p - 1.0) > 0.05
