"""The C++ flux kernel (:mod:`ktgf.solver.flux_kernel`) reproduces the JAX flux divergence to round-off.

The oracle is the JAX path of :mod:`ktgf.solver.fluxes` (the reference implementation, and the
path for GPUs, sharding and non-periodic grids), compiled in the same process: one right-hand
side for every limiter and Riemann solver with and without the viscous fluxes, and three steps of
both time schemes and two closure models.  Also: where the kernel does not apply it is not used,
and without a compiler the solver falls back to the JAX path with one warning.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.solver import flux_kernel, fluxes
from ktgf.solver.boundaries import Boundaries
from ktgf.solver.grid import Grid
from ktgf.solver.initial import random_velocity
from ktgf.solver.physics import Physics
from ktgf.solver.stepping import Numerics, advance, explicit_rhs

D, RHO_S = 1e-3, 2500.0
#: float64: the kernel does the operations of the JAX path in the same order; XLA's fusion may round
#: a few differently.  float32: the same rounding differences, relative to 2^-24.
RTOL = {jnp.float64: 1e-13, jnp.float32: 3e-6}

pytestmark = pytest.mark.skipif(not flux_kernel.available(), reason="flux kernel could not be built")


def _grid() -> Grid:
    # Unequal cell counts and spacings, so an axis mix-up in the kernel shows.
    return Grid((6, 8, 10), (6 * D, 8 * 1.3 * D, 10 * 0.8 * D))


def _state(grid: Grid, phys: Physics, dtype, amplitude: float = 0.05):
    return tuple(jnp.asarray(random_velocity(grid, phys, 0.3, 1e-4, amplitude, 4), dtype=dtype))


def _with_kernel(on: bool, fn):
    saved = fluxes.FLUX_KERNEL
    try:
        fluxes.FLUX_KERNEL = on
        return fn()
    finally:
        fluxes.FLUX_KERNEL = saved


def _close(a, b) -> float:
    a, b = np.asarray(jnp.stack(a), np.float64), np.asarray(jnp.stack(b), np.float64)
    scale = np.abs(b).reshape(len(b), -1).max(axis=1)[:, None, None, None]
    return float(np.max(np.abs(a - b) / np.where(scale > 0, scale, 1.0)))


def _physics(model: str) -> Physics:
    m = get_model(model)
    return Physics(m, 0.8, D, RHO_S, 0.99 * m.phi_max)


#: The default suite runs every limiter and Riemann solver once and both precisions; the full matrix is ``slow``.
FAST_RHS = {("vanleer", "hll", True, jnp.float64), ("vanleer", "hll", False, jnp.float64),
            ("vanleer", "hll", True, jnp.float32), ("minmod", "rusanov", True, jnp.float64),
            ("mc", "hll", False, jnp.float64), ("none", "rusanov", True, jnp.float64)}
RHS_CASES = [pytest.param(lim, rie, v, dt, marks=() if (lim, rie, v, dt) in FAST_RHS else pytest.mark.slow)
             for lim in fluxes.LIMITERS for rie in fluxes.RIEMANN_SOLVERS for v in (True, False)
             for dt in (jnp.float64, jnp.float32)]
FAST_STEPS = {("ssprk3", "ret"), ("imex", "proposed")}
STEP_CASES = [pytest.param(s, m, marks=() if (s, m) in FAST_STEPS else pytest.mark.slow)
              for s in ("ssprk3", "imex") for m in ("ret", "proposed")]


@pytest.mark.parametrize(("limiter", "riemann", "viscous", "dtype"), RHS_CASES)
def test_kernel_rhs_matches_jax(limiter: str, riemann: str, viscous: bool, dtype) -> None:
    grid, phys = _grid(), _physics("ret")
    U = _state(grid, phys, dtype)
    num = Numerics(limiter=limiter, riemann=riemann)
    f = lambda: jax.jit(lambda U: explicit_rhs(U, grid, phys, num, viscous=viscous))(U)  # noqa: E731
    new, ref = _with_kernel(True, f), _with_kernel(False, f)
    assert all(x.dtype == dtype for x in new)
    assert np.all(np.isfinite(np.asarray(jnp.stack(new)))) and float(jnp.max(jnp.abs(new[1]))) > 0
    assert _close(new, ref) < RTOL[dtype]


@pytest.mark.parametrize(("scheme", "model"), STEP_CASES)
def test_kernel_steps_match_jax(scheme: str, model: str) -> None:
    grid, phys = _grid(), _physics(model)
    U = _state(grid, phys, jnp.float64)
    num = Numerics(scheme=scheme)
    f = lambda: jax.jit(lambda U: advance.__wrapped__(U, 0.0, 1e30, 3, grid, phys, num))(U)  # noqa: E731
    new, ref = _with_kernel(True, f), _with_kernel(False, f)
    assert int(new[2]) == int(ref[2]) == 3 and int(new[3]) == int(ref[3]) == 0
    assert _close(new[0], ref[0]) < RTOL[jnp.float64]


def test_kernel_is_in_the_compiled_rhs_only_where_it_applies() -> None:
    phys = _physics("ret")
    periodic = _grid()
    sheared = Grid(periodic.cells, periodic.lengths, Boundaries(("periodic", "lees-edwards", "periodic"),
                                                                 shear_rate=50.0, flow=0))
    flat = Grid((8, 6), (8 * D, 6 * D))

    def hlo(grid: Grid) -> str:
        U = _state(grid, phys, jnp.float64)
        return jax.jit(lambda U: explicit_rhs(U, grid, phys, Numerics(), viscous=True)).lower(U).as_text()

    assert flux_kernel.TARGET in _with_kernel(True, lambda: hlo(periodic))
    assert flux_kernel.TARGET not in _with_kernel(False, lambda: hlo(periodic))
    assert flux_kernel.TARGET not in _with_kernel(True, lambda: hlo(sheared))
    assert flux_kernel.TARGET not in _with_kernel(True, lambda: hlo(flat))


def test_without_a_compiler_the_jax_path_runs_with_one_warning(monkeypatch, tmp_path) -> None:
    monkeypatch.setenv("CXX", "no-such-compiler-ktgf")
    monkeypatch.setenv("KTGF_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(flux_kernel, "_loaded", {})
    with pytest.warns(RuntimeWarning, match="flux kernel unavailable.*no-such-compiler-ktgf"):
        assert not flux_kernel.applies(_grid(), jnp.float64)
    assert not flux_kernel.applies(_grid(), jnp.float64)  # decided once: no second warning, no retry
