"""Runs that start from an earlier configuration: ``[initial] from_run = "earlier.toml"``.

A ``from_run`` that names a TOML run configuration (relative paths from the folder of the config that names
it) makes a chain: the earlier configuration is run first, into its own ``output.directory``, and this run
starts from its result (:mod:`.sequencing` maps it onto this grid).  An earlier stage whose folder already
holds a complete run of the same configuration is not run again; one that holds an interrupted run of it is
resumed; a folder holding anything else is refused as by any run (or cleared with ``overwrite``).  So
running the last configuration again after Ctrl-C continues the chain where it stopped, and the chain's
whole cost (steps, wall and CPU time of every stage) is in the last stage's ``verification.json``
(``run.sequence``).
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

import xarray as xr

from ..errors import InputError, KtgfError
from .config import Config, changed_fields, load_config
from .interrupt import Interrupted
from .io import load_checkpoint
from .run import CHECKPOINT, Simulation

log = logging.getLogger(__name__)


def earlier_config(path: str | Path, cfg: Config) -> Path | None:
    """The configuration file that ``cfg`` (read from ``path``) starts from, or None (no chain)."""
    source = cfg.initial.from_run
    if source is None or not source.endswith(".toml"):
        return None
    return Path(path).parent / source


def stage_config(path: str | Path, folder_of: Callable[[Path], Path] | None = None) -> Config:
    """The configuration in ``path`` with a ``from_run`` that names a configuration replaced by that stage's
    output folder: ``folder_of(earlier config)`` (:func:`run_chain` runs it there), by default its
    ``output.directory`` as configured (the chain already run)."""
    cfg = load_config(path)
    earlier = earlier_config(path, cfg)
    if earlier is None:
        return cfg
    if not earlier.is_file():
        raise InputError(f"field initial.from_run = {cfg.initial.from_run!r}: no run configuration "
                         f"{str(earlier)!r} (valid: a TOML file, relative to the folder of the config naming "
                         "it, or an earlier run's output folder or checkpoint)")
    folder = folder_of(earlier) if folder_of is not None else Path(load_config(earlier).output.directory)
    return cfg.model_copy(update={"initial": cfg.initial.model_copy(update={"from_run": str(folder)})})


def _stage_state(sim: Simulation) -> str:
    """``"complete"``, ``"interrupted"`` (its checkpoint is of the same configuration) or ``"new"``: what the
    output folder of an earlier stage holds of that stage's run."""
    ckpt = sim.directory / CHECKPOINT
    try:
        if changed_fields(json.loads(load_checkpoint(ckpt)["config"]), sim.cfg.model_dump(mode="json")):
            return "new"  # another run: Simulation.run refuses its folder (or clears it with overwrite)
    except (OSError, KtgfError, ValueError, KeyError):
        return "new"
    try:
        with xr.open_dataset(sim.timeseries) as ds:
            return "complete" if int(ds.attrs.get("run_complete", 0)) == 1 else "interrupted"
    except (OSError, ValueError):
        return "interrupted"


def run_chain(path: str | Path, output_dir: str | Path | None = None, resume: str | Path | None = None,
              progress: bool = True, overwrite: bool = False, after: tuple[Path, ...] = ()) -> tuple[Simulation, Any]:
    """Run the configuration in ``path`` after the chain of earlier configurations it starts from (module
    docstring); returns its :class:`~.run.Simulation` and the Dataset of :meth:`~.run.Simulation.run` (None for
    an earlier stage found complete).  ``output_dir``, ``resume`` and ``overwrite`` are those of
    :meth:`~.run.Simulation.run` for this last stage (``overwrite`` also clears an earlier stage's folder that
    holds another run).  Ctrl-C in an earlier stage raises :class:`~.interrupt.Interrupted` with no checkpoint
    to resume by hand: running the chain again continues that stage.  ``after``: the stages that start from
    this one, the last first (empty: this is the last stage)."""
    here, last = Path(path).resolve(), not after
    if here in after:
        raise InputError(f"field initial.from_run: the chain returns to {str(path)!r} (a stage cannot start from "
                         "itself or a later stage)")
    cfg = stage_config(path, lambda earlier: run_chain(earlier, progress=progress, overwrite=overwrite,
                                                         after=(*after, here))[0].directory)
    sim = Simulation(cfg, output_dir)
    state = "new" if last else _stage_state(sim)
    if not last:  # one line per earlier stage (INFO on the ktgf logger: the CLI shows it)
        log.info("chain: %s %s in %s", {"complete": "reusing the complete run of", "interrupted": "resuming",
                                           "new": "running"}[state], path, sim.directory)
    if state == "complete":
        return sim, None
    try:
        ds = sim.run(resume=sim.directory / CHECKPOINT if state == "interrupted" else resume, progress=progress,
                     overwrite=overwrite and state == "new")
    except Interrupted as exc:
        if last:
            raise
        raise Interrupted(f"{exc} (the chain's stage {str(path)!r}; running the chain again continues it)",
                          exit_code=exc.exit_code) from None
    return sim, ds
