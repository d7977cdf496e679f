"""Depth scaling of the inclined layer in the 3D solver against the 1D inclined-layer solver.

Bagnold's u(H) ∝ H^{3/2} holds for the model only in deep layers (RET at 19°: the local exponent
d ln u(H)/d ln H of the 1D solver is 1.64 at 30 d and within 0.01 of 1.5 beyond 90 d,
tests/couette/test_chute.py); the 3D runs here are shallow (10–15.6 d, what 2 cores allow), so the oracle
is the 1D solver's own exponent at the same depths, model, base and inventory
(:func:`ktgf.couette.chute.solve_chute`), not 3/2.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from helpers.chute_case import chute_case

from ktgf.solver.config import parse_config
from ktgf.solver.cases.chute import chute_reference
from ktgf.solver.run import Simulation

CELLS_PER_D = 3.2  # the chute example's resolution (32 cells over 10 d)


pytestmark = pytest.mark.analytic


def _config(depth_d: float) -> dict:
    """The chute of tests/solver/test_solver_shear.py at another depth: the same resolution, time ∝ H²."""
    scale = (depth_d / 10.0) ** 2
    return tomllib.loads(chute_case([int(round(CELLS_PER_D * depth_d))], 2.5 * scale, length_d=depth_d,
                                    outputs=int(round(25 * scale)), steady_tol=1e-4))


def surface_velocities(depth_d: float) -> tuple[float, float]:
    """u(H) of the 3D run (linear extrapolation of the two top cells to the surface) and of the 1D solver."""
    sim = Simulation(parse_config(_config(depth_d)))
    sim.run(progress=False, write_files=False)
    u = np.asarray(sim.history["u_profile"][-1])
    ref = chute_reference(sim.phys, sim.grid, sim.phi0)
    return 1.5 * u[-1] - 0.5 * u[-2], float(ref["u"].values[-1])


@pytest.mark.slow
def test_chute_surface_velocity_scales_with_depth_as_the_1d_solver_says() -> None:
    depths = [10.0, 12.5, 15.625]
    rows = np.array([surface_velocities(h) for h in depths])
    assert np.all(np.abs(rows[:, 0] / rows[:, 1] - 1.0) < 0.01), rows
    lnH = np.log(depths)
    slope_3d = np.diff(np.log(rows[:, 0])) / np.diff(lnH)
    slope_1d = np.diff(np.log(rows[:, 1])) / np.diff(lnH)
    assert np.all(np.abs(slope_3d - slope_1d) < 0.05), (slope_3d, slope_1d)
    assert math.isfinite(slope_3d.sum())
