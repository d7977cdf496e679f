"""The :class:`Case` every case module of this package subclasses and registers, found by ``case.kind``."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from ..boundaries import WALL
from ..flows import PROFILES, WALL_CASE_COLUMNS, add_base_flow, boundaries, wall_case_diagnostics
from ..grid import Grid
from ..kinematics import shear_rate
from ..physics import Physics

#: The registered cases by name (``case.kind``), in registration order.
CASES: dict[str, Case] = {}


def register(cls: type[Case]) -> type[Case]:
    """Class decorator: one instance of the case, under its ``name`` (a new case is one new module)."""
    CASES[cls.name] = cls()
    return cls


#: The registered case of a name (the config refuses any other name: :mod:`ktgf.solver.config`).
get_case = CASES.__getitem__


def kinds(test: Callable[[Case], bool], sep: str = " or ", fmt: Callable[[str], str] = repr) -> str:
    """The names of the registered cases that pass ``test``, as the config errors list them."""
    return sep.join(fmt(c.name) for c in CASES.values() if test(c))


class Case:
    """A flow case: what the numerics ask of it (the defaults fit a periodic box).

    ``hcs``: a freely cooling gas (HCS dissipation, Haff clock τ); ``boundary``: the boundary kind it
    needs on one axis; ``imposed_shear``: its boundaries impose γ̇; ``inclined``: it takes
    ``case.inclination_deg`` and ``initial.shear_rate``; ``columns``: its time-series columns;
    ``units``: those of its columns not in :data:`~ktgf.solver.flows.CASE_UNITS`; ``steady_monitors``:
    the columns whose change decides steadiness; ``panels``: what ``ktgf plot run`` draws against time,
    ((columns of one panel), y label) each; ``profiles``: it writes wall-normal profiles to plot.
    """

    name, label = "", ""  # case.kind, and as the progress bar shows it
    hcs = imposed_shear = inclined = False
    boundary: str | None = None
    columns: tuple[str, ...] = ()
    units: ClassVar[dict[str, str]] = {}
    steady_monitors: tuple[str, ...] = ()
    panels: tuple[tuple[tuple[str, ...], str], ...] = ((("theta_mean",), "θ"),)
    profiles = False

    @property
    def timeseries(self) -> str:
        """The time series' file name in the output folder."""
        return f"{self.name}.nc"

    def check(self, cfg: Any, source: str, shear: str | None, wall: str | None) -> None:
        """Its own config checks after the shared ones (``shear``, ``wall``: the Lees–Edwards and wall axes)."""

    def gravity(self, cfg: Any) -> tuple[float, float, float] | None:
        """Body force per unit mass [m/s²] (None: none)."""

    def boundaries(self, cfg: Any) -> Any:
        """The :class:`~ktgf.solver.boundaries.Boundaries` of the config."""
        return boundaries(cfg)

    def physics(self, phys: Physics, grid: Grid) -> Physics:
        """The physics of the case: its dissipation (HCS or steady shear) and shear-rate scale."""
        return dataclasses.replace(phys, hcs=self.hcs, shear_rate_scale=abs(float(shear_rate(grid))))

    def start(self, U: Any, cfg: Any, grid: Grid) -> Any:
        """The initial state: the perturbed uniform state U plus the case's base flow."""
        return add_base_flow(U, grid, cfg.initial.shear_rate)

    def diagnostics(self, U: Any, t: float, grid: Grid, phys: Physics) -> dict[str, Any]:
        """Its :attr:`columns` at one output."""
        return {}

    def steady_change(self, history: dict[str, list]) -> float | None:
        """Largest relative change of the steady monitors over the last output interval (None: no monitors or
        one output): u profiles relative to max|u| (u changes sign mid-gap), the others pointwise."""
        if not self.steady_monitors or len(history["time"]) < 2:
            return None
        change = 0.0
        for name in self.steady_monitors:
            new, old = (np.asarray(history[name][i], dtype=float) for i in (-1, -2))
            with np.errstate(divide="ignore", invalid="ignore"):
                rel = np.abs(new - old) / (np.max(np.abs(new)) if name == "u_profile" else np.abs(new))
            change = max(change, float(np.max(np.where(np.isfinite(rel), rel, np.inf))))
        return change

    def verification(self, history: dict[str, list], phys: Physics, grid: Grid, phi0: float) -> dict[str, Any] | None:
        """The comparison with its reference at the last output (``verification.json``; None: none)."""

    def about(self, phys: Physics, phi0: float) -> dict[str, Any]:
        return {"case": self.name, "model": phys.model.name, "solid_fraction": phi0, "restitution": float(phys.restitution)}

    def clock(self, t: float, tau: float | None = None, shear_rate: float = 0.0) -> str:
        """The progress bar's clock: ``t = … s``, with ``γ̇t = …`` (the strain) for an imposed γ̇ [1/s]."""
        text = f"t = {t:.4g} s"
        return f"{text}  γ̇t = {shear_rate * t:.3g}" if shear_rate else text


class WallCase(Case):
    """A case with walls on one axis: the wall stresses and slips and the wall-normal profiles as its columns,
    steady when the profiles stop changing, the profiles plotted (the Couette cell, the chute)."""

    boundary = WALL
    panels = ((("theta_mean",), "θ"), (("wall_shear_stress_lower", "wall_shear_stress_upper"), "wall shear stress"))
    profiles = True
    columns, steady_monitors = WALL_CASE_COLUMNS, PROFILES

    def diagnostics(self, U: Any, t: float, grid: Grid, phys: Physics) -> dict[str, Any]:
        return wall_case_diagnostics(U, t, grid, phys)

