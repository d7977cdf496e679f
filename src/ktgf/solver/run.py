"""Run a case (:mod:`.cases`) from a :class:`~ktgf.solver.config.Config`:
outputs, checkpoints, progress, resume.

The host loop calls the compiled :func:`~ktgf.solver.stepping.advance` up to each output
time in chunks of ``time.max_steps_per_call`` steps.  The step sequence depends only on the
state and the next output time (a chunk boundary never shortens a step), so a run resumed
from any checkpoint reproduces the uninterrupted run bit for bit.

Ctrl-C / SIGTERM (:mod:`.interrupt`), the locked output folder (:mod:`.outdir`) and a rejected step
(:class:`~ktgf.errors.DivergenceError`, the last good state in ``checkpoint.npz``): docs/solver.md, "Running".
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import json
import math
import os
import time as _time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from ..closures import get_model
from ..closures.coefficients import mean_free_path
from ..errors import DivergenceError, InputError, KtgfError
from ..io import atomic_path, run_metadata, write_netcdf
from .config import Config, box_lengths, changed_fields, config_value, initial_temperature
from .diagnostics import PER_AXIS, SCALARS, diagnostics
from .cases import get_case
from .flows import CASE_UNITS, PROFILES, VERIFICATION_FILE, describe
from .grid import Grid
from .kinematics import gradient_axis, shear_rate
from .initial import haff_time, perturb, random_velocity, shear_mode, single_mode, t_of_tau, tau_of_t, uniform_fields
from .interrupt import STOP, Interrupted, fault_hook
from ..plotting.fields import save_slices
from .io import CHECKPOINT, load_checkpoint, save_checkpoint, write_vti
from .outdir import RunLock, run_files
from .physics import Physics
from .sequencing import mean_temperature, start_from_run
from .state import PRIMITIVE_NAMES, conservative, primitive
from .stepping import LIMIT_NAMES, STATUS_MESSAGES, Numerics, advance, binding_limit, choose_scheme, limits, state_status, step

HISTORY_KEYS = ("time", *SCALARS, *PER_AXIS, *(f"dt_{n}" for n in LIMIT_NAMES))
#: Config fields that may differ between a checkpoint and the run resuming it: where and how
#: often files are written, the chunk size (the step sequence does not depend on it) and the
#: end time / output count (outputs after the last one recorded follow the new schedule).
RESUMABLE_CHANGES = ("output.directory", "output.checkpoint_every", "output.vtk_every", "output.vtk",
                     "output.png", "time.max_steps_per_call", "time.end", "time.outputs")


#: Peak memory of a run ≈ MEMORY_FACTOR × the state (5 fields); measured as the peak RSS of one
#: compiled chunk at 32³, 64³ and 96³ (float64, CPU): +578 MB for +32.5 MB of state, i.e. 18×.
MEMORY_FACTOR = 20


def _bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n < 1000:
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"


def check_memory(cells: tuple[int, ...], precision: str, available: int | None = None) -> int:
    """Estimate the memory of a run and refuse (:class:`InputError`) one that exceeds the machine's."""
    itemsize = 8 if precision == "float64" else 4
    state = 5 * math.prod(cells) * itemsize
    need = MEMORY_FACTOR * state
    have = available
    if have is None:  # the physical memory of this machine, where the system says it
        with contextlib.suppress(ValueError, OSError, AttributeError):
            have = int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    if have is not None and need > have:
        raise InputError(f"field grid.cells = {list(cells)} needs about {_bytes(need)} of memory ({MEMORY_FACTOR} x "
                         f"the {_bytes(state)} state in {precision}); this machine has {_bytes(have)}: use fewer cells"
                         + (" or numerics.precision = 'float32'" if precision == "float64" else ""))
    return need


def _x64(enabled: bool) -> Any:
    """Context in which JAX uses 64-bit types (``jax.enable_x64``; older JAX: ``jax.experimental``)."""
    ctx = getattr(jax, "enable_x64", None)
    if ctx is None or not callable(ctx):  # pragma: no cover - JAX < 0.5
        from jax.experimental import enable_x64 as ctx
    return ctx(enabled)


def _in_precision(method: Callable[..., Any]) -> Callable[..., Any]:
    """Run a :class:`Simulation` method in the precision of its config (not the process-wide setting)."""

    @functools.wraps(method)
    def wrapper(self: Simulation, *args: Any, **kwargs: Any) -> Any:
        with self.precision():
            return method(self, *args, **kwargs)

    return wrapper


class Simulation:
    """A run of any case described by a config (everything validated here, before any compilation)."""

    def precision(self) -> Any:
        """Context manager of the run: JAX's x64 mode on inside it only (the state's dtype follows numerics.precision:
        the clock t, dt is float64 even when the state is float32, as the step loop of :func:`advance` expects)."""
        return _x64(True)

    @_in_precision  # the Haff time and output times are computed with JAX too
    def __init__(self, cfg: Config, directory: str | Path | None = None) -> None:
        self.cfg = cfg
        check_memory(tuple(cfg.grid.cells), cfg.numerics.precision)
        self.model = get_model(cfg.model.name, **cfg.model.options)
        phi_stop = cfg.numerics.phi_stop if cfg.numerics.phi_stop is not None else 0.99 * self.model.phi_max
        self.case = get_case(cfg.case.kind)
        self.phys = Physics(self.model, cfg.model.restitution, cfg.particles.diameter, cfg.particles.density, phi_stop,
                            self.case.gravity(cfg))
        bc = self.case.boundaries(cfg)
        self.grid = Grid(tuple(cfg.grid.cells), box_lengths(cfg), None if bc.all_periodic else bc)
        self.phys = self.case.physics(self.phys, self.grid)  # the case's dissipation and shear-rate scale
        self.history_keys = (*HISTORY_KEYS, *self.case.columns)
        n = cfg.numerics
        self.num = Numerics(n.cfl, n.cfl_diffusion, n.cfl_source, n.limiter, n.riemann, scheme="ssprk3",
                            implicit_tol=n.implicit_tol, implicit_maxiter=n.implicit_maxiter, sweeps=n.sweeps,
                            mixed=n.precision == "mixed")
        self.dtype = jnp.float64 if n.precision == "float64" else jnp.float32
        self.directory = Path(directory if directory is not None else cfg.output.directory)
        self.timeseries = self.directory / self.case.timeseries
        self.started_from = None  # with initial.from_run: the earlier run's state mapped onto this grid
        if cfg.initial.from_run is not None:
            self.mapped, self.started_from = start_from_run(cfg, self.grid.cells, self.grid.lengths)
        self.phi0 = cfg.initial.solid_fraction
        self.theta0 = initial_temperature(cfg) if self.started_from is None else mean_temperature(self.mapped)
        self.t_haff = haff_time(self.phys, self.phi0, self.theta0)
        end, n_out = cfg.time.end, cfg.time.outputs
        if cfg.time.unit == "tau":  # equal steps in τ: the natural clock of a cooling gas
            with np.errstate(over="ignore"):  # an overflow (end too far along Haff's law) is refused below
                self.output_times = np.asarray(t_of_tau(np.linspace(0.0, end, n_out + 1), self.phys, self.phi0,
                                                        self.theta0))
        else:
            unit = cfg.time.unit
            t_end = end / shear_rate(self.grid) if unit == "strain" else end * (self.t_haff if unit == "haff" else 1.0)
            self.output_times = np.linspace(0.0, t_end, n_out + 1)
        self.output_times[0] = 0.0
        t = self.output_times
        if not (np.isfinite(t).all() and np.all(np.diff(t) > 0)):
            limit = float(tau_of_t(1e300, self.phys, self.phi0, self.theta0)) if cfg.time.unit == "tau" else (
                1e300 / self.t_haff if cfg.time.unit == "haff" else 1e300)
            raise InputError(f"field time.end = {end:g} ({cfg.time.unit}) gives output times that overflow or coincide "
                             f"(t_end = {t[-1]:g} s): valid time.end <= {limit:.4g} {cfg.time.unit} and enough room "
                             f"for time.outputs = {n_out} distinct outputs")
        self.sharding = self._sharding(cfg.parallel.devices)
        scheme = "imex" if "implicit" in (n.acoustics, n.sink) else cfg.time.scheme  # IMEX options
        if scheme == "auto":  # from the config alone (the uniform initial state), so a resume agrees
            uniform = conservative(*uniform_fields(self.grid, self.phys, self.phi0, self.theta0))
            scheme = choose_scheme(uniform, self.grid, self.phys, self.num)
        self.num = dataclasses.replace(self.num, scheme=scheme, acoustics=n.acoustics, sink=n.sink)
        self.wall_stepping, self.steps_timed = 0.0, 0

    def _sharding(self, ndev: int) -> Any:
        if ndev == 1:
            return None
        devices = jax.devices()
        if len(devices) < ndev:
            raise InputError(f"field parallel.devices = {ndev}: only {len(devices)} JAX device(s) available "
                             "(on CPU set XLA_FLAGS=--xla_force_host_platform_device_count=N before starting Python)")
        if self.grid.cells[0] % ndev:
            raise InputError(f"field parallel.devices = {ndev} must divide grid.cells[0] = {self.grid.cells[0]}")
        mesh = jax.sharding.Mesh(np.array(devices[:ndev]), ("x",))
        spec = jax.sharding.PartitionSpec(None, "x", *([None] * (self.grid.ndim - 1)))
        return jax.sharding.NamedSharding(mesh, spec)

    @_in_precision
    def initial_state(self) -> Any:
        """The configured initial state (conservative, on the configured devices)."""
        ini = self.cfg.initial
        if self.started_from is not None:  # the base flow is in the earlier state
            U = self.mapped
            if ini.perturbation == "random":
                U = perturb(U, self.grid, ini.amplitude, ini.seed, ini.max_mode)
            return self.place(U)
        if ini.perturbation == "random":
            U = random_velocity(self.grid, self.phys, self.phi0, self.theta0, ini.amplitude, ini.seed, ini.max_mode)
        elif ini.perturbation == "mode":
            U = single_mode(self.grid, self.phys, self.phi0, self.theta0, tuple(ini.mode), ini.kind, ini.amplitude,
                            ini.branch)[0]
        elif ini.perturbation == "shear-mode":  # about the steady state: θ of the closed form, not θ0
            U, _ = shear_mode(self.grid, self.phys, self.phi0, tuple(ini.mode), ini.amplitude, ini.branch)
        else:
            U = conservative(*(jnp.asarray(f) for f in uniform_fields(self.grid, self.phys, self.phi0, self.theta0)))
        return self.place(self.case.start(U, self.cfg, self.grid))

    @_in_precision
    def place(self, U: Any) -> Any:
        U = jnp.asarray(U, dtype=self.dtype)
        return jax.device_put(U, self.sharding) if self.sharding is not None else U

    def config_json(self) -> str:
        return json.dumps(self.cfg.model_dump(mode="json"), sort_keys=True)

    @_in_precision
    def run(self, resume: str | Path | None = None, progress: bool = True,
            on_chunk: Callable[[dict[str, Any]], None] | None = None, write_files: bool = True,
            overwrite: bool = False) -> Any:
        """Integrate to the end time; return the diagnostics as an xarray Dataset.

        ``on_chunk`` is called after every compiled chunk with the loop's counters (tests use
        it to simulate Ctrl-C).  ``resume`` is a checkpoint of the same config (harmless
        changes allowed: see :data:`RESUMABLE_CHANGES`).  With ``write_files`` the output folder
        is locked for the run; a fresh run refuses a folder holding another run's files unless
        ``overwrite`` (which deletes them).  SIGINT/SIGTERM: see the module docstring.
        """
        if resume is not None and overwrite:
            raise InputError("--resume and --overwrite exclude each other: resume continues the run, overwrite deletes it")
        with STOP:
            if STOP.requested:
                raise Interrupted("interrupted before the run started; nothing written", exit_code=STOP.exit_code)
            with RunLock(self.directory) if write_files else contextlib.nullcontext():
                return self._run(resume, progress, on_chunk, write_files, overwrite)

    def _run(self, resume: str | Path | None, progress: bool, on_chunk: Callable[[dict[str, Any]], None] | None,
             write_files: bool, overwrite: bool) -> Any:
        n_out = len(self.output_times)
        started = (_time.perf_counter(), _time.process_time())
        if resume is not None:
            U, t, steps, k, history = self._resume_from(resume)
        else:
            if write_files:
                self._claim_folder(overwrite)
            U, t, steps, k = self.initial_state(), 0.0, 0, 0
            if status := int(state_status(tuple(U), self.phys)):
                raise InputError(f"initial state: {STATUS_MESSAGES[status]} (phi_stop = {self.phys.phi_stop:g}); "
                                 "reduce initial.amplitude or raise numerics.phi_stop")
            history = {name: [] for name in self.history_keys}
        self.history = history
        ckpt = self.directory / CHECKPOINT
        bar = _Progress(progress, self.output_times[-1], self.phys, self.phi0, self.theta0,
                        case=self.case.name, shear_rate=shear_rate(self.grid))
        chunks = 0
        try:
            with bar:
                while k < n_out:
                    target = float(self.output_times[k])
                    while t < target:
                        self._poll()
                        if chunks == 0:
                            fault_hook("compile")
                        wall = _time.perf_counter()
                        U_new, t_new, n, status, dt = advance(U, t, target, self.cfg.time.max_steps_per_call,
                                                              self.grid, self.phys, self.num)
                        n, status = int(n), int(status)
                        U, t, steps = U_new, float(t_new), steps + n
                        if status != 0:
                            self._fail(U, t, float(dt), steps, status, k, history, ckpt, write_files)
                        chunks += 1
                        wall = _time.perf_counter() - wall
                        if chunks > 1:  # the first call includes the compilation
                            self.wall_stepping, self.steps_timed = self.wall_stepping + wall, self.steps_timed + n
                        bar.update(t, n, wall)
                        if on_chunk is not None:
                            on_chunk({"t": t, "steps": steps, "output_index": k})
                        fault_hook("chunk", chunks)
                    self._poll()
                    self._record(U, t, history)
                    if self.steady_summary(history)["reached"]:  # the last output: its files are written
                        self.output_times = self.output_times[:k + 1]
                        n_out = k + 1
                    if write_files:
                        fault_hook("output", k)
                        self._write_fields(U, t, k)
                        if k % self.cfg.output.checkpoint_every == 0 or k == n_out - 1:
                            self._save(ckpt, U, t, steps, k + 1, history)
                            fault_hook("checkpoint", k)
                    k += 1
                self._poll()
        except KeyboardInterrupt as exc:
            # Whatever was under way, (U, t, steps, k) and the first k rows of the history form a
            # consistent state: output k has not been recorded yet, or is recorded again on resume
            # (its files are rewritten identically).
            self.state, self.time, self.steps = U, t, steps
            if not write_files:
                raise
            self._save(ckpt, U, t, steps, k, history)
            done = "the run is complete" if k >= n_out else f"{k} of {n_out} outputs written"
            raise Interrupted(
                f"interrupted at t = {t:.6g} s after {steps} steps ({done}); checkpoint written to {ckpt}",
                checkpoint=ckpt, exit_code=STOP.exit_code if STOP.requested else 130,
            ) from (None if isinstance(exc, Interrupted) else exc)
        self.state, self.time, self.steps = U, t, steps
        ds = self.dataset(history)
        self.verification = self.case.verification(history, self.phys, self.grid, self.phi0)
        if self.verification is not None:
            self.verification["steady"] = self.steady_summary(history)
            self.verification["run"] = {**self.run_summary(history), "precision": self.cfg.numerics.precision,
                                        "cells": list(self.grid.cells),
                                        "wall_time_s": _time.perf_counter() - started[0],
                                        "cpu_time_s": _time.process_time() - started[1],
                                        "load_average": list(os.getloadavg())}
            if self.started_from is not None:  # the cost of the whole sequence, this stage included
                self.verification["started_from"] = self.started_from
                run = self.verification["run"]
                before = self.started_from["earlier_run"].get("sequence")
                if before is not None:
                    run["sequence"] = {k: (before.get(k) or 0) + run[v] for k, v in
                                       (("steps", "step_count"), ("wall_time_s", "wall_time_s"),
                                        ("cpu_time_s", "cpu_time_s"))}
        if write_files:
            ds.attrs["run_complete"] = 1
            write_netcdf(ds, self.timeseries)
            if self.verification is not None:
                with atomic_path(self.directory / VERIFICATION_FILE) as tmp:
                    tmp.write_text(json.dumps(self.verification, indent=2) + "\n")
        return ds

    def steady_summary(self, history: dict[str, list]) -> dict[str, Any]:
        """The steady-state stop: tolerance, whether it was met, the last change and the time [s]."""
        tol = self.cfg.time.steady_tol
        change = self.case.steady_change(history)
        return {"steady_tol": tol, "reached": bool(tol is not None and change is not None and change < tol),
                "last_change": change, "time_s": history["time"][-1] if history["time"] else None,
                "strain": (history["time"][-1] * shear_rate(self.grid)
                           if history["time"] and shear_rate(self.grid) else None)}

    @staticmethod
    def _poll() -> None:
        if STOP.requested:
            raise Interrupted("interrupted")

    def _save(self, ckpt: Path, U: Any, t: float, steps: int, k: int, history: dict[str, list]) -> None:
        """Checkpoint and time series of the first ``k`` outputs (the time series first: a resume
        rewrites it from the checkpoint, so a kill between the two writes loses nothing)."""
        rows = {name: list(v[:k]) for name, v in history.items()}
        if k > 0:
            ds = self.dataset(rows, steps=steps)
            ds.attrs["run_complete"] = 0
            write_netcdf(ds, self.timeseries)
        save_checkpoint(ckpt, np.asarray(U), t, steps, k, rows, self.config_json())

    def _claim_folder(self, overwrite: bool) -> None:
        """Refuse to start afresh over another run's files (or delete them with ``overwrite``)."""
        files = run_files(self.directory)
        if overwrite or not files:
            for p in files:
                p.unlink(missing_ok=True)
            return
        where = repr(str(self.directory))
        ckpt = self.directory / CHECKPOINT
        state = ""
        if ckpt.is_file():
            try:
                ck = load_checkpoint(ckpt)
                total = int(json.loads(ck["config"])["time"]["outputs"]) + 1
                if ck["output_index"] < total:
                    state = f"an unfinished run (t = {ck['t']:.6g} s, {ck['output_index']} of {total} outputs)"
            except (KtgfError, ValueError, KeyError, TypeError):
                state = "an unfinished run (its checkpoint is unreadable)"
        if state:
            raise InputError(f"output folder {where} holds {state}: continue it with --resume {ckpt}, "
                             "or start again with --overwrite (deletes its files)")
        raise InputError(f"output folder {where} already holds the files of a run ({len(files)} files, e.g. "
                         f"{files[0].name}): use --overwrite to replace them or choose another --output-dir")

    def _resume_from(self, resume: str | Path) -> tuple:
        """Load a checkpoint and check that it fits this run; return (U, t, steps, k, history)."""
        ck = load_checkpoint(resume)
        name = f"checkpoint {str(resume)!r}"
        try:
            old = json.loads(ck["config"])
        except ValueError:
            raise InputError(f"{name}: field config is not JSON") from None
        new = self.cfg.model_dump(mode="json")
        if changed := [f for f in changed_fields(old, new) if f not in RESUMABLE_CHANGES]:
            f = changed[0]
            raise InputError(f"{name} was written by a different configuration: field {f} = {config_value(old, f)!r} "
                             f"in the checkpoint, {config_value(new, f)!r} now (on resume only "
                             f"{', '.join(RESUMABLE_CHANGES)} may change)")
        U, t, steps, k, history = ck["U"], ck["t"], ck["steps"], ck["output_index"], ck["history"]
        shape = (5, *self.grid.cells)
        if U.shape != shape:
            raise InputError(f"{name}: field U has shape {U.shape}; this run needs {shape}")
        if U.dtype != np.dtype(self.dtype):
            raise InputError(f"{name}: field U has dtype {U.dtype}; this run needs {np.dtype(self.dtype)}")
        if not np.isfinite(U).all():
            raise InputError(f"{name}: field U holds NaN or infinite values")
        t_end = float(self.output_times[-1])
        if not (math.isfinite(t) and 0.0 <= t <= t_end):
            raise InputError(f"{name}: field t = {t:g} s is out of range: valid 0 <= t <= {t_end:g} s (the end time)")
        if steps < 0 or (steps == 0 and t > 0):
            raise InputError(f"{name}: field steps = {steps} does not fit t = {t:g} s")
        n_out = len(self.output_times)
        if not 0 <= k <= n_out:
            raise InputError(f"{name}: field output_index = {k} is out of range: valid 0 <= output_index <= {n_out}")
        keys = self.history_keys
        if sorted(history) != sorted(keys):
            raise InputError(f"{name}: field history has the columns {sorted(history)}; expected {sorted(keys)}")
        if bad := [c for c in keys if len(history[c]) != k]:
            raise InputError(f"{name}: field history.{bad[0]} has {len(history[bad[0]])} rows; output_index = {k}")
        try:
            rows = {c: np.asarray(history[c], dtype=float) for c in keys}
        except (TypeError, ValueError):
            raise InputError(f"{name}: field history holds non-numbers") from None
        times = rows["time"]
        if k and (np.any(np.diff(times) <= 0) or times[-1] > t or times[0] != 0.0):
            raise InputError(f"{name}: field history.time is not increasing from 0 to at most t = {t:g} s")
        if {"time.end", "time.outputs"} & set(changed_fields(old, new)):
            # another output schedule: continue with its outputs after the last one recorded
            after = self.output_times[(self.output_times >= t) & (self.output_times > (times[-1] if k else -1.0))]
            k = n_out - len(after)
        elif k and not np.array_equal(times, self.output_times[:k]):
            raise InputError(f"{name}: field history.time does not match the output times of the config")
        elif k < n_out and not ((k == 0 or self.output_times[k - 1] <= t) and t <= self.output_times[k]):
            raise InputError(f"{name}: field t = {t:.9g} s does not lie between output {k - 1} and output {k}")
        elif k == n_out and t != t_end:
            raise InputError(f"{name}: field output_index = {k} (all outputs written) but t = {t:g} s < end time")
        return self.place(U), t, steps, k, history

    def _record(self, U: Any, t: float, history: dict[str, list]) -> None:
        # mixed precision: the diagnostic sums in float64 (the state stays float32)
        d = diagnostics(U.astype(jnp.float64) if self.num.mixed else U, self.grid, self.phys.material_density)
        history["time"].append(t)
        for name in SCALARS:
            history[name].append(float(d[name]))
        for name in PER_AXIS:
            history[name].append([float(v) for v in np.asarray(d[name])])
        for name, v in zip(LIMIT_NAMES, np.asarray(limits(U, self.grid, self.phys, self.num))):
            history.setdefault(f"dt_{name}", []).append(float(v))
        for name, v in self.case.diagnostics(U, t, self.grid, self.phys).items():
            history[name].append(v)

    def _write_fields(self, U: Any, t: float, k: int) -> None:
        out = self.cfg.output
        if not (k == 0 or k == len(self.output_times) - 1 or (out.vtk_every and k % out.vtk_every == 0)):
            return
        W = np.asarray(primitive(U))
        phi = W[0] / self.phys.material_density
        if out.vtk:
            write_vti(self.directory / f"fields_{k:05d}.vti", self.grid,
                      {"solid_fraction": phi, "velocity": W[1:4], "granular_temperature": W[4]}, time=t)
        if out.png:
            speed = np.sqrt(np.sum(W[1:4] ** 2, axis=0))
            save_slices(self.directory / f"slice_{k:05d}.png", self.grid,
                        {"phi": phi, "theta / <theta>": W[4] / W[4].mean(), "|u| [m/s]": speed},
                        title=f"{self.model.label or self.model.name}, t = {t:.4g} s")

    def _fail(self, U: Any, t: float, dt: float, steps: int, status: int, k: int,
              history: dict[str, list], ckpt: Path, write_files: bool) -> None:
        """Save the last good state, reproduce the rejected step and raise a located diagnosis."""
        if write_files:
            self._save(ckpt, U, t, steps, k, history)
        bad, residual = step(U, dt, self.grid, self.phys, self.num, t) if dt > 0 else (U, 0.0)
        W = np.asarray(primitive(jnp.asarray(bad)))
        phi = W[0] / self.phys.material_density
        if status == 1:
            nonfinite = ~np.isfinite(W)
            var = int(np.argmax(nonfinite.reshape(5, -1).any(axis=1)))
            field, idx = PRIMITIVE_NAMES[var], np.unravel_index(np.argmax(nonfinite[var]), self.grid.cells)
            value = W[var][idx]
        elif status in (2, 3, 4):  # the cell of the extreme value
            field, f, pick = {2: ("granular_temperature", W[4], np.argmin), 3: ("solid_fraction", phi, np.argmax),
                              4: ("density", W[0], np.argmin)}[status]
            idx = np.unravel_index(pick(f), self.grid.cells)
            value = f[idx]
        elif status == 6:
            field, idx, value = "implicit_residual_over_tolerance", (), float(residual)
        else:
            field, idx, value = "time_step", (), dt
        where = tuple(int(i) for i in idx)
        pos = ", ".join(f"{(i + 0.5) * h:.4g}" for i, h in zip(where, self.grid.spacing))
        tau = float(tau_of_t(t, self.phys, self.phi0, self.theta0)) if self.case.hcs else float("nan")
        saved = f"; last good state saved to {ckpt}" if write_files else ""
        stopped = f"run stopped at t = {t:.6g} s (tau = {tau:.4g}, step {steps + 1}): {STATUS_MESSAGES[status]}"
        err = DivergenceError(f"{stopped}: {field} = {value:.6g} at cell {where} (x = ({pos}) m){saved}")
        err.field, err.cell, err.time, err.status, err.value = field, where, t, status, float(value)
        raise err

    def dataset(self, history: dict[str, list], steps: int | None = None) -> Any:
        """Diagnostics history as an xarray Dataset with full run metadata (SI units)."""
        import xarray as xr

        t = np.asarray(history["time"], dtype=float)
        data = {name: ("time", np.asarray(history[name], dtype=float)) for name in SCALARS}
        data.update({name: (("time", "axis"), np.asarray(history[name], dtype=float).reshape(len(t), -1))
                     for name in PER_AXIS})
        cooling = self.case.hcs
        if cooling:
            data["theta_haff"] = ("time", self.theta0 / (1.0 + t / self.t_haff) ** 2)
        coords = {"time": t, "axis": list("xyz"[: self.grid.ndim])}
        for name in self.case.columns:
            values = np.asarray(history[name], dtype=float)
            if name in PROFILES:  # profiles across the gap, one row per output
                a = gradient_axis(self.grid)
                data[name] = (("time", "normal"), values.reshape(len(t), self.grid.cells[a]))
                coords["normal"] = ("normal", self.grid.centres(a), {"units": "m", "long_name":
                                    f"cell centres along the wall-normal axis {'xyz'[a]}"})
            else:
                data[name] = ("time", values)
        limit_names = [n for n in LIMIT_NAMES if len(history.get(f"dt_{n}", [])) == len(t)]
        data.update({f"dt_{n}": ("time", np.asarray(history[f"dt_{n}"], dtype=float)) for n in limit_names})
        if cooling:
            data["tau"] = ("time", np.asarray(tau_of_t(t, self.phys, self.phi0, self.theta0), dtype=float))
        ds = xr.Dataset(data, coords=coords)
        units = {"time": "s", "theta_mean": "m2 s-2", "theta_haff": "m2 s-2", "theta_min": "m2 s-2",
                 "kinetic_energy": "m2 s-2", "ke_transverse": "m2 s-2", "ke_longitudinal": "m2 s-2",
                 "tau": "1", "density_variance": "1", "phi_max": "1", "mode_density": "1", "mode_velocity": "1"}
        units.update({f"dt_{name}": "s" for name in limit_names})
        units.update({**CASE_UNITS, **self.case.units})
        for name, unit in units.items():
            if name in ds:
                ds[name].attrs["units"] = unit
        ds.attrs.update(run_metadata(
            self.model, config=self.cfg.model_dump(mode="json"), box_lengths_m=list(self.grid.lengths),
            haff_time_s=self.t_haff, mean_free_path_m=float(mean_free_path(self.phi0, self.phys.diameter)),
            steps=steps if steps is not None else getattr(self, "steps", None),
        ))
        if self.started_from is not None:
            ds.attrs["from_run"] = f"{self.started_from['from_run']} ({self.started_from['cells']} cells, mapped)"
        if not cooling:
            ds.attrs.update({"case": self.case.name, "boundaries": describe(self.grid),
                             "shear_rate_per_s": shear_rate(self.grid)})
        ds.attrs.update(self.run_summary(history))
        return ds

    def run_summary(self, history: dict[str, list]) -> dict[str, Any]:
        """Time scheme, step count, the step limit that bound most outputs, stepping wall time per step."""
        binding = [binding_limit([history[f"dt_{n}"][i] for n in LIMIT_NAMES], self.num.scheme)
                   for i in range(len(history.get("dt_cfl", [])))]
        return {
            "time_scheme": self.num.scheme,
            "step_count": int(getattr(self, "steps", 0) or 0),
            "binding_step_limit": max(set(binding), key=binding.count) if binding else "",
            "wall_time_per_step_s": self.wall_stepping / self.steps_timed if self.steps_timed else float("nan"),
        }


class _Progress:
    """rich progress bar over simulated time, showing the case, its clock (:meth:`~.cases.Case.clock`), the step
    rate and the time left (no-op if disabled).

    The time left is extrapolated in τ = ∫ν dt (the collision count), not in t: a cooling gas takes
    about the same number of steps, hence wall time, per unit of τ, while its time step grows with t.
    The first chunk is left out of every rate, because it includes the compilation.
    """

    def __init__(self, enabled: bool, t_end: float, phys: Physics, phi0: float, theta0: float,
                 clock: Callable[[], float] = _time.perf_counter, case: str = "cooling", shear_rate: float = 0.0) -> None:
        self.enabled, self.t_end, self.clock = enabled, t_end, clock
        self.case, self.shear_rate = get_case(case), shear_rate
        # A sheared case has no Haff clock; its steps are about equally long in t.
        self._tau = (lambda t: float(tau_of_t(t, phys, phi0, theta0))) if self.case.hcs else float
        self.tau_end = self._tau(t_end)
        self._steps, self._wall = 0, 0.0
        self._start: tuple[float, float] | None = None  # (τ, clock) at the end of the first chunk
        self.remaining: float | None = None  # seconds, once two chunks have run

    def __enter__(self) -> _Progress:
        if self.enabled:
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

            self.bar = Progress(TextColumn(f"[bold]{self.case.label}"), BarColumn(), TextColumn("{task.fields[clock]}"),
                                TextColumn("{task.fields[rate]} steps/s"), TimeElapsedColumn(),
                                TextColumn("left {task.fields[eta]}"))
            self.bar.__enter__()
            self.task = self.bar.add_task("run", total=self.t_end, clock=self.clock_text(0.0), rate="-", eta="-")
        return self

    def update(self, t: float, steps: int, wall: float) -> None:
        tau = self._tau(t)
        now = self.clock()
        if self._start is None:  # the first chunk includes compilation: keep it out of the step rate and the ETA
            self._start = (tau, now)
        else:
            self._steps += steps
            self._wall += wall
            tau0, c0 = self._start
            if tau > tau0 and now > c0:
                self.remaining = max(self.tau_end - tau, 0.0) * (now - c0) / (tau - tau0)
        if not self.enabled:
            return
        rate = f"{self._steps / self._wall:.1f}" if self._wall > 0 else "-"
        s = round(self.remaining or 0.0)
        eta = "-" if self.remaining is None else f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"
        self.bar.update(self.task, completed=t, clock=self.clock_text(t), rate=rate, eta=eta)

    def clock_text(self, t: float) -> str:
        """The simulated time as the case counts it (:meth:`~.cases.Case.clock`)."""
        return self.case.clock(t, self._tau(t), self.shear_rate)

    def __exit__(self, *exc: object) -> None:
        if self.enabled:
            self.bar.__exit__(*exc)
