"""Implicit acoustics (``numerics.acoustics = "implicit"``, :mod:`ktgf.solver.acoustics`).

Oracles from outside the solver:
* the sound (longitudinal) eigenmode of the linearised HCS equations (:mod:`ktgf.hcs.stability`,
  through :func:`ktgf.solver.initial.single_mode`): its complex rate at an acoustic Courant number
  near 1, within the 2 % of the explicit-acoustics tests (tests/solver/test_solver_linear.py);
* the convergence order of the ARS(2,2,2) pair: a finite-amplitude sound wave at φ = 0.5 with
  steps 2–8 times the acoustic limit against a 64× finer step, error ∝ Δt²;
* conservation: Σρ and Σρu of a periodic box with a mean flow and random perturbations change by
  round-off only at steps far beyond the acoustic limit;
* bad input: one-line errors naming the field.
The dense Couette cell against the 1D Couette solver is in tests/solver/test_solver_dense_shear.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.growth import fit_rate, fourier_coefficient, temporal_orders

from ktgf.closures import get_model
from ktgf.closures.coefficients import mean_free_path
from ktgf.errors import InputError
from ktgf.solver.config import parse_config
from ktgf.solver.grid import Grid
from ktgf.solver.initial import single_mode, t_of_tau
from ktgf.solver.physics import Physics
from ktgf.solver.state import conservative, primitive
from ktgf.solver.stepping import Numerics, advance, limits

E, D, RHO_S, THETA0 = 0.8, 1e-3, 2500.0, 1e-4


def _box(phi: float, cells: tuple[int, ...], kstar: float, amplitude: float):
    m = get_model("ret")
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max)
    grid = Grid(cells, (2.0 * math.pi * mean_free_path(phi, D) / kstar,) * len(cells))
    U, s, vec = single_mode(grid, phys, phi, THETA0, (1,) + (0,) * (len(cells) - 1), "longitudinal", amplitude, 1)
    return phys, grid, U, s, vec


def acoustic_step(U, grid: Grid, phys: Physics) -> float:
    """Δx/max(|u| + c): the step at acoustic Courant number 1 of the explicit-acoustics scheme."""
    return float(np.asarray(limits(U, grid, phys, Numerics(cfl=1.0)))[0])


@pytest.mark.analytic
def test_sound_mode_rate_at_acoustic_courant_number_near_one() -> None:
    phi = 0.25
    phys, grid, U, s, vec = _box(phi, (64,), 0.1, 1e-6)
    dt = 0.8 * acoustic_step(U, grid, phys)
    num = Numerics(acoustics="implicit", dt_max=dt, cfl_source=0.99)
    taus = np.linspace(0.0, min(3.0 / abs(s.real), 30.0), 9)
    t, proj = 0.0, []
    for target in t_of_tau(taus, phys, phi, THETA0):
        U, t, _, status, _ = advance(U, t, float(target), 10**6, grid, phys, num)
        assert int(status) == 0
        W = np.asarray(primitive(U))
        th = W[4].mean()
        y = np.array([fourier_coefficient(W[0] / W[0].mean(), grid, (1,)), fourier_coefficient(W[4] / th, grid, (1,)),
                      fourier_coefficient(W[1] / math.sqrt(2.0 * th), grid, (1,))])
        proj.append(np.vdot(vec, y) / np.vdot(vec, vec))
    measured = fit_rate(taus, np.array(proj))
    print(f"relative error {abs(measured - s) / abs(s):.4f}", measured, s)
    assert abs(measured - s) <= 0.02 * abs(s), (measured, s)


@pytest.mark.analytic
def test_implicit_acoustics_is_second_order_in_time_beyond_the_acoustic_limit() -> None:
    phi = 0.5
    phys, grid, U0, s, _ = _box(phi, (64,), 0.1, 0.05)
    dt1 = acoustic_step(U0, grid, phys)
    t_end = float(t_of_tau(math.pi / abs(s.imag), phys, phi, THETA0))  # half a sound period
    n0 = math.ceil(t_end / (8.0 * dt1))  # the coarsest step: 8 acoustic limits
    errors, orders = temporal_orders(U0, grid, phys, t_end, n0, [0, 1, 4], THETA0, acoustics="implicit")
    print("dt / acoustic limit", t_end / n0 / dt1, "errors", errors, "orders", orders)
    assert t_end / n0 / dt1 > 6.0
    assert np.all(orders > 1.8), orders


@pytest.mark.analytic
def test_mass_and_momentum_are_conserved_to_round_off_at_large_acoustic_courant_numbers() -> None:
    m = get_model("ret")
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max)
    grid = Grid((16, 16), (16e-3, 16e-3))
    rng = np.random.default_rng(3)
    shape = grid.cells
    phi = 0.4 * (1.0 + 0.05 * rng.standard_normal(shape))
    u = np.stack([0.02 + 0.005 * rng.standard_normal(shape), 0.005 * rng.standard_normal(shape), np.zeros(shape)])
    U0 = conservative(RHO_S * phi, u, THETA0 * (1.0 + 0.05 * rng.standard_normal(shape)))
    dt = 5.0 * acoustic_step(U0, grid, phys)
    num = Numerics(acoustics="implicit", cfl=1.0, cfl_source=0.99, dt_max=dt)
    U, t, steps, status, _ = advance(U0, 0.0, 10.0 * dt, 10**6, grid, phys, num)
    assert int(status) == 0 and int(steps) >= 10
    before, after = np.asarray(U0).sum(axis=(1, 2)), np.asarray(U).sum(axis=(1, 2))
    scale = np.abs(np.asarray(U0)[:3]).sum(axis=(1, 2))
    drift = np.abs(after[:3] - before[:3]) / scale
    print("relative drift of Σρ, Σρu_x, Σρu_y:", drift)
    assert np.all(drift < 1e-13), drift
    assert not np.allclose(np.asarray(U), np.asarray(U0))  # it moved


def _config(**numerics: object) -> dict:
    return {"model": {"name": "ret", "restitution": 0.8},
            "initial": {"solid_fraction": 0.3, "temperature": 1e-4},
            "grid": {"cells": [8, 8], "length_d": 8.0},
            "time": {"end": 1.0, "outputs": 1, "scheme": "ssprk3"},
            "numerics": numerics}


@pytest.mark.contract
def test_bad_acoustics_options_are_refused_in_one_line_naming_the_field() -> None:
    with pytest.raises(InputError, match="numerics.acoustics") as exc:
        parse_config(_config(acoustics="fast"))
    assert "\n" not in str(exc.value)
    with pytest.raises(InputError, match="numerics.acoustics = 'implicit' needs time.scheme"):
        parse_config(_config(acoustics="implicit"))
    with pytest.raises(InputError, match="acoustics"):
        Numerics(acoustics="fast")


@pytest.mark.analytic
@pytest.mark.slow
def test_dense_couette_with_implicit_acoustics_reaches_the_1d_solver_within_one_percent() -> None:
    """examples/couette_dense.toml (φ̄ 0.5, 4×64×4) with implicit acoustics: the criteria of the
    explicit-acoustics run in tests/solver/test_solver_dense_shear.py (1 % in u, φ, θ and the wall stresses)."""
    import tomllib
    from pathlib import Path

    from ktgf.solver.run import Simulation

    data = tomllib.loads((Path(__file__).resolve().parents[2] / "examples" / "couette_dense.toml").read_text())
    data["numerics"] = {"acoustics": "implicit", "cfl_source": 0.2}
    sim = Simulation(parse_config(data))
    sim.run(progress=False, write_files=False)
    ver = sim.verification
    print(ver["max_rel_error"], ver["run"])
    assert ver["steady"]["reached"] and ver["cells_across_gap"] == 64, ver["steady"]
    assert max(ver["max_rel_error"].values()) < 0.01, ver["max_rel_error"]
    tau = np.asarray(ver["wall_shear_stress_Pa"]["run"]) / np.asarray(ver["wall_shear_stress_Pa"]["reference"])
    assert np.max(np.abs(tau - 1.0)) < 0.01, ver["wall_shear_stress_Pa"]


@pytest.mark.analytic
@pytest.mark.slow  # 36-42 s, run twice in CI's default steps (with and without the compiler)
def test_a_lees_edwards_box_with_implicit_acoustics_is_half_of_a_box_twice_as_tall() -> None:
    """A Lees–Edwards box (gradient y, flow z, random perturbation) and a box twice as tall holding it and,
    above, its Galilean image (velocity +γ̇L e_z): the lower half of the tall box must evolve as the box,
    because the box's boundary face sees what the tall box's interior face sees.  Explicit SSP-RK3 does so to
    round-off; with the pressure waves implicit the two differ only by the IMEX split (the frozen h₀, the
    stages at which each part of the flux is taken) and converge at second order — only if the implicit
    mass flux carries the image frame's flow momentum across the boundary (without it they stay 43 % of
    the change apart in ρu_z).  Σρ, Σρu_x, Σρu_y telescope to round-off."""
    from ktgf.solver.boundaries import Boundaries
    from ktgf.solver.flows import add_base_flow
    from ktgf.solver.initial import random_velocity
    from ktgf.solver.state import conservative_fields, primitive_fields

    rate, L = 5.0, 8 * D
    # e 0.97: the explicit collisional sink allows steps beyond the acoustic limit
    phys = Physics(get_model("ret"), 0.97, D, RHO_S, 0.99 * get_model("ret").phi_max)
    box = Grid((4, 8), (4 * D, L), Boundaries(("periodic", "lees-edwards"), shear_rate=rate, flow=2))
    tall = Grid((4, 16), (4 * D, 2 * L), Boundaries(("periodic", "lees-edwards"), shear_rate=rate, flow=2))
    S = add_base_flow(random_velocity(box, phys, 0.4, THETA0, 0.1, 1, 2), box)
    W = list(primitive_fields(tuple(S)))
    W[3] = W[3] + rate * L
    T = np.concatenate([np.asarray(S), np.asarray(conservative_fields(tuple(W)))], axis=2)
    dt_ac = acoustic_step(S, box, phys)
    t_end = 8.0 * dt_ac

    def both(num: Numerics) -> tuple[np.ndarray, np.ndarray]:
        (a, _, _, sa, _), (b, _, _, sb, _) = (advance(U, 0.0, t_end, 10**6, g, phys, num)
                                              for U, g in ((S, box), (T, tall)))
        assert int(sa) == 0 and int(sb) == 0
        return np.asarray(a), np.asarray(b)[:, :, :8]

    a, b = both(Numerics(cfl=1.0, cfl_source=0.99, dt_max=0.3 * dt_ac))
    change = np.abs(a - np.asarray(S)).max(axis=(1, 2))
    assert np.all(np.abs(a - b).max(axis=(1, 2)) < 1e-8 * change)
    errors = []
    for ratio in (2.0, 1.0, 0.5):
        a, b = both(Numerics(acoustics="implicit", cfl=1.0, cfl_source=0.99, dt_max=ratio * dt_ac, scheme="imex"))
        errors.append(np.max(np.abs(a - b).max(axis=(1, 2)) / change))
        sums = a.reshape(5, -1).sum(axis=1) - np.asarray(S).reshape(5, -1).sum(axis=1)
        assert abs(sums[0]) < 1e-13 * a[0].sum() and np.all(np.abs(sums[1:3]) < 1e-13 * np.abs(a[1:4]).sum())
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    print("max difference / change", errors, "orders", orders)
    assert errors[-1] < 2e-3 and np.all(orders > 1.6), (errors, orders)
