"""The faster code paths of the 3D solver reproduce the reference paths to round-off.

Each speed switch of :mod:`ktgf.solver.fluxes` keeps main's path next to the faster one; here both
are compiled in the same process and one right-hand side and a few steps are compared, for
periodic, Lees–Edwards and wall boundaries, both time schemes and two closure models.  The
oracle is the reference path (the code of main before the change), not stored numbers.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.couette.walls import Wall
from ktgf.solver import fluxes
from ktgf.solver.boundaries import Boundaries, WallSide
from ktgf.solver.flows import add_base_flow
from ktgf.solver.grid import Grid
from ktgf.solver.initial import random_velocity
from ktgf.solver.physics import Physics
from ktgf.solver.stepping import Numerics, advance, rhs

D, RHO_S, PHI = 1e-3, 2500.0, 0.3
#: Relative tolerance (float64): different fusion can change the rounding of a few operations.
RTOL = 1e-13


pytestmark = pytest.mark.contract


def _grid(kind: str) -> Grid:
    cells, lengths = (8, 8, 6), (8 * D, 8 * D, 6 * D)
    if kind == "periodic":
        return Grid(cells, lengths)
    if kind == "lees-edwards":
        return Grid(cells, lengths, Boundaries(("periodic", "lees-edwards", "periodic"), shear_rate=50.0, flow=0))
    wall = Wall(specularity=0.3, restitution=0.8)
    walls = (WallSide(wall, (-0.02, 0.0, 0.0)), WallSide(wall, (0.02, 0.0, 0.0)))
    return Grid(cells, lengths, Boundaries(("periodic", "wall", "periodic"), flow=0, walls=(None, walls, None)))


def _run(switches: dict, U, grid, phys, num):
    """(rhs, state after 3 steps) with the module switches set, traced afresh (new jit)."""
    saved = {k: getattr(fluxes, k) for k in switches}
    try:
        for k, v in switches.items():
            setattr(fluxes, k, v)
        L = jax.jit(lambda U: rhs(U, grid, phys, num, 0.0))(U)
        out = jax.jit(lambda U: advance.__wrapped__(U, 0.0, 1e30, 3, grid, phys, num))(U)
    finally:
        for k, v in saved.items():
            setattr(fluxes, k, v)
    assert int(out[2]) == 3 and int(out[3]) == 0
    return np.asarray(jnp.stack(L)), np.asarray(jnp.stack(out[0]))


def _close(a: np.ndarray, b: np.ndarray) -> float:
    scale = np.abs(b).reshape(5, -1).max(axis=1)[:, None, None, None]
    return float(np.max(np.abs(a - b) / np.where(scale > 0, scale, 1.0)))


#: The gather path is opt-in, so the default suite runs one case; the full matrix is ``slow``.
FAST = {("periodic", "ssprk3", "ret")}
CASES = [pytest.param(k, s, m, marks=() if (k, s, m) in FAST else pytest.mark.slow)
         for k in ("periodic", "lees-edwards", "wall") for s in ("ssprk3", "imex") for m in ("ret", "proposed")]


@pytest.mark.parametrize(("kind", "scheme", "model"), CASES)
def test_gather_padding_matches_jnp_pad(kind: str, scheme: str, model: str) -> None:
    m = get_model(model)
    phys = Physics(m, 0.8, D, RHO_S, 0.99 * m.phi_max)
    grid = _grid(kind)
    U = random_velocity(grid, phys, PHI, 1e-4, 0.05, 3)
    if kind == "lees-edwards":
        U = add_base_flow(U, grid)
    U = tuple(jnp.asarray(U))
    num = Numerics(scheme=scheme)
    # The C++ flux kernel (tests/solver/test_solver_flux_kernel.py) would bypass the padding on periodic grids.
    L_new, U_new = _run({"PERIODIC_PAD": "gather", "FLUX_KERNEL": False}, U, grid, phys, num)
    L_ref, U_ref = _run({"PERIODIC_PAD": "pad", "FLUX_KERNEL": False}, U, grid, phys, num)
    assert np.all(np.isfinite(L_new)) and np.abs(L_new).max() > 0
    assert _close(L_new, L_ref) < RTOL
    assert _close(U_new, U_ref) < RTOL


@pytest.mark.parametrize("mode", ["auto", "gather", "pad"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("shape", [(5,), (6, 4), (4, 7, 5)])
def test_periodic_padding_is_numpy_wrap_padding(mode: str, dtype: type, shape: tuple) -> None:
    f = np.random.default_rng(1).random(shape).astype(dtype)
    saved = fluxes.PERIODIC_PAD
    try:
        fluxes.PERIODIC_PAD = mode
        (P,) = fluxes.pad_periodic((jnp.asarray(f),), len(shape))
    finally:
        fluxes.PERIODIC_PAD = saved
    assert P.dtype == dtype
    np.testing.assert_array_equal(np.asarray(P), np.pad(f, fluxes.GHOST, mode="wrap"))
