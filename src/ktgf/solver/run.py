"""Run an HCS case from a :class:`~ktgf.solver.config.Config`: outputs, checkpoints, progress, resume.

The host loop calls the compiled :func:`~ktgf.solver.stepping.advance` up to each output
time in chunks of ``time.max_steps_per_call`` steps.  The step sequence depends only on the
state and the next output time (a chunk boundary never shortens a step), so a run resumed
from any checkpoint reproduces the uninterrupted run bit for bit.

* Ctrl-C (KeyboardInterrupt) between chunks writes ``checkpoint.npz`` and re-raises.
* A step that leaves the physical state space is rejected; the last good state is written
  to ``checkpoint.npz`` and :class:`~ktgf.errors.DivergenceError` names the field, the cell,
  its position and the time.
"""

from __future__ import annotations

import dataclasses
import json
import time as _time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from ..closures import get_model
from ..closures.coefficients import mean_free_path
from ..errors import DivergenceError, InputError
from ..hcs.stability import BOX_CONSTANT, critical_wavenumbers
from .config import Config
from .diagnostics import PER_AXIS, SCALARS, diagnostics
from .grid import Grid
from .initial import haff_time, random_velocity, single_mode, t_of_tau, tau_of_t, uniform_fields
from .io import load_checkpoint, save_checkpoint, save_slices, write_vti
from .physics import Physics
from .state import PRIMITIVE_NAMES, conservative, primitive
from .stepping import LIMIT_NAMES, STATUS_MESSAGES, Numerics, advance, binding_limit, choose_scheme, limits, state_status, step

CHECKPOINT = "checkpoint.npz"
TIMESERIES = "hcs.nc"


def box_lengths(cfg: Config) -> tuple[float, ...]:
    """Box sides [m] from ``grid.length``, ``grid.length_d`` or ``relative_to``·``factor``."""
    g, d, ndim = cfg.grid, cfg.particles.diameter, len(cfg.grid.cells)

    def per_axis(v: Any, scale: float) -> tuple[float, ...]:
        vals = v if isinstance(v, list) else [v]
        vals = vals * ndim if len(vals) == 1 else vals
        return tuple(float(x) * scale for x in vals)

    if g.length is not None:
        return per_axis(g.length, 1.0)
    if g.length_d is not None:
        return per_axis(g.length_d, d)
    phi0 = cfg.initial.solid_fraction
    model = get_model(cfg.model.name, **cfg.model.options)
    kp, kl = critical_wavenumbers(model.reduced(phi0, cfg.model.restitution))
    k = float(kp if g.relative_to == "transverse" else kl)
    return per_axis(g.factor * BOX_CONSTANT / (phi0 * k), d)


class Simulation:
    """An HCS run described by a config (everything validated here, before any compilation)."""

    def __init__(self, cfg: Config, directory: str | Path | None = None) -> None:
        self.cfg = cfg
        self.model = get_model(cfg.model.name, **cfg.model.options)
        phi_stop = cfg.numerics.phi_stop if cfg.numerics.phi_stop is not None else 0.99 * self.model.phi_max
        self.phys = Physics(self.model, cfg.model.restitution, cfg.particles.diameter, cfg.particles.density, phi_stop)
        self.grid = Grid(tuple(cfg.grid.cells), box_lengths(cfg))
        n = cfg.numerics
        self.num = Numerics(n.cfl, n.cfl_diffusion, n.cfl_source, n.limiter, n.riemann, scheme="ssprk3",
                            implicit_tol=n.implicit_tol, implicit_maxiter=n.implicit_maxiter, sweeps=n.sweeps)
        self.dtype = jnp.float64 if n.precision == "float64" else jnp.float32
        self.directory = Path(directory if directory is not None else cfg.output.directory)
        self.phi0, self.theta0 = cfg.initial.solid_fraction, cfg.initial.temperature
        self.t_haff = haff_time(self.phys, self.phi0, self.theta0)
        end, n_out = cfg.time.end, cfg.time.outputs
        if cfg.time.unit == "tau":  # equal steps in τ: the natural clock of a cooling gas
            self.output_times = np.asarray(t_of_tau(np.linspace(0.0, end, n_out + 1), self.phys, self.phi0, self.theta0))
        else:
            t_end = end if cfg.time.unit == "s" else end * self.t_haff
            self.output_times = np.linspace(0.0, t_end, n_out + 1)
        self.output_times[0] = 0.0
        self.sharding = self._sharding(cfg.parallel.devices)
        scheme = cfg.time.scheme
        if scheme == "auto":  # from the config alone (the uniform initial state), so a resume agrees
            uniform = conservative(*uniform_fields(self.grid, self.phys, self.phi0, self.theta0))
            scheme = choose_scheme(uniform, self.grid, self.phys, self.num)
        self.num = dataclasses.replace(self.num, scheme=scheme)
        self.wall_stepping, self.steps_timed = 0.0, 0

    def _sharding(self, ndev: int) -> Any:
        if ndev == 1:
            return None
        devices = jax.devices()
        if len(devices) < ndev:
            raise InputError(
                f"field parallel.devices = {ndev}: only {len(devices)} JAX device(s) available "
                "(on CPU set XLA_FLAGS=--xla_force_host_platform_device_count=N before starting Python)"
            )
        if self.grid.cells[0] % ndev:
            raise InputError(f"field parallel.devices = {ndev} must divide grid.cells[0] = {self.grid.cells[0]}")
        mesh = jax.sharding.Mesh(np.array(devices[:ndev]), ("x",))
        spec = jax.sharding.PartitionSpec(None, "x", *([None] * (self.grid.ndim - 1)))
        return jax.sharding.NamedSharding(mesh, spec)

    # -- state -----------------------------------------------------------------------------
    def initial_state(self) -> Any:
        """The configured HCS initial state (conservative, on the configured devices)."""
        ini = self.cfg.initial
        if ini.perturbation == "random":
            U = random_velocity(self.grid, self.phys, self.phi0, self.theta0, ini.amplitude, ini.seed, ini.max_mode)
        elif ini.perturbation == "mode":
            U, _, _ = single_mode(
                self.grid, self.phys, self.phi0, self.theta0, tuple(ini.mode), ini.kind, ini.amplitude, ini.branch
            )
        else:
            U = conservative(*(jnp.asarray(f) for f in uniform_fields(self.grid, self.phys, self.phi0, self.theta0)))
        return self.place(U)

    def place(self, U: Any) -> Any:
        U = jnp.asarray(U, dtype=self.dtype)
        return jax.device_put(U, self.sharding) if self.sharding is not None else U

    def config_json(self) -> str:
        return json.dumps(self.cfg.model_dump(mode="json"), sort_keys=True)

    # -- run -------------------------------------------------------------------------------
    def run(
        self,
        resume: str | Path | None = None,
        progress: bool = True,
        on_chunk: Callable[[dict[str, Any]], None] | None = None,
        write_files: bool = True,
    ) -> Any:
        """Integrate to the end time; return the diagnostics as an xarray Dataset.

        ``on_chunk`` is called after every compiled chunk with the loop's counters (tests use
        it to simulate Ctrl-C).  ``resume`` is a checkpoint of the same config.
        """
        if resume is not None:
            ck = load_checkpoint(resume)
            if ck["config"] != self.config_json():
                raise InputError(f"checkpoint {str(resume)!r} was written by a different configuration")
            U, t, steps, k, history = self.place(ck["U"]), ck["t"], ck["steps"], ck["output_index"], ck["history"]
        else:
            U, t, steps, k = self.initial_state(), 0.0, 0, 0
            status = int(state_status(tuple(U), self.phys))
            if status:
                raise InputError(
                    f"initial state: {STATUS_MESSAGES[status]} (phi_stop = {self.phys.phi_stop:g}); "
                    "reduce initial.amplitude or raise numerics.phi_stop"
                )
            history = {name: [] for name in ("time", *SCALARS, *PER_AXIS)}
        self.history = history
        ckpt = self.directory / CHECKPOINT
        n_out = len(self.output_times)
        bar = _Progress(progress, self.output_times[-1], self.t_haff, self.phys, self.phi0, self.theta0)
        first_chunk = True
        try:
            with bar:
                while k < n_out:
                    target = float(self.output_times[k])
                    while t < target:
                        wall = _time.perf_counter()
                        U_new, t_new, n, status, dt = advance(
                            U, t, target, self.cfg.time.max_steps_per_call, self.grid, self.phys, self.num
                        )
                        n, status = int(n), int(status)
                        if status != 0:
                            U, t, steps = U_new, float(t_new), steps + n
                            self._fail(U, t, float(dt), steps, status, k, history, ckpt, write_files)
                        U, t, steps = U_new, float(t_new), steps + n
                        wall = _time.perf_counter() - wall
                        if not first_chunk:  # the first call includes the compilation
                            self.wall_stepping, self.steps_timed = self.wall_stepping + wall, self.steps_timed + n
                        first_chunk = False
                        bar.update(t, n, wall)
                        if on_chunk is not None:
                            on_chunk({"t": t, "steps": steps, "output_index": k})
                    self._record(U, t, history)
                    if write_files:
                        self._write_fields(U, t, k)
                        if k % self.cfg.output.checkpoint_every == 0 or k == n_out - 1:
                            save_checkpoint(ckpt, np.asarray(U), t, steps, k + 1, history, self.config_json())
                    k += 1
        except KeyboardInterrupt:
            if write_files:
                save_checkpoint(ckpt, np.asarray(U), t, steps, k, history, self.config_json())
            self.state, self.time, self.steps = U, t, steps
            raise
        self.state, self.time, self.steps = U, t, steps
        ds = self.dataset(history)
        if write_files:
            from ..io import write_netcdf

            write_netcdf(ds, self.directory / TIMESERIES)
        return ds

    def _record(self, U: Any, t: float, history: dict[str, list]) -> None:
        d = diagnostics(U, self.grid, self.phys.material_density)
        history["time"].append(t)
        for name in SCALARS:
            history[name].append(float(d[name]))
        for name in PER_AXIS:
            history[name].append([float(v) for v in np.asarray(d[name])])
        lim = np.asarray(limits(U, self.grid, self.phys, self.num))
        for name, v in zip(LIMIT_NAMES, lim):
            history.setdefault(f"dt_{name}", []).append(float(v))

    def _write_fields(self, U: Any, t: float, k: int) -> None:
        out = self.cfg.output
        last = k == len(self.output_times) - 1
        every = out.vtk_every
        if not (k == 0 or last or (every and k % every == 0)):
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
            save_checkpoint(ckpt, np.asarray(U), t, steps, k, history, self.config_json())
        bad, residual = step(U, dt, self.grid, self.phys, self.num) if dt > 0 else (U, 0.0)
        W = np.asarray(primitive(jnp.asarray(bad)))
        phi = W[0] / self.phys.material_density
        if status == 1:
            nonfinite = ~np.isfinite(W)
            var = int(np.argmax(nonfinite.reshape(5, -1).any(axis=1)))
            field, idx = PRIMITIVE_NAMES[var], np.unravel_index(np.argmax(nonfinite[var]), self.grid.cells)
            value = W[var][idx]
        elif status == 2:
            field, idx = "granular_temperature", np.unravel_index(np.argmin(W[4]), self.grid.cells)
            value = W[4][idx]
        elif status == 3:
            field, idx = "solid_fraction", np.unravel_index(np.argmax(phi), self.grid.cells)
            value = phi[idx]
        elif status == 4:
            field, idx = "density", np.unravel_index(np.argmin(W[0]), self.grid.cells)
            value = W[0][idx]
        elif status == 6:
            field, idx, value = "implicit_residual_over_tolerance", (), float(residual)
        else:
            field, idx, value = "time_step", (), dt
        where = tuple(int(i) for i in idx)
        pos = ", ".join(f"{(i + 0.5) * h:.4g}" for i, h in zip(where, self.grid.spacing))
        tau = float(tau_of_t(t, self.phys, self.phi0, self.theta0))
        saved = f"; last good state saved to {ckpt}" if write_files else ""
        err = DivergenceError(
            f"run stopped at t = {t:.6g} s (tau = {tau:.4g}, step {steps + 1}): {STATUS_MESSAGES[status]}: "
            f"{field} = {value:.6g} at cell {where} (x = ({pos}) m){saved}"
        )
        err.field, err.cell, err.time, err.status, err.value = field, where, t, status, float(value)
        raise err

    def dataset(self, history: dict[str, list]) -> Any:
        """Diagnostics history as an xarray Dataset with full run metadata (SI units)."""
        import xarray as xr

        from ..io import run_metadata

        t = np.asarray(history["time"], dtype=float)
        theta_haff = self.theta0 / (1.0 + t / self.t_haff) ** 2
        data = {name: ("time", np.asarray(history[name], dtype=float)) for name in SCALARS}
        data.update({name: (("time", "axis"), np.asarray(history[name], dtype=float).reshape(len(t), -1))
                     for name in PER_AXIS})
        data["theta_haff"] = ("time", theta_haff)
        limit_names = [n for n in LIMIT_NAMES if len(history.get(f"dt_{n}", [])) == len(t)]
        for name in limit_names:
            data[f"dt_{name}"] = ("time", np.asarray(history[f"dt_{name}"], dtype=float))
        data["tau"] = ("time", np.asarray(tau_of_t(t, self.phys, self.phi0, self.theta0), dtype=float))
        ds = xr.Dataset(data, coords={"time": t, "axis": list("xyz"[: self.grid.ndim])})
        units = {"time": "s", "theta_mean": "m2 s-2", "theta_haff": "m2 s-2", "theta_min": "m2 s-2",
                 "kinetic_energy": "m2 s-2", "ke_transverse": "m2 s-2", "ke_longitudinal": "m2 s-2",
                 "tau": "1", "density_variance": "1", "phi_max": "1", "mode_density": "1", "mode_velocity": "1"}
        units.update({f"dt_{name}": "s" for name in limit_names})
        for name, unit in units.items():
            ds[name].attrs["units"] = unit
        ds.attrs.update(run_metadata(
            self.model, config=self.cfg.model_dump(mode="json"), box_lengths_m=list(self.grid.lengths),
            haff_time_s=self.t_haff, mean_free_path_m=float(mean_free_path(self.phi0, self.phys.diameter)),
            steps=getattr(self, "steps", None),
        ))
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
    """rich progress bar over simulated time, showing t, τ and the step rate (no-op if disabled)."""

    def __init__(self, enabled: bool, t_end: float, t_haff: float, phys: Physics, phi0: float, theta0: float) -> None:
        self.enabled, self.t_end = enabled, t_end
        self.args = (phys, phi0, theta0)
        self._steps, self._wall, self._first = 0, 0.0, True

    def __enter__(self) -> _Progress:
        if self.enabled:
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

            self.bar = Progress(
                TextColumn("[bold]HCS"), BarColumn(), TextColumn("t = {task.fields[t]}  τ = {task.fields[tau]}"),
                TextColumn("{task.fields[rate]} steps/s"), TimeElapsedColumn(), TimeRemainingColumn(),
            )
            self.bar.__enter__()
            self.task = self.bar.add_task("run", total=self.t_end, t="0", tau="0", rate="-")
        return self

    def update(self, t: float, steps: int, wall: float) -> None:
        if not self.enabled:
            return
        if self._first:  # the first chunk includes compilation: keep it out of the step rate
            self._first = False
        else:
            self._steps += steps
            self._wall += wall
        rate = f"{self._steps / self._wall:.1f}" if self._wall > 0 else "-"
        tau = float(tau_of_t(t, *self.args))
        self.bar.update(self.task, completed=t, t=f"{t:.4g} s", tau=f"{tau:.3g}", rate=rate)

    def __exit__(self, *exc: object) -> None:
        if self.enabled:
            self.bar.__exit__(*exc)
