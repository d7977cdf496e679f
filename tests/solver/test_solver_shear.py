"""Lees–Edwards boundaries and the uniform-shear case of the 3D solver.

Oracles from outside the solver: an analytic shearing-periodic field (its ghost-cell images),
the closed-form uniform shear of :mod:`ktgf.shear.steady` (θ, η, p of the energy
balance ηγ̇² = (3/2)ρθζ0, model.md §9), and exact conservation of mass.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers.chute_case import chute_case as _chute
from helpers.couette_case import couette_case as _couette
from helpers.couette_case import parse as _parse
from helpers.couette_case import run_from_profile_within_one_percent

from ktgf.closures import get_model
from ktgf.errors import InputError
from ktgf.solver.boundaries import Boundaries, pad
from ktgf.solver.cases.uniform_shear import uniform_shear_reference
from ktgf.solver.config import load_config, parse_config
from ktgf.solver.flows import add_base_flow, stress_tensor
from ktgf.solver.grid import Grid
from ktgf.solver.physics import Physics
from ktgf.solver.run import Simulation, _x64
from ktgf.solver.state import conservative
from ktgf.solver.stepping import Numerics, rhs

ROOT = Path(__file__).resolve().parents[2]
D, RHO_S, E, PHI, RATE = 1e-3, 2500.0, 0.8, 0.3, 50.0


def _ghost_error(n: int, t: float) -> tuple[float, float]:
    """Max error of the Lees–Edwards ghost cells of cos(k(x − Δ(t) y/L_y)) (exactly LE-periodic), and
    the error amplitude of linear interpolation between cells, |(1 − w) + w e^{−ikh} − e^{−ikwh}|
    (w: the fractional cell shift), which is O((kh)²)."""
    Lx, Ly = 1.0, 0.5
    grid = Grid((n, n // 2), (Lx, Ly), Boundaries(("periodic", "lees-edwards"), shear_rate=RATE, flow=0))
    delta = RATE * Ly * t
    k = 2.0 * math.pi / Lx

    def field(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.cos(k * (x - delta * y / Ly))

    hx, hy = grid.spacing
    x = (np.arange(-2, n + 2) + 0.5) * hx
    y = (np.arange(-2, n // 2 + 2) + 0.5) * hy
    X, Y = np.meshgrid(x, y, indexing="ij")
    inner = field(*grid.mesh())
    with _x64(True):
        P = np.asarray(jax.jit(lambda f, g, t: pad((f,), g, 2, t)[0])(jnp.asarray(inner), grid, t))
    w = (delta / hx) % 1.0
    amplitude = abs((1 - w) + w * np.exp(-1j * k * hx) - np.exp(-1j * k * w * hx))
    return float(np.max(np.abs(P - field(X, Y)))), float(amplitude)


@pytest.mark.analytic
def test_lees_edwards_ghosts_image_a_shearing_periodic_field_by_linear_interpolation() -> None:
    t = 0.0123  # Δ = 0.3075 L_x: a fractional number of cells on every grid
    for n in (16, 32, 64):
        err, amplitude = _ghost_error(n, t)
        h = 1.0 / n
        assert 0.9 * amplitude < err <= amplitude * (1 + 1e-9), (n, err, amplitude)
        assert amplitude < 0.125 * (2 * math.pi * h) ** 2  # second order: w(1 − w)(kh)²/2 at most
    assert _ghost_error(16, 0.0)[0] < 1e-13  # no displacement: plain periodic images


@pytest.mark.analytic
def test_lees_edwards_ghosts_carry_the_velocity_jump_on_the_flow_component_only() -> None:
    grid = Grid((8, 6), (1.0, 0.6), Boundaries(("periodic", "lees-edwards"), shear_rate=RATE, flow=0))
    y = grid.mesh()[1]
    u = [jnp.asarray(RATE * (y - 0.3)), jnp.zeros(grid.cells), jnp.zeros(grid.cells)]
    with _x64(True):
        padded = jax.jit(lambda u, g: (pad(u, g, 2, 0.37, velocity=0), pad(u, g, 2, 0.37, velocity=0, affine=False)))
        full, linear = ([np.asarray(f) for f in x] for x in padded(u, grid))
    yg = (np.arange(-2, 8) + 0.5) * 0.1
    np.testing.assert_allclose(full[0][4], RATE * (yg - 0.3), rtol=0, atol=1e-12)  # the profile continues
    np.testing.assert_allclose(linear[0][4, 1], RATE * (0.55 - 0.3), rtol=1e-12)  # image of the top cell, no jump
    assert np.all(full[1] == 0.0) and np.all(full[2] == 0.0)


def _shear_state(grid: Grid, phys: Physics, theta: float) -> jnp.ndarray:
    U = conservative(jnp.full(grid.cells, RHO_S * PHI), jnp.zeros((3, *grid.cells)), jnp.full(grid.cells, theta))
    return add_base_flow(U, grid)


@pytest.mark.analytic
@pytest.mark.parametrize("model", ["ret", pytest.param("visc-div", marks=pytest.mark.slow)])
def test_closed_form_uniform_shear_is_a_steady_state_of_the_discrete_equations(model: str) -> None:
    m = get_model(model)
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max)
    grid = Grid((8, 8), (8 * D, 8 * D), Boundaries(("periodic", "lees-edwards"), shear_rate=RATE, flow=0))
    ref = uniform_shear_reference(phys, PHI, RATE)
    with _x64(True):
        U = _shear_state(grid, phys, ref["theta"])
        f = jax.jit(rhs)
        dU = [np.asarray(x) for x in f(tuple(U), grid, phys, Numerics(), 0.21)]
        heating = ref["eta"] * RATE**2  # the scale of each term of the energy balance [W/m³]
        assert np.max(np.abs(dU[4])) < 1e-9 * heating
        assert np.max(np.abs(dU[1])) < 1e-9 * ref["eta"] * RATE / D
        # Hotter than the closed form, the gas cools; colder, it heats (one root of the balance).
        hot = np.asarray(f(tuple(_shear_state(grid, phys, 2 * ref["theta"])), grid, phys, Numerics(), 0.0)[4])
        cold = np.asarray(f(tuple(_shear_state(grid, phys, 0.5 * ref["theta"])), grid, phys, Numerics(), 0.0)[4])
        assert np.all(hot < -0.1 * heating) and np.all(cold > 0.1 * heating)
        # The box-averaged stress of the state is the closed form's: P_xy = −ηγ̇, P_ii = p.
        P = np.asarray(stress_tensor(U, 0.0, grid, phys))
    np.testing.assert_allclose(P[3], -ref["eta"] * RATE, rtol=1e-12)
    np.testing.assert_allclose(P[:3], ref["p"], rtol=1e-12)


def _case(cells: list[int], axis: str, flow: str, end: float, extra: str = "") -> str:
    return f"""
[case]
kind = "uniform-shear"
[model]
name = "ret"
restitution = {E}
[initial]
solid_fraction = {PHI}
temperature = 4e-4
perturbation = "random"
amplitude = 0.02
[grid]
cells = {cells}
length_d = 6.0
[boundaries]
{axis} = {{ kind = "lees-edwards", shear_rate = {RATE}, flow = "{flow}" }}
[time]
end = {end}
unit = "strain"
outputs = 4
{extra}
[output]
png = false
vtk = false
"""


@pytest.mark.analytic
def test_uniform_shear_run_relaxes_to_the_closed_form_and_conserves_mass() -> None:
    # 1D grid along the gradient x, flow along y (no image displacement: the velocity jump only).
    sim = Simulation(_parse(_case([8], "x", "y", 40.0)))
    with sim.precision():
        U0 = np.asarray(sim.initial_state())
    ds = sim.run(progress=False, write_files=False)
    err = sim.verification["max_rel_error"]
    assert max(err.values()) < 1e-4, err
    assert set(err) == {"theta", "eta", "p"}
    with sim.precision():
        U1 = np.asarray(sim.state)
    assert abs(U1[0].sum() / U0[0].sum() - 1.0) < 1e-13
    assert ds.attrs["case"] == "uniform-shear" and "tau" not in ds


@pytest.mark.analytic
@pytest.mark.parametrize("scheme", ["ssprk3", pytest.param("imex", marks=pytest.mark.slow)])
def test_lees_edwards_box_with_fractional_image_shift_conserves_mass_and_cross_flow_momentum(scheme: str) -> None:
    """The lower Lees–Edwards face flux is the upper one handed back through the boundary
    (:func:`~ktgf.solver.boundaries.lees_edwards_faces`): Σρ, Σρu_y (gradient) and Σρu_z telescope to
    round-off over 65 steps with a fractional shift and a strong random perturbation, and Σρu_x
    changes (the boundary's Galilean rule).  Before, mass drifted by 3e-5 and Σρu_y by 1.6e-3 of
    Σ|ρu| here."""
    from ktgf.solver.initial import random_velocity
    from ktgf.solver.stepping import advance

    with _x64(True):
        phys = Physics(get_model("ret"), E, D, RHO_S, 0.99, None)
        grid = Grid((8, 8, 4), (8 * D, 8 * D, 4 * D), Boundaries(("periodic", "lees-edwards", "periodic"),
                                                                 shear_rate=RATE, flow=0))
        num = Numerics(0.4, 0.4, 0.5, "vanleer", "hll", scheme=scheme)
        U0 = add_base_flow(random_velocity(grid, phys, PHI, 1.5e-3, 0.1, 1, 2), grid)
        t_end = 0.0371  # Δ/Δx = γ̇L_y t/Δx mod 8 passes through fractional values throughout
        U1, t, n, status, _ = advance(U0, 0.0, t_end, 100000, grid, phys, num)
        assert int(status) == 0 and float(t) == pytest.approx(t_end) and int(n) > 50
        U0, U1 = np.asarray(U0), np.asarray(U1)
    s0, s1 = U0.reshape(5, -1).sum(axis=1), U1.reshape(5, -1).sum(axis=1)
    momentum_scale = np.abs(U0[1:4]).sum()
    assert abs(s1[0] / s0[0] - 1.0) < 1e-13
    assert abs(s1[2] - s0[2]) < 1e-13 * momentum_scale and abs(s1[3] - s0[3]) < 1e-13 * momentum_scale
    assert abs(s1[1] - s0[1]) > 1e-3 * momentum_scale  # the flow component is not conserved


@pytest.mark.contract
@pytest.mark.parametrize("text, field", [
    ('[case]\nkind = "cooling"\n[boundaries]\ny = { kind = "lees-edwards", shear_rate = 5.0, flow = "x" }',
     "boundaries.y.kind"),
    ('[case]\nkind = "uniform-shear"', "case.kind"),
    ('[case]\nkind = "uniform-shear"\n[boundaries]\ny = { kind = "lees-edwards", flow = "x" }', "boundaries.y"),
    ('[case]\nkind = "uniform-shear"\n[boundaries]\ny = { kind = "lees-edwards", shear_rate = 5.0, flow = "y" }',
     "boundaries"),
    ('[case]\nkind = "uniform-shear"\n[boundaries]\nz = { kind = "lees-edwards", shear_rate = 5.0, flow = "x" }',
     "boundaries.z.kind"),
    ('[case]\nkind = "uniform-shear"\n[boundaries]\ny = { kind = "lees-edwards", shear_rate = -5.0, flow = "x" }',
     "boundaries.y.shear_rate"),
])
def test_bad_case_or_boundary_config_is_one_line_naming_the_field(text: str, field: str) -> None:
    import tomllib

    base = tomllib.loads('[initial]\nsolid_fraction = 0.2\ntemperature = 1e-4\n[grid]\ncells = [8, 8]\n'
                         'length_d = 5.0\n[time]\nend = 1.0\nunit = "s"\n')
    data = {**base, **tomllib.loads(text)}
    with pytest.raises(InputError) as exc:
        parse_config(data)
    msg = str(exc.value)
    assert "\n" not in msg and field in msg, msg


@pytest.mark.contract
def test_haff_clock_is_refused_for_a_sheared_case() -> None:
    with pytest.raises(InputError, match="time.unit = 'tau' is for the cooling case"):
        _parse(_case([8], "x", "y", 1.0).replace('unit = "strain"', 'unit = "tau"'))


@pytest.mark.contract
def test_uniform_shear_example_parses() -> None:
    cfg = load_config(ROOT / "examples" / "uniform_shear.toml")
    assert cfg.case.kind == "uniform-shear" and cfg.boundaries.y.kind == "lees-edwards"


# --- planar Couette: Johnson–Jackson walls -------------------------------------------------------

@pytest.mark.analytic
@pytest.mark.slow
def test_one_d_couette_solution_is_kept_by_the_3d_solver_within_one_percent() -> None:
    """Started from the 1D solver's steady profile, the 3D solver (32 cells across the gap) stays
    within 1 % of it in u, φ, θ and in the wall stress; mass is conserved to round-off."""
    from ktgf.solver.cases.couette import couette_reference

    n = 32
    sim = Simulation(_parse(_couette([n], 10.0)))
    ref = couette_reference(sim.phys, sim.grid, 0.3)
    U0 = run_from_profile_within_one_percent(sim, ref, 0.3)
    with sim.precision():
        assert abs(float(np.asarray(sim.state)[0].sum()) / float(np.asarray(U0)[0].sum()) - 1) < 1e-12


@pytest.mark.analytic
def test_wall_ghosts_make_the_face_fluxes_the_johnson_jackson_conditions() -> None:
    """The central viscous and heat fluxes through the wall faces equal c u_sl and D − G of
    ktgf.couette.walls at the wall state (the ghost cells solve the Robin conditions)."""
    from ktgf.couette.walls import Wall, jj_dissipation, jj_friction
    from ktgf.solver.boundaries import WallSide, wall_terms

    m = get_model("ret")
    phys = Physics(m, 0.9, D, RHO_S, 0.99 * m.phi_max)
    wall = Wall(specularity=0.3, restitution=0.8)
    walls = (WallSide(wall, (0.0, -0.5, 0.0)), WallSide(wall, (0.0, 0.5, 0.0)))
    grid = Grid((8,), (8 * D,), Boundaries(("wall",), flow=1, walls=(walls,)))
    x = grid.centres(0) / (8 * D)
    phi = 0.3 + 0.05 * x**2
    theta = 1e-3 * (1.0 + x)
    u = np.zeros((3, 8))
    u[1] = 0.8 * (x - 0.5) + 0.1 * x**3
    with _x64(True):
        rho = jnp.asarray(RHO_S * phi)
        r = phys.reduced(rho)
        transport = phys.transport(rho, jnp.asarray(theta), r)

        @jax.jit
        def padded(rho, u, theta, transport, grid):
            T = wall_terms(rho, u, theta, transport, grid, phys)
            return pad((rho, *u, theta), grid, 2, velocity=1, theta=4, walls=T), pad(transport, grid, 2)

        P, Pk = padded(rho, [jnp.asarray(v) for v in u], jnp.asarray(theta), transport, grid)
        P, Pk = [np.asarray(f) for f in P], [np.asarray(f) for f in Pk]
    h = grid.spacing[0]
    for side, (c, g) in enumerate(((2, 1), (-3, -2))):  # (wall cell, ghost) in the padded arrays
        u_face = 0.5 * (P[2][c] + P[2][g])
        slip = u_face - walls[side].velocity[1]
        i = 0 if side == 0 else -1
        phi_w = 1.5 * phi[i] - 0.5 * phi[i - 1 if side else 1]
        theta_w = 1.5 * theta[i] - 0.5 * theta[i - 1 if side else 1]
        chi = float(m.chi(phi_w))
        c_jj = RHO_S * jj_friction(wall, phi_w, chi, theta_w)
        eta, kap = (0.5 * (Pk[k][c] + Pk[k][g]) for k in (0, 2))  # the face coefficients of the fluxes
        assert 0.7 < eta / float(transport[0][i]) < 1.3
        stress = eta * (P[2][c] - P[2][g]) / h  # η ∂u/∂n at the wall face (n into the medium)
        np.testing.assert_allclose(stress, c_jj * slip, rtol=1e-12)
        heat_out = kap * (P[4][c] - P[4][g]) / h  # κ ∂θ/∂n = −q·n: heat into the wall
        loss = RHO_S * jj_dissipation(wall, phi_w, chi, theta_w) - c_jj * slip**2
        np.testing.assert_allclose(heat_out, loss, rtol=1e-12)
        assert P[1][c] == -P[1][g]  # no flow through the wall (normal component odd)


@pytest.mark.analytic
@pytest.mark.slow
def test_couette_transient_converges_to_the_1d_solver_with_resolution() -> None:
    """From the linear profile, the transient (strain 150) reaches the 1D steady state; the
    deviation falls at second order with the cells across the gap (measured: u 0.22, 0.033,
    0.0061 %; φ 0.77, 0.20, 0.056 %; θ 2.0, 0.37, 0.070 %; wall stress 0.31, 0.030, 0.0015 % at
    16, 32, 64 cells; ≈ 100 s under load)."""
    errors = []
    for n in (16, 32, 64):
        sim = Simulation(_parse(_couette([n], 150.0)))
        sim.run(progress=False, write_files=False)
        ver = sim.verification
        tau = ver["wall_shear_stress_Pa"]
        errors.append([*ver["max_rel_error"].values(), abs(tau["run"][0] / tau["reference"][0] - 1)])
    errors = np.asarray(errors)
    assert np.all(errors[1] < 0.01), errors  # resolved (32 cells): within 1 % in u, φ, θ and the stress
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all(orders > 1.7), (errors, orders)


@pytest.mark.contract
def test_couette_example_parses() -> None:
    cfg = load_config(ROOT / "examples" / "couette_2d.toml")
    assert cfg.case.kind == "couette" and cfg.boundaries.y.kind == "wall"


# --- chute: gravity-driven layer -----------------------------------------------------------------



@pytest.mark.contract
@pytest.mark.parametrize("text, field", [
    ('kind = "chute"\ninclination_deg = 25.0', "boundaries"),
    ('kind = "couette"\ninclination_deg = 25.0', "case.inclination_deg"),
])
def test_chute_config_errors_name_the_field(text: str, field: str) -> None:
    import tomllib

    data = tomllib.loads(_chute([8], 1.0))
    data["case"] = tomllib.loads(text)
    if data["case"]["kind"] == "chute":
        del data["boundaries"]
    with pytest.raises(InputError) as exc:
        parse_config(data)
    assert field in str(exc.value) and "\n" not in str(exc.value), str(exc.value)


@pytest.mark.contract
def test_chute_example_parses_and_its_gravity_points_down_the_slope() -> None:
    from ktgf.solver.cases import get_case

    cfg = load_config(ROOT / "examples" / "chute_2d.toml")
    g = get_case("chute").gravity(cfg)
    z = math.radians(25.0)
    np.testing.assert_allclose(g, (9.81 * math.sin(z), -9.81 * math.cos(z), 0.0), rtol=1e-15)


@pytest.mark.analytic
@pytest.mark.slow
def test_chute_reaches_the_1d_inclined_layer() -> None:
    """32 cells across the column, t = 2.5 s: u, φ, θ within 1 % of the 1D solver and the base
    stress equal to the weight of the column ρ_s g sin ζ φ̄ H (the steady momentum balance)."""
    sim = Simulation(_parse(_chute([32], 2.5)))
    sim.run(progress=False, write_files=False)
    ver = sim.verification
    assert max(ver["max_rel_error"].values()) < 0.01, ver["max_rel_error"]
    weight = RHO_S * 9.81 * math.sin(math.radians(25.0)) * 0.3 * 10 * D
    assert abs(ver["base_shear_stress_Pa"]["run"] / weight - 1) < 1e-3, ver["base_shear_stress_Pa"]


@pytest.mark.contract
@pytest.mark.slow
@pytest.mark.parametrize("case", ["uniform-shear", "couette", "chute"])
def test_sheared_case_resumes_bit_for_bit_and_writes_its_files(tmp_path: Path, case: str) -> None:
    """Ctrl-C mid-run, resume: the final state, the case columns and verification.json equal the
    uninterrupted run's; <case>.nc, VTK and checkpoint are written for the case."""
    import tomllib

    import xarray as xr
    from helpers.vti import read_vti

    text = {"uniform-shear": lambda: _case([8, 8], "y", "x", 2.0),
            "couette": lambda: _couette([4, 8], 4.0, lengths="[4.0, 8.0]", axis="y", flow="x"),
            "chute": lambda: _chute([8, 4], 0.1, length_d=[10.0, 4.0])}[case]()
    data = tomllib.loads(text)
    data["time"]["outputs"] = 4
    data["time"]["max_steps_per_call"] = 20
    data["output"]["vtk"] = True
    cfg = parse_config(data)
    full = Simulation(cfg, tmp_path / "full")
    ds_full = full.run(progress=False)
    sim = Simulation(cfg, tmp_path / "split")
    calls = []

    def interrupt(info: dict) -> None:
        calls.append(info)
        if len(calls) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sim.run(progress=False, on_chunk=interrupt)
    resumed = Simulation(cfg, tmp_path / "split")
    ds_res = resumed.run(progress=False, resume=tmp_path / "split" / "checkpoint.npz")
    with full.precision():
        assert np.array_equal(np.asarray(resumed.state), np.asarray(full.state))
    for name in ds_full.data_vars:
        if name != "residual_history":
            assert np.array_equal(ds_res[name].values, ds_full[name].values), name
    ver = [json.loads((tmp_path / run / "verification.json").read_text()) for run in ("split", "full")]
    timing = ("wall_time_s", "cpu_time_s", "load_average", "wall_time_per_step_s")
    for v in ver:  # the run's timing differs between the two
        assert all(v["run"].pop(k) is not None for k in timing)
    assert ver[0] == ver[1]
    ds = xr.open_dataset(tmp_path / "full" / f"{case}.nc")
    assert ds.attrs["case"] == case and "stress_xy" in ds
    assert "solid_fraction" in read_vti(tmp_path / "full" / "fields_00004.vti")


@pytest.mark.analytic
@pytest.mark.slow
@pytest.mark.parametrize("example, tolerance", [("uniform_shear", 1e-4), ("couette_2d", 0.01), ("chute_2d", 0.01)])
def test_example_runs_to_its_reference(tmp_path: Path, example: str, tolerance: float) -> None:
    """``ktgf run examples/<example>.toml`` writes verification.json within the tolerance (run times:
    docs/examples.md)."""
    from typer.testing import CliRunner

    from ktgf.cli import app

    res = CliRunner().invoke(app, ["run", str(ROOT / "examples" / f"{example}.toml"), "-o", str(tmp_path),
                                   "--no-progress"])
    assert res.exit_code == 0, res.output
    ver = json.loads((tmp_path / "verification.json").read_text())
    assert max(ver["max_rel_error"].values()) < tolerance, ver
