"""Start a run from an earlier run's result on another grid (grid sequencing, as OpenFOAM's mapFields;
docs/solver.md, "Starting from an earlier run").

``[initial] from_run = "path"`` names the output folder of an earlier run (its ``checkpoint.npz``) or a
checkpoint file.  Along a periodic axis the new box may be a whole multiple of the old one (the state is tiled
first); then every axis is remapped conservatively (:func:`remap_axis`, :func:`_remap_state`): order 2, or order
1 where order 2 would leave the physical state space (θ ≤ 0, ρ ≤ 0).  A grid equal to the earlier one gives the
earlier state bit for bit.  The earlier run must be the same flow (:data:`SAME_FIELDS`, the dimension, and the
box length along a wall or Lees–Edwards axis): each mismatch is refused in one line naming the field.  The new
run starts at t = 0 (a Lees–Edwards image shift restarts at 0), plus ``perturbation = "random"``
(:func:`~.initial.perturb`) if configured.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, KtgfError
from .boundaries import PERIODIC
from .config import box_lengths, changed_fields, config_value, parse_config
from .flows import VERIFICATION_FILE, boundaries
from .io import CHECKPOINT, load_checkpoint
from .state import NVAR

#: Config fields that must be the same in the earlier run (dotted; sections compared leaf by leaf).
SAME_FIELDS = ("case", "model", "particles", "boundaries", "initial.solid_fraction")
#: Relative tolerance of the box-length checks (lengths in m from the same config arithmetic).
LENGTH_RTOL = 1e-9


def checkpoint_path(path: str | Path) -> Path:
    """The checkpoint of ``initial.from_run``: the file itself, or ``checkpoint.npz`` in a run folder."""
    p = Path(path)
    if p.is_dir():
        p = p / CHECKPOINT
        if not p.is_file():
            raise InputError(f"field initial.from_run = {str(path)!r}: the folder holds no {CHECKPOINT} "
                             "(valid: the output folder of a finished ktgf run, or its checkpoint file)")
        return p
    if p.suffix == ".toml":
        raise InputError(f"field initial.from_run = {str(path)!r} is a run configuration: run the chain with "
                         "ktgf run (or ktgf.solver.chain.run_chain), which runs it first")
    if p.suffix == ".nc":
        raise InputError(f"field initial.from_run = {str(path)!r}: a netCDF time series holds no fields; valid: "
                         f"the run's output folder or its {CHECKPOINT}")
    if not p.is_file():
        raise InputError(f"field initial.from_run = {str(path)!r} does not exist (valid: the output folder of an "
                         f"earlier run or its {CHECKPOINT})")
    return p


def load_run(path: str | Path) -> tuple[np.ndarray, Any, int]:
    """(U, config, steps) of an earlier run: its last checkpointed state, its validated :class:`Config` and
    its step count."""
    ckpt = checkpoint_path(path)
    ck = load_checkpoint(ckpt)
    try:
        old = parse_config(json.loads(ck["config"]), str(ckpt))
    except (ValueError, KtgfError) as exc:
        raise InputError(f"field initial.from_run = {str(path)!r}: its config is not valid here ({exc})") from None
    return np.asarray(ck["U"], dtype=np.float64), old, int(ck["steps"])


def _earlier_cost(path: str | Path, steps: int) -> dict[str, Any]:
    """Steps, wall and CPU time of the earlier run and of the whole sequence up to it (its verification.json)."""
    ver = Path(path) / VERIFICATION_FILE if Path(path).is_dir() else Path(path).with_name(VERIFICATION_FILE)
    try:
        run = json.loads(ver.read_text())["run"]
    except (OSError, ValueError, KeyError, TypeError):
        return {"steps": steps}
    stage = {"steps": steps, "wall_time_s": run.get("wall_time_s"), "cpu_time_s": run.get("cpu_time_s")}
    # the earlier run's own sequence already counts it (and the runs before it)
    return {**stage, "sequence": run.get("sequence") or stage}


def start_from_run(cfg: Any, cells: tuple[int, ...], lengths: tuple[float, ...]) -> tuple[np.ndarray, dict[str, Any]]:
    """The state of ``cfg.initial.from_run`` mapped onto this grid (checked against ``cfg``), and a record of it."""
    source = cfg.initial.from_run
    U_old, old, steps = load_run(source)
    old_lengths = box_lengths(old)
    check_compatible(old, cfg, old_lengths, lengths, source)
    U, order = map_state(U_old, tuple(old.grid.cells), old_lengths, cells, lengths, boundaries(cfg).kinds)
    return U, {"from_run": source, "cells": list(old.grid.cells), "lengths_m": list(old_lengths), "remap_order": order,
               "earlier_run": _earlier_cost(source, steps)}


def mean_temperature(U: np.ndarray) -> float:
    """Mass-weighted mean θ [m²/s²] of a conservative state."""
    rho = U[0]
    theta = (U[4] / rho - 0.5 * np.sum((U[1:4] / rho) ** 2, axis=0)) / 1.5
    return float(np.sum(rho * theta) / np.sum(rho))


def check_compatible(old: Any, new: Any, old_lengths: tuple[float, ...], new_lengths: tuple[float, ...],
                     source: str) -> None:
    """Refuse (one line naming the field) an earlier run that is not the same flow on a mappable box."""
    a, b = old.model_dump(mode="json"), new.model_dump(mode="json")
    where = f"(initial.from_run = {source!r})"
    if changed := [f for name in SAME_FIELDS
                   for f in changed_fields(config_value(a, name), config_value(b, name), name + ".")]:
        key = changed[0]
        raise InputError(f"field {key} = {config_value(b, key)!r} differs from the earlier run's "
                         f"{config_value(a, key)!r} {where}: a run maps only onto the same flow")
    n_old, n_new = len(old.grid.cells), len(new.grid.cells)
    if n_old != n_new:
        raise InputError(f"field grid.cells has {n_new} axes, the earlier run {n_old} {where}: valid the same dimension")
    kinds = boundaries(new).kinds
    for ax, (lo, ln) in enumerate(zip(old_lengths, new_lengths)):
        ratio = ln / lo
        if kinds[ax] != PERIODIC:
            if abs(ratio - 1.0) > LENGTH_RTOL:
                raise InputError(f"field grid length along {'xyz'[ax]} = {ln:.6g} m differs from the earlier run's "
                                 f"{lo:.6g} m {where}: along a {kinds[ax]} axis the box must be the same")
        elif ratio < 1.0 - LENGTH_RTOL or abs(ratio - round(ratio)) > LENGTH_RTOL * ratio:
            raise InputError(f"field grid length along {'xyz'[ax]} = {ln:.6g} m is not a whole multiple of the earlier "
                             f"run's {lo:.6g} m {where}: a periodic axis is the same or tiled (valid: m × {lo:.6g} m)")


def _slopes(f: np.ndarray, axis: int, periodic: bool, limiter: str = "minmod") -> np.ndarray:
    """Differences per cell along ``axis``: minmod-limited, or central (unlimited); one-sided in the end
    cells of a bounded axis."""
    d = np.diff(f, axis=axis)
    n = f.shape[axis]
    if periodic:
        first = last = np.take(f, [0], axis=axis) - np.take(f, [n - 1], axis=axis)  # across the wrap
    else:
        first, last = np.take(d, [0], axis=axis), np.take(d, [n - 2], axis=axis)
    left = np.concatenate([first, d], axis=axis)    # f_i − f_{i−1}
    right = np.concatenate([d, last], axis=axis)   # f_{i+1} − f_i
    if limiter == "central":
        return 0.5 * (left + right)
    return np.where(left * right > 0.0, np.sign(left) * np.minimum(np.abs(left), np.abs(right)), 0.0)


def remap_axis(f: np.ndarray, axis: int, n_new: int, periodic: bool, order: int = 2,
               limiter: str = "minmod") -> np.ndarray:
    """Conservative remap of cell averages ``f`` along ``axis`` onto ``n_new`` equal cells of the same length.

    With cell averages f_i and slopes s_i (order 2; 0 for order 1) the reconstruction in old cell i is
    f_i + s_i ξ, ξ ∈ [−1/2, 1/2]; its integral from the axis start to position X (in old cells) is
    C(X) = Σ_{j<i} f_j + f_i(ξ + 1/2) + s_i(ξ² − 1/4)/2 (i = ⌊X⌋, ξ = X − i − 1/2), and the new average
    of the cell [X_k, X_{k+1}] is (C(X_{k+1}) − C(X_k)) n_new/n_old.  Σ over the new cells telescopes
    to Σ f_j n_new/n_old: the integral is conserved to round-off.
    """
    f = np.moveaxis(np.asarray(f, dtype=np.float64), axis, 0)
    n_old = f.shape[0]
    if n_new == n_old:
        return np.moveaxis(f, 0, axis).copy()
    s = _slopes(f, 0, periodic, limiter) if order == 2 else np.zeros_like(f)
    edges = np.arange(n_new + 1) * (n_old / n_new)      # new cell edges in old-cell units
    edges[-1] = n_old
    i = np.minimum(np.floor(edges).astype(int), n_old - 1)
    xi = (edges - i - 0.5).reshape((-1,) + (1,) * (f.ndim - 1))
    before = np.concatenate([np.zeros_like(f[:1]), np.cumsum(f, axis=0)[:-1]], axis=0)
    C = before[i] + f[i] * (xi + 0.5) + s[i] * (xi * xi - 0.25) * 0.5
    return np.moveaxis(np.diff(C, axis=0) * (n_new / n_old), 0, axis)


def _physical(U: np.ndarray) -> bool:
    rho = U[0]
    if not np.all(np.isfinite(U)) or np.min(rho) <= 0.0:
        return False
    ke = 0.5 * (U[1] ** 2 + U[2] ** 2 + U[3] ** 2) / rho
    return bool(np.min(U[4] - ke) > 0.0)


def map_state(U: np.ndarray, old_cells: tuple[int, ...], old_lengths: tuple[float, ...],
              new_cells: tuple[int, ...], new_lengths: tuple[float, ...], kinds: tuple[str, ...]) -> tuple[np.ndarray, int]:
    """The conservative state ``U`` (5, *old_cells) mapped onto the new grid; returns (U_new, order used).

    Periodic axes are tiled by round(L_new/L_old) first; then every axis is remapped by
    :func:`remap_axis` (order 2, or order 1 if order 2 leaves the physical state space).
    """
    U = np.asarray(U, dtype=np.float64)
    if U.shape != (NVAR, *old_cells):
        raise InputError(f"field U of the earlier run has shape {U.shape}; its config says {(NVAR, *old_cells)}")
    for ax, (lo, ln) in enumerate(zip(old_lengths, new_lengths)):
        m = int(round(ln / lo))
        if kinds[ax] == PERIODIC and m > 1:
            U = np.tile(U, [m if b == 1 + ax else 1 for b in range(U.ndim)])
    for order in (2, 1):
        out = U
        for ax, n in enumerate(new_cells):
            out = _remap_state(out, 1 + ax, n, kinds[ax] == PERIODIC, order)
        if _physical(out):
            return out, order
    raise InputError("field initial.from_run: the earlier state is not physical (θ <= 0 or ρ <= 0 somewhere)")


def _remap_state(U: np.ndarray, axis: int, n_new: int, periodic: bool, order: int) -> np.ndarray:
    """One axis of :func:`map_state`: ρ, ρu and the internal energy ρe = E − k (minmod slopes) and the
    kinetic energy k = |ρu|²/2ρ (central slopes) remapped, E = ρe + k.

    Why not E itself: on refinement the resolved mean flow has more kinetic energy than the coarse
    cell's |ρu|²/2ρ; with E remapped directly the minmod slopes of the (nearly quadratic) k leave a
    grid-scale θ error of ±0.5 % in the dense Couette core (64 → 128 cells), with k remapped on
    central slopes (exact for a quadratic on 2× refinement) 0.06–0.3 %.  Both are conservative in E.
    """
    if U.shape[axis] == n_new:
        return U
    rho, m = U[0], U[1:4]
    k = 0.5 * np.sum(m * m, axis=0) / rho
    parts = [remap_axis(f, axis - 1, n_new, periodic, order) for f in (rho, *m, U[4] - k)]
    k_new = remap_axis(k, axis - 1, n_new, periodic, order, limiter="central")
    return np.stack([*parts[:4], parts[4] + k_new])


def totals(U: np.ndarray, lengths: tuple[float, ...]) -> np.ndarray:
    """∫ρ dV, ∫ρu dV, ∫E dV of a state on a box of the given lengths [SI]."""
    cell = math.prod(L / n for L, n in zip(lengths, U.shape[1:]))
    return np.asarray(U, dtype=np.float64).reshape(NVAR, -1).sum(axis=1) * cell
