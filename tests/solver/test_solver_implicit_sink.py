"""The collisional sink in the implicit part of the IMEX scheme (``numerics.sink = "implicit"``).

Oracles from outside the code: Haff's law θ_H(t) = θ0/(1 + t/t_H)² for the homogeneous cooling gas
(its error must fall with the second power of Δt, also at steps 3× the explicit cooling limit
0.5/ζ0), positivity and monotone cooling when the step is left to the implicit sink's own limit
(ζ0Δt ≤ 2: ARS(2,2,2) stays positive below 1 + √2), the 1D Couette solver for the steady dense
Couette cell, and the config checks (one line naming the field).
"""

from __future__ import annotations

import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.errors import InputError
from ktgf.hcs.haff import haff_temperature
from ktgf.solver.config import parse_config
from ktgf.solver.grid import Grid
from ktgf.solver.initial import haff_time, uniform_fields
from ktgf.solver.physics import Physics
from ktgf.solver.state import conservative, primitive
from ktgf.solver.stepping import Numerics, advance, limits

PHI0, E, D, RHO_S, THETA0 = 0.4, 0.7, 1e-3, 2500.0, 1e-4


def _cooling_box():
    m = get_model("ret")
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max, hcs=True)
    grid = Grid((4, 4, 4), (0.4,) * 3)  # uniform: cells of 100 d, so that no Courant limit binds
    U0 = conservative(*uniform_fields(grid, phys, PHI0, THETA0))
    return grid, phys, U0


def _theta(U) -> float:
    return float(np.mean(np.asarray(primitive(U))[4]))


@pytest.mark.analytic
def test_haff_law_second_order_beyond_the_cooling_limit() -> None:
    grid, phys, U0 = _cooling_box()
    t_h = haff_time(phys, PHI0, THETA0)
    t_end = 3.0 * t_h  # = 6/ζ0(θ0)
    cooling_limit = float(np.asarray(limits(U0, grid, phys, Numerics()))[3])  # the explicit sink's 0.5/ζ0(θ0)
    errors = []
    for n in (4, 8, 16, 32, 64):
        num = Numerics(sink="implicit", dt_max=t_end / n, implicit_tol=1e-12)
        U, t, steps, status, _ = advance(U0, 0.0, t_end, 10**6, grid, phys, num)
        assert int(status) == 0 and float(t) == t_end and int(steps) in (n, n + 1)  # n + 1: round-off of t_end/n
        errors.append(abs(_theta(U) / float(haff_temperature(t_end, THETA0, t_h)) - 1.0))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    print("dt / explicit cooling limit", t_end / 4 / cooling_limit, "errors", errors, "orders", orders)
    assert t_end / 4 / cooling_limit > 2.9  # the coarsest step is 3x what the explicit sink may take
    assert np.all(orders > 1.8) and errors[-1] < 1e-3, (errors, orders)


@pytest.mark.analytic
def test_steps_at_the_implicit_sink_limit_keep_theta_positive_and_cooling() -> None:
    grid, phys, U0 = _cooling_box()
    explicit = float(np.asarray(limits(U0, grid, phys, Numerics()))[3])
    implicit = float(np.asarray(limits(U0, grid, phys, Numerics(sink="implicit")))[3])
    assert implicit == pytest.approx(4.0 * explicit, rel=1e-12)  # SINK_COURANT/ζ0 against cfl_source/ζ0
    num = Numerics(sink="implicit")  # no dt_max: the implicit sink's limit sets every step
    theta, U, t = [THETA0], U0, 0.0
    for _ in range(10):
        U, t, steps, status, _ = advance(U, t, 1e30, 1, grid, phys, num)
        assert int(status) == 0 and int(steps) == 1
        theta.append(_theta(U))
    assert np.all(np.diff(theta) < 0) and theta[-1] > 0.0
    # L-stable: far past the cooling time the gas keeps cooling at about Haff's rate, not faster or oscillating
    t_h = haff_time(phys, PHI0, THETA0)
    assert 0.3 < theta[-1] / float(haff_temperature(float(t), THETA0, t_h)) < 3.0


@pytest.mark.contract
def test_implicit_sink_needs_imex_and_is_refused_in_one_line() -> None:
    base = {"model": {"name": "ret", "restitution": 0.7}, "initial": {"solid_fraction": 0.3, "temperature": 1e-4},
            "grid": {"cells": [8, 8], "length_d": 8.0}, "time": {"end": 1.0, "outputs": 1, "scheme": "ssprk3"},
            "numerics": {"sink": "implicit"}}
    with pytest.raises(InputError, match="numerics.sink = 'implicit' needs time.scheme"):
        parse_config(base)
    base["numerics"] = {"sink": "semi"}
    with pytest.raises(InputError, match="sink"):
        parse_config(base)
    with pytest.raises(InputError, match="sink 'implicit' needs the imex scheme"):
        Numerics(scheme="ssprk3", sink="implicit")


@pytest.mark.analytic
@pytest.mark.slow
def test_dense_couette_with_implicit_sink_and_acoustics_reaches_the_1d_solver() -> None:
    """examples/couette_dense.toml (φ̄ 0.5, 4×64×4) with the sink and the pressure waves implicit: the
    step is set by the flow speed (binding limit cfl, not cooling) and the steady profiles are within
    1 % of the 1D solver, as with both explicit (tests/solver/test_solver_dense_shear.py).  cfl = 0.2: at 0.4
    this random start diverges at step 2 whatever the sink (acoustic Courant numbers of tens; with the
    explicit sink its 0.2/ζ limit kept the step below that)."""
    import tomllib
    from pathlib import Path

    from ktgf.solver.run import Simulation

    data = tomllib.loads((Path(__file__).resolve().parents[2] / "examples" / "couette_dense.toml").read_text())
    data["numerics"] = {"acoustics": "implicit", "sink": "implicit", "cfl": 0.2}
    sim = Simulation(parse_config(data))
    sim.run(progress=False, write_files=False)
    ver = sim.verification
    print(ver["max_rel_error"], ver["run"])
    assert ver["steady"]["reached"], ver["steady"]
    assert ver["run"]["binding_step_limit"] == "cfl"
    assert max(ver["max_rel_error"].values()) < 0.01, ver["max_rel_error"]
    tau = np.asarray(ver["wall_shear_stress_Pa"]["run"]) / np.asarray(ver["wall_shear_stress_Pa"]["reference"])
    assert np.max(np.abs(tau - 1.0)) < 0.01, ver["wall_shear_stress_Pa"]


@pytest.mark.analytic
def test_couette_3d_perturbation_measure() -> None:
    """benchmarks/couette_3d_perturbation.py (the 3D part of a Couette state, docs/solver.md): zero for a
    state uniform in x and z, the rms of an added x–z mode otherwise."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from couette_3d_perturbation import plane_deviation

    nx, ny, nz = 8, 6, 4
    y = np.linspace(0.1, 0.9, ny)[None, :, None]
    rho = RHO_S * (0.5 + 0.05 * y) * np.ones((nx, ny, nz))
    u = np.zeros((3, nx, ny, nz))
    u[0] = (y - 0.5) * np.ones((nx, ny, nz))
    U = np.stack([rho, *(rho * u), rho * (0.5 * (u**2).sum(0) + 1.5 * 1e-3)])
    assert all(v < 1e-12 for v in plane_deviation(U, RHO_S).values())
    x = np.arange(nx)[:, None, None]
    u[2] = 1e-3 * np.sin(2 * np.pi * x / nx) * np.ones((nx, ny, nz))  # a spanwise velocity varying along x
    U = np.stack([rho, *(rho * u), rho * (0.5 * (u**2).sum(0) + 1.5 * 1e-3)])
    dev = plane_deviation(U, RHO_S)
    assert dev["u_z"] == pytest.approx(1e-3 / np.sqrt(2.0), rel=1e-12) and dev["phi"] < 1e-12


@pytest.mark.analytic
@pytest.mark.slow(minutes=1.9)
def test_the_dense_couette_chain_to_3d_reaches_the_1d_solver_from_a_uniform_start(tmp_path, monkeypatch) -> None:
    """The shipped chain examples/couette_dense_3d.toml (φ̄ 0.5; `ktgf run` runs the 4 × 64 × 4 slab of
    couette_dense.toml first, from a uniform start, then the cube with implicit acoustics and sink), with the cube
    16 × 64 × 16 (16 d × 10 d × 16 d, the shipped spacing) instead of 64³: steady within a few hundred steps,
    within 1 % of the 1D solver in u, φ, θ and the wall stresses, as is the slab (the shipped example, 64 cells
    across the gap), and the 3D part of its perturbation decays
    (docs/solver.md "Dense sheared flows in 3D").  The 64³ chains as shipped (10 and 15 worker-minutes, too long
    for CI) are run and timed by benchmarks/couette_dense_chain.py, which checks the same 1 %."""
    import json
    import sys
    from pathlib import Path

    from ktgf.solver.chain import run_chain

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from couette_3d_perturbation import plane_deviation

    examples = Path(__file__).resolve().parents[2] / "examples"
    cube = (examples / "couette_dense_3d.toml").read_text()
    for shipped, smaller in (("cells = [64, 64, 64]", "cells = [16, 64, 16]"),
                             ("length_d = [64.0, 10.0, 64.0]", "length_d = [16.0, 10.0, 16.0]")):
        assert shipped in cube
        cube = cube.replace(shipped, smaller)
    (tmp_path / "couette_dense_3d.toml").write_text(cube)
    (tmp_path / "couette_dense.toml").write_text((examples / "couette_dense.toml").read_text())
    monkeypatch.chdir(tmp_path)  # the stages' output folders are relative to the working directory
    sim, _ = run_chain(tmp_path / "couette_dense_3d.toml", progress=False)
    slab = json.loads((tmp_path / "couette_dense_run" / "verification.json").read_text())
    assert slab["steady"]["reached"] and sim.verification["started_from"]["cells"] == [4, 64, 4]
    ver = sim.verification
    assert ver["run"]["cells"] == [16, 64, 16]
    assert ver["steady"]["reached"] and ver["run"]["step_count"] < 300, (ver["steady"], ver["run"]["step_count"])
    assert slab["cells_across_gap"] == ver["cells_across_gap"] == 64
    for stage in (slab, ver):  # the slab is examples/couette_dense.toml as shipped
        assert max(stage["max_rel_error"].values()) < 0.01, stage["max_rel_error"]
        tau = np.asarray(stage["wall_shear_stress_Pa"]["run"]) / np.asarray(stage["wall_shear_stress_Pa"]["reference"])
        assert np.max(np.abs(tau - 1.0)) < 0.01, stage["wall_shear_stress_Pa"]
    start = plane_deviation(np.asarray(sim.initial_state()), RHO_S)
    end = plane_deviation(np.asarray(sim.state), RHO_S)
    assert end["phi"] < 0.3 * start["phi"] and end["u_y"] < 0.3 * start["u_y"], (start, end)
