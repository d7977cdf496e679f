"""Time series of a sheared 3D-solver run (uniform shear, planar Couette, chute): ``ktgf plot run``."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

#: Wall-normal profiles drawn at the last output (cases that write them: ``Case.profiles``).
PROFILES = (("u_profile", "u_f"), ("phi_profile", "φ"), ("theta_profile", "θ"))


def needs(panels: Sequence[tuple[Sequence[str], str]], profiles: bool) -> tuple[str, ...]:
    """The variables :func:`plot_sheared_run` reads from a time series with these panels (and profiles)."""
    return ("time", *(name for names, _ in panels for name in names), *(name for name, _ in PROFILES if profiles))


def _unit(da: Any) -> str:
    unit = da.attrs.get("units", "")
    return f" [{unit}]" if unit and unit != "1" else ""


def plot_sheared_run(ds: Any, out: str | Path, panels: Sequence[tuple[Sequence[str], str]], profiles: bool) -> Path:
    """Plot a sheared run's history against the strain γ̇t (or t [s] when no shear rate is imposed).

    One panel per entry of ``panels`` ((variables, y label): θ, the stresses the case measures; the run's case
    declares them, :attr:`ktgf.solver.cases.Case.panels`) and, with ``profiles``, the velocity, solid fraction
    and temperature across the gap at the last output.
    """
    import matplotlib.pyplot as plt

    from . import save

    case = str(ds.attrs["case"])
    rate = float(ds.attrs.get("shear_rate_per_s", 0.0))
    x, xlabel = (ds.time * rate, "strain γ̇t") if rate else (ds.time, "t [s]")
    profiles = profiles and "normal" in ds.coords
    n = len(panels) + (len(PROFILES) if profiles else 0)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n, 3.4))
    for ax, (names, label) in zip(axes, panels):
        for name in names:
            ax.plot(x, ds[name], label=name.replace("wall_shear_stress_", ""))
        ax.set_xlabel(xlabel)
        ax.set_ylabel(label + _unit(ds[names[0]]))
        if len(names) > 1:
            ax.legend()
    if profiles:
        for ax, (name, label) in zip(axes[len(panels):], PROFILES):
            ax.plot(ds[name].isel(time=-1), ds.normal)
            ax.set_xlabel(f"{label}{_unit(ds[name])} at t = {float(ds.time[-1]):.3g} s")
            ax.set_ylabel(f"wall-normal position{_unit(ds.normal)}")
    fig.suptitle(f"{ds.attrs.get('model_label', '')} {case}")
    fig.tight_layout()
    return save(fig, out)
