"""CPU fast path of :func:`.fluxes.flux_divergence` and of a whole SSP-RK3 stage: XLA FFI custom calls (``flux_kernel.cc``).

The kernel does the numerics of :mod:`.fluxes` only (MUSCL reconstruction with the configured
limiter, HLL/Rusanov, central viscous stress and heat flux, face divergence, ∇·u) from the same
cell fields the JAX path gets; every closure stays in Python (the cell programs of
:func:`ssprk_stage_cells` are generated from it).  It computes each face once
instead of once per flux component (docs/solver.md, Speed) and agrees with the JAX path to
round-off (tests/test_solver_flux_kernel.py).  :func:`ssprk_stage` also applies the energy
source and the stage update of :func:`.stepping.ssprk3_step` in the same sweep, so a stage of
the explicit scheme is one closure pass (XLA) and one kernel call; :func:`ssprk_stage_cells` also
evaluates the closures, by a generated cell program (:mod:`.cell_program`), so a stage is one call;
a step's first stage is :func:`cell_fields` (closures and the maxima of the step-limit terms, in the
padding pass) and :func:`ssprk_stage_padded`, with the step size computed from the maxima between them.

It is used where it applies — CPU backend, one device, a 3D fully periodic grid, float32 or
float64 — and when it is switched on: :data:`.fluxes.FLUX_KERNEL` (default from the environment
variable ``KTGF_FLUX_KERNEL``; ``0`` switches it off).  The JAX path remains the reference and
the path for GPUs, sharding, walls and Lees–Edwards boundaries.

Build: compiled on first use with the C++ compiler ``$CXX`` (default ``g++``; OpenMP, ``-O3
-march=native``) into ``$KTGF_CACHE_DIR`` (default ``~/.cache/ktgf``), keyed by the source, the
flags, jaxlib's version and the host; without a compiler (or if the build fails) the JAX path
runs and one warning says why.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import platform
import shutil
import subprocess
import tempfile
import warnings
from pathlib import Path
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

SOURCE = Path(__file__).with_name("flux_kernel.cc")
TARGET = "ktgf_flux_divergence"
STAGE_TARGET = "ktgf_ssprk_stage"
CELLS_TARGET = "ktgf_ssprk_stage_cells"
CELLS_PAD_TARGET = "ktgf_cells_pad"
STAGE_PADDED_TARGET = "ktgf_ssprk_stage_padded"
FLAGS = ("-O3", "-march=native", "-fopenmp", "-ffp-contract=off", "-fno-math-errno", "-shared", "-fPIC", "-std=c++17")
_loaded: dict[str, Any] = {}


def _cache_dir() -> Path:
    return Path(os.environ.get("KTGF_CACHE_DIR", Path.home() / ".cache" / "ktgf"))


def build() -> Path:
    """The compiled library (built now if not in the cache); raises RuntimeError if it cannot be."""
    cxx = shutil.which(os.environ.get("CXX", "g++"))
    if cxx is None:
        raise RuntimeError(f"no C++ compiler ({os.environ.get('CXX', 'g++')!r} not found)")
    key = hashlib.sha256(b"\0".join([SOURCE.read_bytes(), " ".join(FLAGS).encode(), cxx.encode(),
                                     jax.__version__.encode(), platform.node().encode()])).hexdigest()[:16]
    lib = _cache_dir() / f"flux_kernel-{key}.so"
    if lib.exists():
        return lib
    lib.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".so", dir=lib.parent)
    os.close(fd)
    cmd = [cxx, *FLAGS, f"-I{jax.ffi.include_dir()}", str(SOURCE), "-o", tmp]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        os.unlink(tmp)
        last = (proc.stderr.strip().splitlines() or ["?"])[-1]
        raise RuntimeError(f"compiling {SOURCE.name} failed: {last}")
    os.replace(tmp, lib)  # atomic: parallel test workers may build at the same time
    return lib


def available() -> bool:
    """Whether the kernel is built and registered with XLA (tried once per process)."""
    if "ok" not in _loaded:
        try:
            # Idle OpenMP threads must sleep, not spin: between calls XLA's own threads need the cores.
            os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
            lib = ctypes.cdll.LoadLibrary(str(build()))
            jax.ffi.register_ffi_target(TARGET, jax.ffi.pycapsule(lib.KtgfFluxDivergence), platform="cpu")
            jax.ffi.register_ffi_target(STAGE_TARGET, jax.ffi.pycapsule(lib.KtgfSsprkStage), platform="cpu")
            jax.ffi.register_ffi_target(CELLS_TARGET, jax.ffi.pycapsule(lib.KtgfSsprkStageCells), platform="cpu")
            jax.ffi.register_ffi_target(CELLS_PAD_TARGET, jax.ffi.pycapsule(lib.KtgfCellsPad), platform="cpu")
            jax.ffi.register_ffi_target(STAGE_PADDED_TARGET, jax.ffi.pycapsule(lib.KtgfSsprkStagePadded),
                                        platform="cpu")
            _loaded["lib"] = lib
            _loaded["ok"] = True
        except (RuntimeError, OSError) as err:
            warnings.warn(f"ktgf flux kernel unavailable, using the JAX path: {err}", RuntimeWarning, stacklevel=2)
            _loaded["ok"] = False
    return _loaded["ok"]


def applies(grid: Any, dtype: Any) -> bool:
    """Whether the kernel can replace the JAX flux divergence here (see the module docstring)."""
    periodic = grid.boundaries is None or grid.boundaries.all_periodic
    return (grid.ndim == 3 and periodic and jnp.dtype(dtype) in (jnp.float32, jnp.float64)
            and jax.default_backend() == "cpu" and jax.device_count() == 1 and available())


def _cell_fields(W: Any, eos: Any, transport: Any, grid: Any, viscous: bool) -> tuple[list[Any], Any]:
    """The kernel's 11 cell-field inputs and its workspace (their copies with periodic ghost cells)."""
    from .fluxes import GHOST

    dtype = W[0].dtype
    fields = [jnp.asarray(f, dtype) for f in (*W, *eos)]
    # Non-viscous calls pass ρ in the unused transport slots (no copy; the kernel ignores them).
    fields += [jnp.asarray(f, dtype) for f in transport] if viscous else [fields[0]] * 4
    nfield = 11 if viscous else 7
    return fields, jax.ShapeDtypeStruct((nfield, *(n + 2 * GHOST for n in grid.cells)), dtype)


def _schemes(limiter: str, riemann: str) -> dict[str, Any]:
    from .fluxes import LIMITERS, RIEMANN_SOLVERS

    return {"limiter": np.int32(LIMITERS.index(limiter)), "riemann": np.int32(RIEMANN_SOLVERS.index(riemann))}


def flux_divergence(W: Any, eos: Any, transport: Any, grid: Any, rho_s: Any, limiter: str, riemann: str,
                    viscous: bool) -> tuple[list[Any], Any]:
    """−∇·F of the five conservative fields and the central ∇·u, as :func:`.fluxes.flux_divergence`."""
    fields, work = _cell_fields(W, eos, transport, grid, viscous)
    field = jax.ShapeDtypeStruct(tuple(grid.cells), W[0].dtype)
    call = jax.ffi.ffi_call(TARGET, (field,) * 6 + (work,))
    params = jnp.stack([jnp.asarray(v, jnp.float64) for v in (*grid.spacing, rho_s)])
    out = call(*fields, params, **_schemes(limiter, riemann), viscous=np.int32(viscous))
    return list(out[:5]), out[5]


def ssprk_stage(U0: Any, Uk: Any, W: Any, eos: Any, transport: Any, source: tuple[Any, Any], a: Any, dt: Any,
                grid: Any, rho_s: Any, limiter: str, riemann: str) -> tuple[Any, ...]:
    """One SSP-RK3 stage U' = a U0 + (1 − a)(Uk + Δt L(Uk)), as in :func:`.stepping.ssprk3_step`.

    L = −∇·F (convective, viscous and heat fluxes, as :func:`flux_divergence`) plus the energy
    source s0 + s1 ∇·u with ``source`` = (s0, s1) at the cells of Uk (:func:`.sources.cooling_source`
    is linear in ∇·u); ``W``, ``eos``, ``transport``: the primitive fields and cell coefficients of Uk.
    """
    dtype = Uk[0].dtype
    fields, work = _cell_fields(W, eos, transport, grid, True)
    state = [jnp.asarray(f, dtype) for f in (*U0, *Uk, *source)]
    field = jax.ShapeDtypeStruct(tuple(grid.cells), dtype)
    # U' is written over Uk (each cell reads its own Uk only, after the fluxes): no new buffers, and
    # none of the loop-carry copies XLA inserts when a stage's output cannot take its input's place.
    call = jax.ffi.ffi_call(STAGE_TARGET, (field,) * 5 + (work,),
                            input_output_aliases={len(fields) + 6 + v: v for v in range(5)})
    params = _stage_params(a, dt, grid, rho_s, dtype)
    return tuple(call(*fields, params, *state, **_schemes(limiter, riemann))[:5])


def _register(program: Any) -> None:
    """Makes a :class:`~.cell_program.CellProgram` known to the stage kernel (once per process and program)."""
    done = _loaded.setdefault("programs", set())
    if program.key not in done:
        bits = 8 * program.dtype.itemsize
        _loaded["lib"].KtgfRegisterCells(ctypes.c_int64(program.key), ctypes.c_void_p(program.address),
                                         ctypes.c_int32(bits))
        done.add(program.key)


def _workspace(grid: Any, dtype: Any) -> Any:
    """The cell-program workspace: the 11 kernel cell fields with periodic ghost cells, then s0 and s1."""
    from .fluxes import GHOST

    padded = int(np.prod([n + 2 * GHOST for n in grid.cells]))
    return jax.ShapeDtypeStruct((11 * padded + 2 * grid.size,), dtype)


def cell_fields(Uk: Any, program: Any, leaf: Any, grid: Any) -> tuple[Any, Any]:
    """The workspace of the step-start cell program ``program`` (:func:`.cell_program.for_physics` with
    ``limits``) at the state Uk, and the maxima over the cells of its limit terms
    (:data:`.stepping.LIMIT_TERMS`), reduced in the same pass: the closures and step-limit reductions of a
    step's start in one call, so that the step size is known before :func:`ssprk_stage_padded` runs the
    first stage on this workspace."""
    _register(program)
    dtype = Uk[0].dtype
    call = jax.ffi.ffi_call(CELLS_PAD_TARGET, (_workspace(grid, dtype), jax.ShapeDtypeStruct((program.nlim,), dtype)))
    return call(leaf, *(jnp.asarray(f, dtype) for f in Uk), program=np.int64(program.key), nlim=np.int32(program.nlim))


def _stage_params(a: Any, dt: Any, grid: Any, rho_s: Any, dtype: Any) -> Any:
    # a and Δt as the state precision rounds them (the JAX path computes in that precision).
    coef = [jnp.asarray(v).astype(dtype).astype(jnp.float64) for v in (a, dt)]
    return jnp.stack([*(jnp.asarray(v, jnp.float64) for v in (*grid.spacing, rho_s)), *coef])


def ssprk_stage_cells(U0: Any, Uk: Any, program: Any, leaf: Any, a: Any, dt: Any, grid: Any, rho_s: Any,
                      limiter: str, riemann: str) -> tuple[Any, ...]:
    """The SSP-RK3 stage of :func:`ssprk_stage` with the cell fields and the energy source computed in
    the kernel from Uk by a cell program (:func:`.cell_program.for_physics`) with parameters ``leaf``
    (:func:`.cell_program.leaf_values`)."""
    _register(program)
    dtype = Uk[0].dtype
    state = [jnp.asarray(f, dtype) for f in (*U0, *Uk)]
    field = jax.ShapeDtypeStruct(tuple(grid.cells), dtype)
    call = jax.ffi.ffi_call(CELLS_TARGET, (field,) * 5 + (_workspace(grid, dtype),),
                            input_output_aliases={7 + v: v for v in range(5)})
    params = _stage_params(a, dt, grid, rho_s, dtype)
    return tuple(call(params, leaf, *state, **_schemes(limiter, riemann), program=np.int64(program.key))[:5])


def ssprk_stage_padded(U0: Any, Uk: Any, work: Any, a: Any, dt: Any, grid: Any, rho_s: Any, limiter: str,
                       riemann: str) -> tuple[Any, ...]:
    """The stage of :func:`ssprk_stage_cells` from the workspace ``work`` = :func:`cell_fields` of Uk."""
    dtype = Uk[0].dtype
    state = [jnp.asarray(f, dtype) for f in (*U0, *Uk)]
    field = jax.ShapeDtypeStruct(tuple(grid.cells), dtype)
    call = jax.ffi.ffi_call(STAGE_PADDED_TARGET, (field,) * 5, input_output_aliases={6 + v: v for v in range(5)})
    params = _stage_params(a, dt, grid, rho_s, dtype)
    return tuple(call(params, *state, work, **_schemes(limiter, riemann)))
