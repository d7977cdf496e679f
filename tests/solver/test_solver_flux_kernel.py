"""The C++ flux kernel (:mod:`ktgf.solver.flux_kernel`) reproduces the JAX flux divergence to round-off.

The oracle is the JAX path of :mod:`ktgf.solver.fluxes` (the reference implementation, and the
path for GPUs, sharding and non-periodic grids), compiled in the same process: one right-hand
side for every limiter and Riemann solver with and without the viscous fluxes, and three steps of
both time schemes and two closure models.  The fused SSP-RK3 stage (:func:`.flux_kernel.ssprk_stage`)
is checked the same way, in both precisions and with a frictional model, and its energy source
s0 + s1∇·u against :func:`~ktgf.solver.sources.cooling_source` for every registered model.  Also:
where the kernel does not apply it is not used (without a compiler: tests/solver/test_cxx_toolchain.py).
The build: one library per variant instantiates the face sweep once, refuses calls of another variant, is
built once by two processes that need it at the same time, and is announced (INFO on the ``ktgf`` logger,
which the command line shows).
"""

from __future__ import annotations

import dataclasses
import logging
import os
import re
import shutil
import subprocess
import sys

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.closures.models import list_models
from ktgf.solver import flux_kernel, fluxes
from ktgf.solver.boundaries import Boundaries
from ktgf.solver.cases import get_case
from ktgf.solver.cell_terms import (
    LIMIT_TERMS,
    START_TERMS,
    STATUS_TERMS,
    kernel_stage_inputs,
    limit_terms,
    status_terms,
)
from ktgf.solver.friction import cell_coefficients
from ktgf.solver.grid import Grid
from ktgf.solver.initial import random_velocity
from ktgf.solver.physics import Physics
from ktgf.solver.run import Simulation
from ktgf.solver.sources import cooling_source
from ktgf.solver.state import primitive_fields
from ktgf.solver.stepping import (
    Numerics,
    advance,
    checks_program,
    explicit_rhs,
    kernel_step_limits,
    ssprk3_step,
    state_status,
    status_of_maxima,
    step_limits,
)

D, RHO_S = 1e-3, 2500.0
#: float64: the kernel does the operations of the JAX path in the same order; XLA's fusion may round
#: a few differently.  float32: the same rounding differences, relative to 2^-24.
RTOL = {jnp.float64: 1e-13, jnp.float32: 3e-6}

_WHY = None if flux_kernel.available() else flux_kernel.unavailable()
pytestmark = pytest.mark.skipif(_WHY is not None, reason=f"the C++ flux kernel could not be built: {_WHY}")


def _grid() -> Grid:
    # Unequal cell counts and spacings, so an axis mix-up in the kernel shows.
    return Grid((6, 8, 10), (6 * D, 8 * 1.3 * D, 10 * 0.8 * D))


def _state(grid: Grid, phys: Physics, dtype, amplitude: float = 0.05, phi: float = 0.3):
    return tuple(jnp.asarray(random_velocity(grid, phys, phi, 1e-4, amplitude, 4), dtype=dtype))


def _with_kernel(on: bool, fn, stage: bool = True, cells: bool = True):
    saved = fluxes.FLUX_KERNEL, fluxes.STAGE_KERNEL, fluxes.CELL_PROGRAM
    try:
        fluxes.FLUX_KERNEL, fluxes.STAGE_KERNEL, fluxes.CELL_PROGRAM = on, stage, cells
        return fn()
    finally:
        fluxes.FLUX_KERNEL, fluxes.STAGE_KERNEL, fluxes.CELL_PROGRAM = saved


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


@pytest.mark.contract
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


@pytest.mark.contract
@pytest.mark.parametrize(("scheme", "model"), STEP_CASES)
def test_kernel_steps_match_jax(scheme: str, model: str) -> None:
    grid, phys = _grid(), _physics(model)
    U = _state(grid, phys, jnp.float64)
    new, ref = _three_steps(U, grid, phys, Numerics(scheme=scheme))
    assert _close(new[0], ref[0]) < RTOL[jnp.float64]


def _three_steps(U, grid: Grid, phys: Physics, num: Numerics) -> tuple:
    """``advance`` by 3 steps with the kernel and on the JAX path (both take the 3 steps)."""
    f = lambda: jax.jit(lambda U: advance.__wrapped__(U, 0.0, 1e30, 3, grid, phys, num))(U)  # noqa: E731
    new, ref = _with_kernel(True, f), _with_kernel(False, f)
    assert int(new[2]) == int(ref[2]) == 3 and int(new[3]) == int(ref[3]) == 0
    return new, ref


@pytest.mark.contract
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
    assert flux_kernel.TARGET in _with_kernel(True, lambda: hlo(sheared))  # fields padded by JAX
    assert flux_kernel.TARGET not in _with_kernel(True, lambda: hlo(flat))


#: Lees–Edwards grids of the kernel comparisons: (gradient axis, flow axis); the gradient along z takes the
#: kernel's padded z ghosts, which on periodic grids it makes itself.
SHEARS = [(1, 0), (0, 2), (2, 1)]


def _sheared(axis: int, flow: int) -> tuple[Grid, Physics]:
    kinds = tuple("lees-edwards" if b == axis else "periodic" for b in range(3))
    grid = Grid(_grid().cells, _grid().lengths, Boundaries(kinds, shear_rate=50.0, flow=flow))
    m = get_model("ret")
    return grid, get_case("uniform-shear").physics(Physics(m, 0.8, D, RHO_S, 0.99 * m.phi_max), grid)


def _some_slow(cases: list, fast: set) -> list:
    """``cases`` as pytest params, those not in ``fast`` marked slow (the default suite runs each axis once)."""
    return [pytest.param(*c, marks=() if c in fast else pytest.mark.slow) for c in cases]


@pytest.mark.contract
@pytest.mark.parametrize("axis, flow, viscous, dtype", _some_slow(
    [(*s, *v) for s in SHEARS for v in ((True, jnp.float64), (False, jnp.float64), (True, jnp.float32))],
    {(1, 0, True, jnp.float64), (0, 2, False, jnp.float64), (2, 1, True, jnp.float32)}))
def test_kernel_rhs_on_a_lees_edwards_grid_matches_jax(axis: int, flow: int, viscous: bool, dtype) -> None:
    """The fields padded with their moving images (fractional shift: t is not a whole number of cells) and the
    lower boundary face replaced by the mapped upper one (conservative): the JAX path's right-hand side."""
    grid, phys = _sheared(axis, flow)
    U = _state(grid, phys, dtype)
    f = lambda: jax.jit(lambda U: explicit_rhs(U, grid, phys, Numerics(), viscous=viscous, t=3.7e-3))(U)  # noqa: E731
    new, ref = _with_kernel(True, f), _with_kernel(False, f)
    assert all(x.dtype == dtype for x in new)
    assert _close(new, ref) < RTOL[dtype]


def _walled(case: str, axis: str) -> Simulation:
    """A Couette cell or a chute (base and lid, gravity at 25°) on the unequal grid, walls across ``axis``."""
    import tomllib

    from ktgf.solver.config import parse_config

    flow = "y" if axis == "x" else "x"
    walls = '{ type = "johnson-jackson", specularity = 0.1, restitution = 0.9 }'
    speed = 1.0 if case == "couette" else 0.0
    extra = "inclination_deg = 25.0\n" if case == "chute" else ""
    return Simulation(parse_config(tomllib.loads(f"""
[case]
kind = "{case}"
{extra}[boundaries]
{axis} = {{ kind = "wall", flow = "{flow}", wall_speed = {speed}, walls = {walls} }}
[model]
name = "ret"
restitution = 0.8
[initial]
solid_fraction = 0.3
temperature = 1e-3
{"shear_rate = 100.0" if case == "chute" else ""}
perturbation = "random"
amplitude = 0.05
max_mode = 2
[grid]
cells = {list(_grid().cells)}
length_d = 8.0
[time]
end = 1.0
unit = "s"
""")))


def _close_momentum(a, b) -> float:
    """:func:`_close` with one scale for the three momentum fields (the largest): a component across a flow is
    small, and its round-off is that of the flow's momentum."""
    a, b = np.asarray(jnp.stack(a), np.float64), np.asarray(jnp.stack(b), np.float64)
    scale = np.abs(b).reshape(len(b), -1).max(axis=1)
    scale[1:4] = scale[1:4].max()
    return float(np.max(np.abs(a - b) / scale[:, None, None, None]))


WALLS = [("couette", "y"), ("couette", "x"), ("couette", "z"), ("chute", "y"), ("chute", "z")]


@pytest.mark.contract
@pytest.mark.parametrize("case, axis", _some_slow(WALLS, {("couette", "y"), ("couette", "z"), ("chute", "y")}))
def test_kernel_rhs_between_walls_matches_jax(case: str, axis: str) -> None:
    """The wall faces' mirror flux and the viscous ghost cells of the wall conditions (the wall plane's fluxes
    along every axis) as corrections of the kernel's wall planes: the JAX path's right-hand side."""
    sim = _walled(case, axis)
    with sim.precision():
        U = tuple(sim.initial_state())
        for viscous in (True, False):
            f = lambda: jax.jit(lambda U: explicit_rhs(U, sim.grid, sim.phys, Numerics(),  # noqa: E731
                                                       viscous=viscous))(U)
            assert _close(_with_kernel(True, f), _with_kernel(False, f)) < RTOL[jnp.float64]


@pytest.mark.contract
@pytest.mark.parametrize("case, axis, scheme", _some_slow([(*w, m) for w in WALLS for m in ("ssprk3", "imex")],
                                                          {("chute", "y", "ssprk3"), ("chute", "z", "imex")}))
def test_kernel_steps_between_walls_match_jax(case: str, axis: str, scheme: str) -> None:
    """Three steps; the stage kernel adds the chute's gravity (also where it writes the new state over the old)."""
    sim = _walled(case, axis)
    with sim.precision():
        U = tuple(sim.initial_state())
        new, ref = _three_steps(U, sim.grid, sim.phys, Numerics(scheme=scheme))
    assert _close_momentum(new[0], ref[0]) < RTOL[jnp.float64]
    assert _close(new[0], U) > 0.1


@pytest.mark.contract
@pytest.mark.parametrize("axis, flow, scheme", _some_slow([(*s, m) for s in SHEARS for m in ("ssprk3", "imex")],
                                                          {(1, 0, "ssprk3"), (2, 1, "imex")}))
def test_kernel_steps_on_a_lees_edwards_grid_match_jax(axis: int, flow: int, scheme: str) -> None:
    grid, phys = _sheared(axis, flow)
    U = _state(grid, phys, jnp.float64)
    new, ref = _three_steps(U, grid, phys, Numerics(scheme=scheme))
    assert _close(new[0], ref[0]) < RTOL[jnp.float64]
    assert _close(new[0], U) > 100 * RTOL[jnp.float64]


def _steps(U, grid, phys, num, steps: int = 3):
    return jax.jit(lambda U: advance.__wrapped__(U, 0.0, 1e30, steps, grid, phys, num))(U)


#: (model, options, φ, perturbation, dtype) of the fused-stage step comparisons; a frictional stress
#: (above its φ_min = 0.5) makes the cell coefficients depend on the velocity gradient and adds the
#: frictional work to s0.
STAGE_CASES = [("ret", {}, 0.3, 0.2, jnp.float64), ("ret", {}, 0.3, 0.2, jnp.float32),
               ("proposed", {}, 0.52, 0.05, jnp.float64), ("frictional", {"stress": "schaeffer"}, 0.53, 0.01, jnp.float64)]


@pytest.mark.contract
@pytest.mark.parametrize(("model", "options", "phi", "amplitude", "dtype"), STAGE_CASES)
def test_fused_stage_steps_match_jax(model: str, options: dict, phi: float, amplitude: float, dtype) -> None:
    grid = _grid()
    m = get_model(model, **options)
    phys = get_case("cooling").physics(Physics(m, 0.8, D, RHO_S, 0.99 * m.phi_max), grid)
    U = _state(grid, phys, dtype, amplitude=amplitude, phi=phi)
    if m.friction.has_stress:  # the frictional stress is present in (nearly) every cell
        assert float(jnp.mean(cell_coefficients(primitive_fields(U), grid, phys).p_f > 0.0)) > 0.9
    num = Numerics(scheme="ssprk3")
    cells = _with_kernel(True, lambda: _steps(U, grid, phys, num))  # closures by a cell program, where it applies
    fused = _with_kernel(True, lambda: _steps(U, grid, phys, num), cells=False)  # closures by XLA
    kernel = _with_kernel(True, lambda: _steps(U, grid, phys, num), stage=False)  # fluxes only
    ref = _with_kernel(False, lambda: _steps(U, grid, phys, num))
    for out in (cells, fused, kernel, ref):
        assert int(out[2]) == 3 and int(out[3]) == 0
    assert fused[0].dtype == cells[0].dtype == dtype
    assert _close(fused[0], ref[0]) < RTOL[dtype]
    assert _close(fused[0], kernel[0]) < RTOL[dtype]
    assert _close(cells[0], ref[0]) < RTOL[dtype]
    assert _close(fused[0], U) > 100 * RTOL[dtype]  # the steps changed the state


@pytest.mark.contract
def test_fused_stage_on_few_planes_matches_jax() -> None:
    """The fused sweep's ring of planes on a grid of the fewest planes (4: planes -2, -1 are planes 2, 3, and
    the periodic images n0, n0 + 1 the kept planes 0, 1) and rows split unevenly over the threads (13 rows)."""
    grid = Grid((4, 13, 5), (4 * D, 13 * 0.9 * D, 5 * 1.2 * D))
    phys = get_case("cooling").physics(_physics("ret"), grid)
    U = _state(grid, phys, jnp.float64, amplitude=0.2)
    num = Numerics(scheme="ssprk3")
    cells = _with_kernel(True, lambda: _steps(U, grid, phys, num))
    ref = _with_kernel(False, lambda: _steps(U, grid, phys, num))
    assert int(cells[2]) == 3 and int(cells[3]) == 0
    assert _close(cells[0], ref[0]) < RTOL[jnp.float64]
    assert _close(cells[0], U) > 100 * RTOL[jnp.float64]


_THREADS_SCRIPT = """
import hashlib, sys
import jax, jax.numpy as jnp, numpy as np
jax.config.update("jax_enable_x64", True)
from ktgf.closures import get_model
from ktgf.solver.cases import get_case
from ktgf.solver.grid import Grid
from ktgf.solver.initial import random_velocity
from ktgf.solver.physics import Physics
from ktgf.solver.stepping import Numerics, advance
m = get_model("proposed")
grid = Grid((24, 41, 16), (24e-3, 41e-3, 16e-3))
phys = get_case("cooling").physics(Physics(m, 0.8, 1e-3, 2500.0, 0.99 * m.phi_max), grid)
U = tuple(jnp.asarray(random_velocity(grid, phys, 0.3, 1e-4, 0.05, 4)))
out = advance(U, 0.0, 1e30, 6, grid, phys, Numerics(scheme="ssprk3"))
assert int(out[2]) == 6 and int(out[3]) == 0
print(hashlib.sha256(np.asarray(out[0]).tobytes()).hexdigest())
"""


@pytest.mark.contract
def test_fused_stage_does_not_depend_on_the_threads(tmp_path) -> None:
    """Every cell does the same operations whatever the threads' split of the rows (and which thread computes
    a ghost row): six steps with 1, 2 and 3 OpenMP threads are bit for bit the same.  41 rows: 20/21 and
    13/14/14 rows a thread, so ghost rows and the neighbours' waits (a stage that writes U' over Uk, which its
    neighbours read for their ghost rows, waits for them) cross thread boundaries; on this grid the threads
    drift apart enough that a stage without those waits gives other bits (checked by mutation)."""
    import os
    import subprocess
    import sys

    script = tmp_path / "threads.py"
    script.write_text(_THREADS_SCRIPT)
    digests = set()
    for threads in (1, 2, 3):
        env = {**os.environ, "OMP_NUM_THREADS": str(threads)}
        run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=300)
        assert run.returncode == 0, run.stderr[-2000:]
        digests.add(run.stdout.strip().splitlines()[-1])
    assert len(digests) == 1


_WAIT_SCRIPT = """
import ctypes
from ktgf.solver import flux_kernel
flux_kernel._library(flux_kernel.DEFAULT)
getenv = ctypes.CDLL(None).getenv
getenv.restype = ctypes.c_char_p
print(getenv(b"OMP_WAIT_POLICY").decode(), getenv(b"GOMP_SPINCOUNT").decode())
"""


@pytest.mark.contract
@pytest.mark.parametrize("user", [{}, {"GOMP_SPINCOUNT": "100", "OMP_WAIT_POLICY": "ACTIVE"}])
def test_openmp_threads_spin_briefly_then_sleep_unless_told_otherwise(tmp_path, user: dict) -> None:
    """libgomp reads its wait settings from the environment (the C one) once, when it loads: the kernel's
    library sets them before it loads, passive with a short spin (flux_kernel.SPIN_COUNT), and a user's
    settings win."""
    script = tmp_path / "wait.py"
    script.write_text(_WAIT_SCRIPT)
    env = {k: v for k, v in os.environ.items() if k not in ("GOMP_SPINCOUNT", "OMP_WAIT_POLICY")} | user
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    expected = [user.get("OMP_WAIT_POLICY", "PASSIVE"), user.get("GOMP_SPINCOUNT", str(flux_kernel.SPIN_COUNT))]
    assert run.stdout.split() == expected


@pytest.mark.contract
@pytest.mark.parametrize(("stop", "accepted", "budget"), [(0.362, 3, 10), (0.362, 3, 4), (0.345, 0, 10), (0.345, 0, 1)])
def test_kernel_checked_loop_returns_the_last_good_state(stop: float, accepted: int, budget: int) -> None:
    """With cell programs, the kernel checks each new state (:func:`.flux_kernel.cell_limits`, whose maxima also
    give the next step's limits).  A flow converging on x = 0 raises the maximum φ by ≈ 0.004 a step; phi_stop
    stops it at the fourth step (or the first: the last good state is then the initial one).  The outcome is that
    of the XLA closures' loop (:func:`state_status`), and the returned state is the one the accepted steps alone
    give, bit for bit."""
    grid = _grid()
    phys = dataclasses.replace(get_case("cooling").physics(_physics("ret"), grid), phi_stop=stop)
    U = list(_state(grid, phys, jnp.float64, phi=0.3))
    x = (np.arange(grid.cells[0]) + 0.5) / grid.cells[0]
    u = -0.02 * np.sin(2.0 * np.pi * x)[:, None, None]  # ≈ the thermal speed (0.016 m/s)
    U[4] = U[4] + U[1] * u + 0.5 * U[0] * u**2
    U[1] = U[1] + U[0] * u
    U = tuple(U)
    assert 0.343 < float(jnp.max(U[0])) / RHO_S < 0.345  # the initial state is fine
    num = Numerics(scheme="ssprk3")
    fused = _with_kernel(True, lambda: advance(U, 0.0, 1e30, budget, grid, phys, num))
    assert _with_kernel(True, lambda: checks_program(grid, phys, num, jnp.float64)) is not None  # kernel checks
    kept = _with_kernel(True, lambda: advance(U, 0.0, 1e30, budget, grid, phys, num), cells=False)
    assert [int(fused[k]) for k in (2, 3)] == [int(kept[k]) for k in (2, 3)] == [accepted, 3]
    assert float(fused[1]) == pytest.approx(float(kept[1]), rel=1e-12)
    assert float(fused[1]) > 0.0 if accepted else float(fused[1]) == 0.0
    assert _close(fused[0], kept[0]) < RTOL[jnp.float64]
    assert int(state_status(tuple(fused[0]), phys)) == 0
    alone = _with_kernel(True, lambda: advance(U, 0.0, 1e30, accepted, grid, phys, num))
    assert int(alone[2]) == accepted and int(alone[3]) == 0
    assert np.array_equal(np.asarray(fused[0]), np.asarray(alone[0]))


@pytest.mark.contract
def test_fused_stage_refuses_a_small_ring(monkeypatch) -> None:
    """The fused stage's workspace (its threads' rings) is sized by the kernel (KtgfRingElements): one element
    short, the call is an error, not a write past the buffer."""
    grid, phys = _grid(), _physics("ret")
    U = _state(grid, phys, jnp.float64)
    ring = flux_kernel._ring
    monkeypatch.setattr(flux_kernel, "_ring", lambda *a: jax.ShapeDtypeStruct((ring(*a).shape[0] - 1,), ring(*a).dtype))
    with pytest.raises(Exception, match="ring workspace"):
        _with_kernel(True, lambda: np.asarray(_steps(U, grid, phys, Numerics(scheme="ssprk3"))[0]))


@pytest.mark.analytic
@pytest.mark.parametrize("model", [m.name for m in list_models()])
def test_stage_source_is_the_cooling_source(model: str) -> None:
    """s0 + s1∇·u (what the fused stage adds) equals −(3/2)ρθζ for any ∇·u, for every registered model."""
    grid = _grid()
    m = get_model(model)
    phys = get_case("uniform-shear").physics(Physics(m, 0.8, D, RHO_S, 0.99 * m.phi_max), grid)
    U = _state(grid, phys, jnp.float64, amplitude=0.2)
    W = primitive_fields(U)
    r = cell_coefficients(W, grid, phys)
    _, _, _, (s0, s1) = kernel_stage_inputs(U, r, phys)
    divu = jnp.asarray(np.random.default_rng(3).normal(0.0, 50.0, grid.cells))
    exact, _ = cooling_source(W, divu, phys, r)
    scale = float(jnp.max(jnp.abs(exact)))
    if float(jnp.max(jnp.abs(r.zeta_u))) > 0.0:  # Lun et al. (1984) have no ζ_U: s1 = 0 there
        assert float(jnp.max(jnp.abs(s1 * divu))) > 1e-3 * scale  # the ∇·u part is not negligible here
    assert float(jnp.max(jnp.abs(s0 + s1 * divu - exact))) < 1e-13 * scale


@pytest.mark.contract
def test_fused_stage_is_in_the_compiled_step_only_where_it_applies() -> None:
    grid, phys = _grid(), _physics("ret")
    U = _state(grid, phys, jnp.float64)
    num = Numerics(scheme="ssprk3")

    def hlo(phys: Physics) -> str:
        return jax.jit(lambda U: ssprk3_step(U, 1e-6, grid, phys, num)).lower(U).as_text()

    def calls(text: str, base: str) -> bool:
        # A variant's target is the base name, "__", the variant (ktgf_ssprk_stage is a prefix of the cells target).
        return re.search(rf"\b{base}__", text) is not None

    text = _with_kernel(True, lambda: hlo(phys))
    assert calls(text, flux_kernel.CELLS_TARGET)  # RET: the closures by a cell program, in the stage kernel
    stage = flux_kernel.variant(jnp.float64, num.limiter, num.riemann, "stage")
    assert f"@{flux_kernel.target(flux_kernel.CELLS_TARGET, stage)}(" in text  # the variant of the step's numerics
    assert not calls(text, flux_kernel.TARGET) and not calls(text, flux_kernel.STAGE_TARGET)
    text = _with_kernel(True, lambda: hlo(phys), cells=False)
    assert calls(text, flux_kernel.STAGE_TARGET) and not calls(text, flux_kernel.TARGET)  # the stage does the fluxes
    assert not calls(_with_kernel(True, lambda: hlo(phys), stage=False), flux_kernel.STAGE_TARGET)
    sheared = get_case("uniform-shear").physics(_physics("frictional"), grid)  # closures with the velocity gradient
    text = _with_kernel(True, lambda: hlo(sheared))
    assert calls(text, flux_kernel.STAGE_TARGET) and not calls(text, flux_kernel.CELLS_TARGET)
    with_gravity = Physics(phys.model, 0.8, D, RHO_S, phys.phi_stop, gravity=(0.0, -9.81, 0.0))
    text = _with_kernel(True, lambda: hlo(with_gravity))  # a body force: the cell program, which adds it
    assert calls(text, flux_kernel.CELLS_TARGET) and not calls(text, flux_kernel.STAGE_TARGET)


@pytest.mark.contract
def test_closures_once_per_stage(monkeypatch) -> None:
    """Tracing one SSP-RK3 step of ``advance`` evaluates the closures twice: at the step start (shared by
    the step limits and the first stage) and in the stage loop (the two later stages) — 3 per step.
    With a cell program, never: the kernel evaluates them, also for the step limits."""
    grid, phys = _grid(), _physics("ret")
    U = _state(grid, phys, jnp.float64)
    calls = []
    original = Physics.reduced
    monkeypatch.setattr(Physics, "reduced", lambda self, *a, **k: calls.append(1) or original(self, *a, **k))
    num = Numerics(scheme="ssprk3")
    for stage in (True, False):
        # The step-start cell program is generated (by tracing the closures) once per process and then cached: here
        # before counting, so that the count does not depend on the tests run before this one.
        _with_kernel(True, lambda: checks_program(grid, phys, num, jnp.float64), stage=stage, cells=False)
        calls.clear()
        _with_kernel(True, lambda: jax.jit(lambda U: advance.__wrapped__(
            U, 0.0, 1e30, 1, grid, phys, num)).lower(U), stage=stage, cells=False)
        assert len(calls) == 2
    from ktgf.solver import cell_program

    assert cell_program.for_physics(phys, jnp.float64) is not None  # generated (and traced) once, cached
    assert cell_program.for_physics(phys, jnp.float64, limits="explicit") is not None  # the step-start program
    calls.clear()
    _with_kernel(True, lambda: jax.jit(lambda U: advance.__wrapped__(
        U, 0.0, 1e30, 1, grid, phys, Numerics(scheme="ssprk3"))).lower(U))
    assert len(calls) == 0  # the kernel evaluates the closures and reduces the step limits' terms


@pytest.mark.contract
@pytest.mark.parametrize("dtype", [jnp.float64, jnp.float32])
@pytest.mark.parametrize("model", ["ret", "proposed", "frictional"])
def test_step_limits_reduced_in_the_kernel(model: str, dtype) -> None:
    """The step limits from the maxima the kernel reduces in its padding pass are those of the XLA
    closures and reductions (:func:`step_limits`; float32: of the float64 state, to the float32 closures'
    rounding); each of the four follows its own term, so a swap of terms, axes or cell sizes shows, and a
    NaN term (θ < 0 in one cell) reaches the maxima as in ``jnp.max``.  The same pass reduces the state
    check's terms: each status code comes out as :func:`state_status` gives it."""
    from ktgf.solver.cell_program import leaf_values

    grid = _grid()
    phys = get_case("cooling").physics(_physics(model), grid)
    U = _state(grid, phys, dtype, phi=0.5)
    num = Numerics(scheme="ssprk3")
    program = _with_kernel(True, lambda: checks_program(grid, phys, num, dtype))
    assert program is not None and program.nlim == len(START_TERMS) == len(LIMIT_TERMS) + len(STATUS_TERMS)
    reduce = jax.jit(lambda U: flux_kernel.cell_limits(U, program, leaf_values(phys, grid), grid, num.limiter,
                                                       num.riemann))
    got = np.asarray(kernel_step_limits(reduce(U), primitive_fields(U)[1:4], grid, num), np.float64)
    want = np.asarray(jax.jit(lambda U: step_limits(U, grid, phys, num))(tuple(jnp.asarray(u, jnp.float64) for u in U)))
    tol = 1e-13 if dtype == jnp.float64 else 1e-5  # float32: the cell program's rounding (< 128 ε₃₂)
    np.testing.assert_allclose(got, want, rtol=tol)
    assert len(set(np.round(want / want.min(), 6))) == 4  # four different limits: a swap would show
    # Each maximum, from every cell (the threads' partial maxima merged), against NumPy's of the XLA terms.
    W = primitive_fields(U)
    terms = (*limit_terms(W, cell_coefficients(W, grid, phys), phys, num.acoustics, grid.spacing), *status_terms(U, W))
    np.testing.assert_allclose(np.asarray(reduce(U), np.float64), [float(np.max(np.asarray(f))) for f in terms],
                               rtol=tol)

    stop = dataclasses.replace(phys, phi_stop=0.6)  # above the state's φ (the frictional model's own is below)

    def status(U: tuple) -> tuple[int, int]:  # (from the kernel's maxima, from state_status)
        return int(status_of_maxima(reduce(U)[len(LIMIT_TERMS):], stop)), int(state_status(U, stop))

    assert status(U) == (0, 0)
    cell = (5, 7, 9)  # the last cell of a thread
    cold = list(U)
    cold[4] = cold[4].at[cell].set(0.5 * (cold[1][cell] ** 2 + cold[2][cell] ** 2 + cold[3][cell] ** 2)
                                   / cold[0][cell] * 0.5)  # kinetic energy > E: θ < 0
    assert np.isnan(np.asarray(reduce(tuple(cold)))[0])  # c = √(θg) is NaN there
    assert status(tuple(cold)) == (2, 2)
    for v, value, code in ((3, np.inf, 1), (1, np.nan, 1), (0, 0.6 * RHO_S, 3), (0, 0.0, 4)):
        bad = list(U)
        bad[v] = bad[v].at[cell].set(value)
        assert status(tuple(bad)) == (code, code), (v, value)


def _sweeps(library) -> set[tuple[str, ...]]:
    """The template arguments (type, limiter, Riemann solver, viscous, output) of the sweeps in a library."""
    symbols = subprocess.run(["nm", "-C", str(library)], capture_output=True, text=True, check=True).stdout
    return set(re.findall(r"sweep<(\w+), (\d), (\d), (true|false), \(anonymous namespace\)::(\w+)<", symbols))


@pytest.mark.contract
@pytest.mark.skipif(shutil.which("nm") is None, reason="needs nm (binutils)")
def test_a_variant_library_compiles_the_sweep_once() -> None:
    """Each library holds the one face sweep of its variant (a build compiles one, not 64) and the entries of
    its kind."""
    cases = [(flux_kernel.DEFAULT, ("double", "1", "0", "true", "Stage")),  # the variants the tests above use
             (flux_kernel.variant(jnp.float64, "minmod", "rusanov", "rhs"), ("double", "0", "1", "true", "Rhs")),
             (flux_kernel.variant(jnp.float64, "mc", "hll", "euler"), ("double", "2", "0", "false", "Rhs"))]
    for v, sweep in cases:
        library = flux_kernel.build(v)
        assert _sweeps(library) == {sweep}, v
        exported = subprocess.run(["nm", "-D", "--defined-only", str(library)], capture_output=True, text=True,
                                  check=True).stdout
        entries = set(re.findall(r"\b(Ktgf\w+)", exported))
        stage = v.kind == "stage"
        assert entries == set(flux_kernel.ENTRIES[v.kind]) | ({"KtgfRegisterCells", "KtgfRingElements"} if stage else set())
        symbols = subprocess.run(["nm", "-C", str(library)], capture_output=True, text=True, check=True).stdout
        fused = set(re.findall(r"sweep_fused<(\w+), (\d), (\d)>", symbols))  # the cell-program stage's sweep
        assert fused == ({sweep[:3]} if stage else set()), v


@pytest.mark.contract
def test_a_library_refuses_a_call_of_another_variant(monkeypatch) -> None:
    """Every call goes to the float64 vanleer/hll viscous library here: a call that asks for another
    precision, limiter, Riemann solver or viscous flag is an error, never that library's result."""
    grid, phys = _grid(), _physics("ret")

    def divergence(dtype, limiter: str, riemann: str, viscous: bool):
        U = _state(grid, phys, dtype)
        W, eos, transport, _ = kernel_stage_inputs(U, cell_coefficients(primitive_fields(U), grid, phys), phys)
        return jax.jit(lambda: flux_kernel.flux_divergence(W, eos, transport, grid, RHO_S, limiter, riemann,
                                                           viscous))()

    want = divergence(jnp.float64, "vanleer", "hll", True)
    target = flux_kernel._target
    monkeypatch.setattr(flux_kernel, "_target",
                        lambda base, *args: target(base, jnp.float64, "vanleer", "hll", "rhs"))
    got = divergence(jnp.float64, "vanleer", "hll", True)
    assert _close(got[0], want[0]) == 0.0 and float(jnp.max(jnp.abs(got[1] - want[1]))) == 0.0
    others = [(jnp.float64, "minmod", "hll", True, "float64 minmod/hll viscous"),
              (jnp.float64, "vanleer", "rusanov", True, "float64 vanleer/rusanov viscous"),
              (jnp.float64, "vanleer", "hll", False, "float64 vanleer/hll inviscid"),
              (jnp.float32, "vanleer", "hll", True, "float32 vanleer/hll viscous")]
    for dtype, limiter, riemann, viscous, asked in others:
        with pytest.raises(jax.errors.JaxRuntimeError,
                           match=f"built for float64 vanleer/hll viscous, the call asks for {asked}"):
            jax.block_until_ready(divergence(dtype, limiter, riemann, viscous))


@pytest.mark.contract
def test_two_processes_build_a_variant_once(tmp_path) -> None:
    """Two processes that need the same variant at the same time: one compiles, the other waits and loads it."""
    script = ("import logging; logging.basicConfig(level=logging.INFO, format='%(message)s')\n"
              "from ktgf.solver import flux_kernel as k\n"
              "print(k.build(k.Variant('float32', 'none', 'rusanov', 'euler')))")
    env = {**os.environ, "KTGF_CACHE_DIR": str(tmp_path)}
    procs = [subprocess.Popen([sys.executable, "-c", script], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for _ in range(2)]
    outs = [proc.communicate(timeout=600) for proc in procs]
    assert [proc.returncode for proc in procs] == [0, 0], outs
    libraries = {out.strip() for out, _ in outs}
    assert len(libraries) == 1
    assert sorted(f.name for f in tmp_path.iterdir() if f.suffix != ".lock") == [os.path.basename(libraries.pop())]
    logs = "".join(err for _, err in outs)  # one build; the other process may say it waits for it
    assert len(re.findall(r"^compiling the CPU flux kernel for float32 none/rusanov euler ", logs, re.M)) == 1, logs
    assert len(re.findall(r"^compiled ", logs, re.M)) == 1, logs


@pytest.mark.contract
def test_a_build_is_announced_once(monkeypatch, tmp_path, caplog) -> None:
    """A build logs that it starts (what, and that it is once per machine) and its time; the cache hit after it,
    nothing."""
    compiler = tmp_path / "fake-cxx"  # writes an empty "library": only the announcement is checked here
    compiler.write_text('#!/bin/sh\nfor last; do :; done\n: > "$last"\n')
    compiler.chmod(0o755)
    monkeypatch.setenv("CXX", str(compiler))
    monkeypatch.setenv("KTGF_CACHE_DIR", str(tmp_path / "cache"))
    v = flux_kernel.variant(jnp.float32, "mc", "rusanov", "stage")
    with caplog.at_level(logging.INFO, logger="ktgf"):
        assert flux_kernel.build(v) == flux_kernel.build(v)
    messages = [r.getMessage() for r in caplog.records if r.name.startswith("ktgf")]
    assert len(messages) == 2, messages
    assert messages[0] == "compiling the CPU flux kernel for float32 mc/rusanov stage (once per machine, about 10-15 s)"
    assert re.fullmatch(r"compiled the CPU flux kernel for float32 mc/rusanov stage in \d+\.\d s", messages[1])


@pytest.mark.contract
def test_the_command_line_shows_the_build_messages(capsys) -> None:
    """Library use is silent at INFO; the ``ktgf`` command's entry shows the ``ktgf`` INFO records on stderr."""
    from ktgf.cli import show_info

    logger, record = logging.getLogger("ktgf"), logging.getLogger("ktgf.solver.cxx")
    saved = list(logger.handlers), logger.level
    try:
        logger.handlers.clear()
        logger.setLevel(logging.NOTSET)
        record.info("compiling something")
        assert "compiling something" not in capsys.readouterr().err
        show_info()
        record.info("compiling something")
        assert capsys.readouterr().err == "ktgf: compiling something\n"
    finally:
        logger.handlers[:] = saved[0]
        logger.setLevel(saved[1])
