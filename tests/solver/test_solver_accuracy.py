"""Time- and space-accuracy of the solver, measured (model.md §§1, 8).

* A uniform gas cools by Haff's law θ = θ0/(1 + t/t0)² (exact solution of the equations);
  the error must fall with the third power of the step for SSP-RK3 and the second for the
  IMEX scheme (whose explicit part integrates the sink).
* A smooth, finite-amplitude (nonlinear) wave converges at second order in space towards a
  fine-grid solution (MUSCL reconstruction, central viscous fluxes).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.closures.coefficients import mean_free_path
from ktgf.hcs.haff import cooling_time, haff_temperature
from ktgf.solver.grid import Grid
from ktgf.solver.initial import single_mode, t_of_tau, uniform_fields
from ktgf.solver.physics import Physics
from ktgf.solver.state import conservative, primitive
from ktgf.solver.stepping import Numerics, advance

PHI0, E, D, RHO_S, THETA0 = 0.3, 0.7, 1e-3, 2500.0, 1e-4


pytestmark = pytest.mark.analytic


def _physics(model: str = "ret") -> Physics:
    m = get_model(model)
    return Physics(m, E, D, RHO_S, 0.99 * m.phi_max)


@pytest.mark.parametrize("model, scheme, order", [("ret", "ssprk3", 3), ("ret", "imex", 2)])
def test_uniform_gas_follows_haff_at_the_scheme_order(model: str, scheme: str, order: int) -> None:
    phys = _physics(model)
    grid = Grid((4,), (0.05,))
    U0 = conservative(*uniform_fields(grid, phys, PHI0, THETA0))
    t0 = float(cooling_time(model, PHI0, E, THETA0, d=D))  # the oracle: ktgf.hcs.haff
    t_end = 3.0 * t0
    errors = []
    for c in (0.2, 0.1, 0.05):
        U, t, _steps, status, _ = advance(U0, 0.0, t_end, 10**6, grid, phys, Numerics(cfl=c, cfl_diffusion=c, cfl_source=c, scheme=scheme))
        assert int(status) == 0 and float(t) == t_end
        theta = np.asarray(primitive(U))[4]
        assert np.ptp(theta) == 0.0  # stays exactly uniform
        errors.append(abs(theta[0] / float(haff_temperature(t_end, THETA0, t0)) - 1.0))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    print(model, scheme, "Haff errors", errors, "orders", orders)
    assert np.all(orders > order - 0.2), orders


def _smooth_run(cells: int, scheme: str) -> np.ndarray:
    """A finite-amplitude vortex + sound + heat wave in 1D (k* = 0.3), run to τ = 3."""
    phys = _physics("ret")
    L = 2.0 * math.pi * mean_free_path(PHI0, D) / 0.3
    grid = Grid((cells,), (L,))
    Ut, _, _ = single_mode(grid, phys, PHI0, THETA0, (1,), "transverse", 0.05)
    Ul, _, _ = single_mode(grid, phys, PHI0, THETA0, (1,), "longitudinal", 0.05, branch=1)
    W = np.array(primitive(Ul))
    W[2] = np.asarray(primitive(Ut))[2]  # add the transverse velocity
    U0 = conservative(W[0], W[1:4], W[4])
    U, _, _, status, _ = advance(U0, 0.0, float(t_of_tau(3.0, phys, PHI0, THETA0)), 10**6, grid, phys, Numerics(cfl=0.2, scheme=scheme))
    assert int(status) == 0
    return np.asarray(primitive(U))


@pytest.mark.parametrize("scheme", ["imex", "ssprk3"])
def test_spatial_convergence_second_order(scheme: str) -> None:
    ref = _smooth_run(256, scheme)
    errors = []
    for n in (16, 32, 64):
        coarse = ref.reshape(5, n, -1).mean(axis=2)  # cell averages of the reference
        W = _smooth_run(n, scheme)
        scale = np.array([ref[0].mean(), math.sqrt(THETA0), math.sqrt(THETA0), math.sqrt(THETA0), THETA0])
        errors.append(np.mean(np.abs(W - coarse) / scale[:, None]))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    print(scheme, "L1 errors", errors, "orders", orders)
    assert orders[-1] >= 2.0 - 0.1 and np.all(orders > 1.7), orders
