"""Resumable sweeps of DEM states: one LAMMPS process per (state, seed), on any executor.

Every (state, seed) runs in its own folder and leaves ``result.json`` when it has finished, so a
sweep that was interrupted (Ctrl-C, a failed run, a lost worker) is resumed by running it again:
finished runs are read back, not rerun.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from itertools import groupby
from pathlib import Path
from typing import Any

from ..sweep import map_tasks
from .contact import calibrate_restitution
from .lammps import LammpsError, find_lammps
from .shear import ShearRun, ShearState, check_state, combine, run_shear


def _run_task(task: tuple[ShearRun, str]) -> dict:
    run, root = task
    return run_shear(run, Path(root))


def shear_sweep(phis: Sequence[float], e: float, *, mu: float = 0.0, particles: int = 864, seeds: int = 2,
                strain: float = 10.0, skip: float = 2.0, contact_fraction: float = 0.01, steps_per_contact: float = 50.0,
                run_dir: Path = Path("ktgf-dem-runs"), executor: Any = None,
                progress: Callable[[int, int], None] | None = None) -> list[ShearState]:
    """Run (or read back) every seed of every φ and return the states, in the order of ``phis``.

    All inputs are checked before the first run; a failed LAMMPS run raises :class:`LammpsError`
    (its last log lines) and leaves the finished runs in ``run_dir``.
    """
    from ..errors import InputError

    if seeds < 1:
        raise InputError(f"seeds = {seeds} is out of range: valid seeds >= 1")
    for phi in phis:
        check_state(float(phi), e, mu, particles, strain, skip, contact_fraction)
    lammps = find_lammps()
    runs = [ShearRun(float(phi), e, mu, particles, seed, strain, skip, contact_fraction, steps_per_contact)
            for phi in phis for seed in range(1, seeds + 1)]
    try:
        calibrate_restitution(e, steps_per_contact, lammps=lammps)  # once here; the workers read the cache
        results = map_tasks(_run_task, [(r, str(run_dir)) for r in runs], executor=executor, progress=progress)
    except LammpsError as exc:
        raise LammpsError(f"{exc} (finished runs are kept in {run_dir}: run the same command again to resume)") from None
    states = []
    for _, group in groupby(zip(runs, results), key=lambda rr: rr[0].key):
        pairs = list(group)
        states.append(combine([p[0] for p in pairs], [p[1] for p in pairs]))
    return states


def stiffness_change(base: ShearState, stiffer: ShearState) -> dict[str, tuple[float, float]]:
    """Relative change (stiffer/base − 1) of each observable when f_c is halved, and that change in combined standard errors."""
    out = {}
    for k in ("T", "p_star", "tau_over_p", "p_over_nT", "eta_over_eta0"):
        a, b = base.values[k], stiffer.values[k]
        da, db = base.errors[k], stiffer.errors[k]
        out[k] = (b / a - 1.0, (b - a) / (da**2 + db**2) ** 0.5)
    return out


def _cooling_task(task: tuple[Any, str]) -> dict:
    from .cooling import run_cooling

    run, root = task
    return run_cooling(run, Path(root))


def cooling_sweep(phis: Sequence[float], es: Sequence[float], *, particles: int = 6912, seeds: int = 2,
                  contact_fraction: float = 0.01, steps_per_contact: float = 50.0, run_dir: Path = Path("ktgf-dem-runs"),
                  executor: Any = None, progress: Callable[[int, int], None] | None = None) -> list[dict]:
    """Homogeneous-cooling rows for every (φ, e), resumable like :func:`shear_sweep`."""
    from ..errors import InputError
    from .cooling import CoolingRun, check_cooling, combine_cooling

    if seeds < 1:
        raise InputError(f"seeds = {seeds} is out of range: valid seeds >= 1")
    for phi in phis:
        for e in es:
            check_cooling(float(phi), float(e), particles, contact_fraction)
    lammps = find_lammps()
    runs = [CoolingRun(float(phi), float(e), particles, seed, contact_fraction, steps_per_contact)
            for phi in phis for e in es for seed in range(1, seeds + 1)]
    try:
        for e in es:
            calibrate_restitution(float(e), steps_per_contact, lammps=lammps)
        results = map_tasks(_cooling_task, [(r, str(run_dir)) for r in runs], executor=executor, progress=progress)
    except LammpsError as exc:
        raise LammpsError(f"{exc} (finished runs are kept in {run_dir}: run the same command again to resume)") from None
    rows = []
    for _, group in groupby(zip(runs, results), key=lambda rr: rr[0].key):
        pairs = list(group)
        rows.append(combine_cooling([p[0] for p in pairs], [p[1] for p in pairs]))
    return rows
