"""CPU fast path of :func:`.fluxes.flux_divergence` and of a whole SSP-RK3 stage: XLA FFI custom calls (``flux_kernel.cc``).

The kernel does the numerics of :mod:`.fluxes` only (MUSCL reconstruction, HLL/Rusanov, central viscous
stress and heat flux, face divergence, ∇·u), computing each face once instead of once per flux component
(docs/solver.md, Speed); it agrees with the JAX path to round-off (tests/solver/test_solver_flux_kernel.py).
Every closure stays in Python.  :func:`ssprk_stage` also applies the energy source and the stage update of
:func:`.stepping.ssprk3_step`; :func:`ssprk_stage_cells` also evaluates the closures, by a cell program
generated from them (:mod:`.cell_program`), plane by plane as it sweeps, so a stage is one call;
:func:`cell_limits` reduces the step-limit and state-check terms of a state.

It is used where it applies — CPU backend, one device, a 3D grid, float32 or float64 — unless
:data:`.fluxes.FLUX_KERNEL` is off (``KTGF_FLUX_KERNEL=0``).  With walls or Lees–Edwards boundaries the caller
passes the ghost planes of the boundary axis, which the kernel puts over its periodic padding, and corrects the
planes next to the boundary (:func:`.fluxes.kernel_fields`); the cell programs run on periodic grids only.  The JAX path remains the reference and the path for GPUs and sharding.

Build: one shared library per :class:`Variant`, compiled when a solver first needs it (:func:`applies`) by
:mod:`.cxx` into ``$KTGF_CACHE_DIR`` (default ``~/.cache/ktgf``) and kept there; ``-D`` macros choose the
variant, so a build compiles the face sweep once (7–15 s here).  A variant's FFI targets are the base names
(:data:`TARGET`, ...) plus :attr:`Variant.suffix`.  Without a compiler (or if a build fails, or JAX has no
``jax.ffi``) the JAX path runs and one WARNING on the ``ktgf`` logger says why and what it costs
(:func:`unavailable`); no further build is tried in that process.
"""

from __future__ import annotations

import ctypes
import logging
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from .cxx import shared_library, warn_once
from .stencil import GHOST, LIMITERS, RIEMANN_SOLVERS

log = logging.getLogger(__name__)

SOURCE = Path(__file__).with_name("flux_kernel.cc")
#: Base names of the FFI targets; a variant's are these plus its :attr:`Variant.suffix`.
TARGET = "ktgf_flux_divergence"
STAGE_TARGET = "ktgf_ssprk_stage"
CELLS_TARGET = "ktgf_ssprk_stage_cells"
LIMITS_TARGET = "ktgf_cell_limits"
#: Spins (``pause`` instructions, 3000 take 80 us on this machine) an idle OpenMP thread waits before it sleeps.
SPIN_COUNT = 3000
#: What the JAX path costs where the kernel would run, for the one-line warning when it cannot be built: the
#: time per step of the JAX path over the kernel's (docs/solver.md, "Fallbacks": 64³ RET float64 SSP-RK3).
FALLBACK_COST = "about 6x the time per SSP-RK3 step on a periodic 3D grid"
#: What a library computes, in the order of the KTGF_KIND values of flux_kernel.cc: the viscous flux
#: divergence (:func:`flux_divergence` with ``viscous``), the inviscid one (the explicit part of the IMEX
#: scheme), and the SSP-RK3 stage (:func:`ssprk_stage`, :func:`ssprk_stage_cells`, :func:`cell_limits` and the
#: cell-program registry).
KINDS = ("rhs", "euler", "stage")
#: The FFI entries (C symbol: base target name) in a library of each kind.
ENTRIES = {
    "rhs": {"KtgfFluxDivergence": TARGET},
    "euler": {"KtgfFluxDivergence": TARGET},
    "stage": {"KtgfSsprkStage": STAGE_TARGET, "KtgfSsprkStageCells": CELLS_TARGET, "KtgfCellLimits": LIMITS_TARGET},
}
#: Loaded libraries by :class:`Variant`; ``"failed"``: why a build failed (none is tried after it);
#: ``"programs"``: the (variant, key) of the cell programs registered with a stage library.
_loaded: dict[Any, Any] = {}


@dataclass(frozen=True)
class Variant:
    """One build of the kernel: the state precision (``"float64"`` or ``"float32"``), the limiter (one of
    :data:`.stencil.LIMITERS`), the Riemann solver (:data:`.stencil.RIEMANN_SOLVERS`) and the kind (:data:`KINDS`)."""

    dtype: str
    limiter: str
    riemann: str
    kind: str

    def __post_init__(self) -> None:
        for value, valid in ((self.dtype, ("float64", "float32")), (self.limiter, LIMITERS),
                             (self.riemann, RIEMANN_SOLVERS), (self.kind, KINDS)):
            if value not in valid:
                raise ValueError(f"no flux kernel variant for {value!r}; valid: {valid}")

    def __str__(self) -> str:
        return f"{self.dtype} {self.limiter}/{self.riemann} {self.kind}"

    @property
    def suffix(self) -> str:
        """What this variant's FFI target names add to the base names, e.g. ``__f64_vanleer_hll_stage``."""
        return f"__f{self.dtype[5:]}_{self.limiter}_{self.riemann}_{self.kind}"

    @property
    def macros(self) -> tuple[str, ...]:
        """The ``-D`` flags that select the variant in flux_kernel.cc."""
        return (f"-DKTGF_REAL={'double' if self.dtype == 'float64' else 'float'}",
                f"-DKTGF_LIMITER={LIMITERS.index(self.limiter)}",
                f"-DKTGF_RIEMANN={RIEMANN_SOLVERS.index(self.riemann)}", f"-DKTGF_KIND={KINDS.index(self.kind)}")


#: The variant :func:`available` builds: the SSP-RK3 stage of the default numerics in float64.
DEFAULT = Variant("float64", "vanleer", "hll", "stage")


def variant(dtype: Any, limiter: str, riemann: str, kind: str) -> Variant:
    """The :class:`Variant` of a state of ``dtype`` (any form :func:`jax.numpy.dtype` takes)."""
    return Variant(jnp.dtype(dtype).name, limiter, riemann, kind)


def target(base: str, v: Variant) -> str:
    """The FFI target name of the entry ``base`` (e.g. :data:`STAGE_TARGET`) in the library of ``v``."""
    return base + v.suffix


def build(v: Variant = DEFAULT) -> Path:
    """The compiled library of the variant ``v`` (built now if not in the cache); raises RuntimeError if it cannot
    be."""
    if not hasattr(jax, "ffi"):
        raise RuntimeError(f"jax {jax.__version__} has no jax.ffi (jax >= 0.5 has)")
    return shared_library("flux_kernel", SOURCE, (*v.macros, f"-I{jax.ffi.include_dir()}"),
                          f"the CPU flux kernel for {v}", "10-15 s", threads=True)


def _library(v: Variant) -> Any:
    """The library of ``v`` (ctypes), loaded and its FFI targets registered on first need; raises
    RuntimeError or OSError if it cannot be built or loaded."""
    lib = _loaded.get(v)
    if lib is None:
        # Idle OpenMP threads sleep (XLA's threads need the cores between calls), after a short spin: waking them
        # for each of a step's three calls cost about 0.2 ms per step.  libgomp reads both when it loads.
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
        os.environ.setdefault("GOMP_SPINCOUNT", str(SPIN_COUNT))
        lib = ctypes.cdll.LoadLibrary(str(build(v)))
        for entry, base in ENTRIES[v.kind].items():
            jax.ffi.register_ffi_target(target(base, v), jax.ffi.pycapsule(getattr(lib, entry)), platform="cpu")
        if v.kind == "stage":
            lib.KtgfRingElements.restype = ctypes.c_long
        _loaded[v] = lib
    return lib


def _usable(v: Variant) -> bool:
    """Whether the library of ``v`` is loaded, or can be now.  The first failure warns (one line, WARNING on the
    ``ktgf`` logger: why, and what the JAX path costs) and switches the kernel off for the process: a compiler
    that fails once would fail (slowly) for every variant."""
    if "failed" in _loaded:
        return False
    try:
        _library(v)
    except (RuntimeError, OSError) as err:
        _loaded["failed"] = str(err)
        warn_once(log, f"the C++ flux kernel is not available ({err}); the solver runs the JAX path instead, "
                       f"{FALLBACK_COST} (docs/solver.md, Fallbacks)")
        return False
    return True


def unavailable() -> str | None:
    """Why the kernel is off in this process (the error of its first failed build), or None if it is not (yet)."""
    return _loaded.get("failed")


def available() -> bool:
    """Whether the kernel can be used: :data:`DEFAULT` is built (once per machine) and registered."""
    return _usable(DEFAULT)


def applies(grid: Any, dtype: Any, kind: str, limiter: str, riemann: str) -> bool:
    """Whether the variant (``dtype``, ``limiter``, ``riemann``, ``kind``) of the kernel can replace the JAX path
    on ``grid`` (see the module docstring; other boundaries than periodic: the caller pads the fields,
    :func:`.fluxes.kernel_fields`); builds it if needed."""
    return (grid.ndim == 3 and jnp.dtype(dtype) in (jnp.float32, jnp.float64)
            and jax.default_backend() == "cpu" and jax.device_count() == 1
            and _usable(variant(dtype, limiter, riemann, kind)))


def _target(base: str, dtype: Any, limiter: str, riemann: str, kind: str) -> str:
    """The FFI target of the entry ``base`` in the library of that variant, loaded if it is not yet."""
    v = variant(dtype, limiter, riemann, kind)
    _library(v)
    return target(base, v)


def _cell_fields(W: Any, eos: Any, transport: Any, grid: Any, viscous: bool) -> tuple[list[Any], Any]:
    """The kernel's 11 cell-field inputs and its workspace (their copies with ghost cells)."""
    dtype = W[0].dtype
    fields = [jnp.asarray(f, dtype) for f in (*W, *eos)]
    # Non-viscous calls pass ρ in the unused transport slots (no copy; the kernel ignores them).
    fields += [jnp.asarray(f, dtype) for f in transport] if viscous else [fields[0]] * 4
    nfield = 11 if viscous else 7
    return fields, jax.ShapeDtypeStruct((nfield, *(n + 2 * GHOST for n in grid.cells)), dtype)


def _ghost_args(params: Any, ghosts: Any, dtype: Any, fix: Any = None, grid: Any = None) -> tuple[Any, list[Any]]:
    """The kernel's params and extra fields with the ghost planes ``ghosts`` = (axis, planes), or None: the axis
    appended to the params, the planes one extra field; a stage's boundary corrections ``fix`` (as
    :func:`.fluxes.add_boundary_fluxes` takes them, on ``grid``) a second one, their planes next to the cells 0 and
    n − 1 of the axis (zero where ``fix`` has none), five fields each."""
    if ghosts is None:
        return params, []
    extra = [jnp.asarray(ghosts[1], dtype)]
    if fix is not None:
        a, planes = fix
        shape = tuple(c for b, c in enumerate(grid.cells) if b != a)
        zero = [jnp.zeros(shape, dtype)] * 5
        extra.append(jnp.stack([jnp.stack([jnp.reshape(c, shape).astype(dtype) for c in planes.get(p, zero)])
                                for p in (0, grid.cells[a] - 1)]))
    return jnp.append(params, jnp.asarray(ghosts[0], jnp.float64)), extra


def _schemes(limiter: str, riemann: str) -> dict[str, Any]:
    return {"limiter": np.int32(LIMITERS.index(limiter)), "riemann": np.int32(RIEMANN_SOLVERS.index(riemann))}


def flux_divergence(W: Any, eos: Any, transport: Any, grid: Any, rho_s: Any, limiter: str, riemann: str,
                    viscous: bool, ghosts: Any = None) -> tuple[list[Any], Any]:
    """−∇·F of the five conservative fields and the central ∇·u, as :func:`.fluxes.flux_divergence`.

    ``ghosts``: None (periodic) or (axis, planes): the ghost planes along that axis (:func:`.fluxes.kernel_fields`)."""
    fields, work = _cell_fields(W, eos, transport, grid, viscous)
    field = jax.ShapeDtypeStruct(tuple(grid.cells), W[0].dtype)
    kind = "rhs" if viscous else "euler"
    call = jax.ffi.ffi_call(_target(TARGET, W[0].dtype, limiter, riemann, kind), (field,) * 6 + (work,))
    params, extra = _ghost_args(jnp.stack([jnp.asarray(v, jnp.float64) for v in (*grid.spacing, rho_s)]), ghosts,
                                W[0].dtype)
    out = call(params, *fields, *extra, **_schemes(limiter, riemann), viscous=np.int32(viscous))
    return list(out[:5]), out[5]


def ssprk_stage(U0: Any, Uk: Any, W: Any, eos: Any, transport: Any, source: tuple[Any, Any], a: Any, dt: Any,
                grid: Any, rho_s: Any, limiter: str, riemann: str, ghosts: Any = None, fix: Any = None,
                gravity: Any = None) -> tuple[Any, ...]:
    """One SSP-RK3 stage U' = a U0 + (1 − a)(Uk + Δt L(Uk)), as in :func:`.stepping.ssprk3_step`.

    L = −∇·F (convective, viscous and heat fluxes, as :func:`flux_divergence`) plus the energy
    source s0 + s1 ∇·u with ``source`` = (s0, s1) at the cells of Uk (:func:`.sources.cooling_source`
    is linear in ∇·u) plus the body force (:func:`.sources.add_body_force`, ``gravity`` = g or None);
    ``W``, ``eos``, ``transport``: the primitive fields and cell coefficients of Uk; ``ghosts`` as in
    :func:`flux_divergence`, with the boundary corrections ``fix`` of :func:`.fluxes.boundary_terms` (L's on
    the planes next to the boundary; the kernel adds them to its output).
    """
    dtype = Uk[0].dtype
    fields, work = _cell_fields(W, eos, transport, grid, True)
    state = [jnp.asarray(f, dtype) for f in (*U0, *Uk, *source)]
    field = jax.ShapeDtypeStruct(tuple(grid.cells), dtype)
    # U' is written over Uk (each cell reads its own Uk only, after the fluxes): no new buffers, and
    # none of the loop-carry copies XLA inserts when a stage's output cannot take its input's place.
    call = jax.ffi.ffi_call(_target(STAGE_TARGET, dtype, limiter, riemann, "stage"), (field,) * 5 + (work,),
                            input_output_aliases={1 + len(fields) + 5 + v: v for v in range(5)})
    params, extra = _ghost_args(_stage_params(a, dt, grid, rho_s, dtype, gravity), ghosts, dtype, fix, grid)
    return tuple(call(params, *fields, *state, *extra, **_schemes(limiter, riemann))[:5])


def _register(program: Any, limiter: str, riemann: str, grid: Any) -> None:
    """Makes a :class:`~.cell_program.CellProgram` known to the stage library of its precision with ``limiter`` and
    ``riemann`` on ``grid``, whose calls use it (each library has its own registry; once per process, library and
    program)."""
    v = variant(program.dtype, limiter, riemann, "stage")
    done = _loaded.setdefault("programs", set())
    if (v, program.key) not in done:
        bits = 8 * program.dtype.itemsize
        if _library(v).KtgfRegisterCells(ctypes.c_int64(program.key), ctypes.c_void_p(program.address),
                                         ctypes.c_int32(bits)) != 0:
            raise RuntimeError(f"a {program.dtype} cell program cannot be registered with the {v} kernel")
        done.add((v, program.key))


def cell_limits(Uk: Any, program: Any, leaf: Any, grid: Any, limiter: str, riemann: str) -> Any:
    """The maxima over the cells of the terms (step limits, then state status) of the step-start cell program
    ``program`` (:func:`.cell_program.for_physics` with ``limits``) at the state Uk, in one pass that writes
    nothing per cell: the check of an ``advance`` call's last state.  ``limiter``, ``riemann``: those of the
    stages, whose library this call uses."""
    _register(program, limiter, riemann, grid)
    dtype = Uk[0].dtype
    call = jax.ffi.ffi_call(_target(LIMITS_TARGET, dtype, limiter, riemann, "stage"),
                            jax.ShapeDtypeStruct((program.nlim,), dtype))
    return call(leaf, *(jnp.asarray(f, dtype) for f in Uk), program=np.int64(program.key))


def _stage_params(a: Any, dt: Any, grid: Any, rho_s: Any, dtype: Any, gravity: Any) -> Any:
    # a, Δt and g as the state precision rounds them (the JAX path computes in that precision).
    coef = [jnp.asarray(v).astype(dtype).astype(jnp.float64) for v in (a, dt, *(gravity or (0.0, 0.0, 0.0)))]
    return jnp.stack([*(jnp.asarray(v, jnp.float64) for v in (*grid.spacing, rho_s)), *coef])


def _ring(grid: Any, dtype: Any, v: Variant) -> Any:
    """The workspace of :func:`ssprk_stage_cells`: the planes its threads keep (``KtgfRingElements``)."""
    n = [ctypes.c_long(int(c)) for c in grid.cells]
    return jax.ShapeDtypeStruct((int(_library(v).KtgfRingElements(*n)),), dtype)


def ssprk_stage_cells(U0: Any, Uk: Any, program: Any, leaf: Any, a: Any, dt: Any, grid: Any, rho_s: Any,
                      limiter: str, riemann: str, write_over: str = "uk", ghosts: Any = None, fix: Any = None,
                      gravity: Any = None) -> tuple[Any, ...]:
    """The SSP-RK3 stage of :func:`ssprk_stage` with the cell fields and the energy source computed in
    the kernel from Uk by a cell program (:func:`.cell_program.for_physics`) with parameters ``leaf``
    (:func:`.cell_program.leaf_values`), plane by plane as it sweeps: no cell field is written to memory.

    ``write_over``: the input buffers U' is written over: ``"uk"`` or ``"new"`` (where Uk is still read
    elsewhere: written in place, XLA would first copy it).  ``ghosts``: as in :func:`flux_divergence`, along y
    or z (the cell fields of the ghost cells); ``fix``, ``gravity``: as in :func:`ssprk_stage`.
    """
    _register(program, limiter, riemann, grid)
    dtype = Uk[0].dtype
    state = [jnp.asarray(f, dtype) for f in (*U0, *Uk)]
    stage = variant(dtype, limiter, riemann, "stage")
    field = jax.ShapeDtypeStruct(tuple(grid.cells), dtype)
    # The inputs are params, leaf, U0 (5), Uk (5).
    aliases = {"uk": {7 + i: i for i in range(5)}, "new": None}[write_over]
    call = jax.ffi.ffi_call(target(CELLS_TARGET, stage), (field,) * 5 + (_ring(grid, dtype, stage),),
                            input_output_aliases=aliases)
    params, extra = _ghost_args(_stage_params(a, dt, grid, rho_s, dtype, gravity), ghosts, dtype, fix, grid)
    out = call(params, leaf, *state, *extra, **_schemes(limiter, riemann), program=np.int64(program.key))
    return tuple(out[:5])
