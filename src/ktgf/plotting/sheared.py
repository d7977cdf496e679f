"""Time series of a sheared 3D-solver run (uniform shear, planar Couette, chute): ``ktgf plot run``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

#: Panels per case: (variables of the time series, y label); the units come from the file.
PANELS = {
    "uniform-shear": ((("theta_mean",), "θ"), (("pressure",), "p"), (("viscosity",), "η = −⟨P_fa⟩/γ̇")),
    "couette": ((("theta_mean",), "θ"), (("wall_shear_stress_lower", "wall_shear_stress_upper"), "wall shear stress")),
    "chute": ((("theta_mean",), "θ"), (("wall_shear_stress_lower", "wall_shear_stress_upper"), "wall shear stress")),
}
#: Wall-normal profiles drawn at the last output (Couette cell and chute).
PROFILES = (("u_profile", "u_f"), ("phi_profile", "φ"), ("theta_profile", "θ"))


def needs(case: str) -> tuple[str, ...]:
    """The variables :func:`plot_sheared_run` reads from the time series of ``case``."""
    cols = [name for names, _ in PANELS[case] for name in names]
    return ("time", *cols, *(name for name, _ in PROFILES if case != "uniform-shear"))


def _unit(da: Any) -> str:
    unit = da.attrs.get("units", "")
    return f" [{unit}]" if unit and unit != "1" else ""


def plot_sheared_run(ds: Any, out: str | Path) -> Path:
    """Plot a sheared run's history against the strain γ̇t (or t [s] when no shear rate is imposed).

    One panel per quantity of :data:`PANELS` (θ, the stresses the case measures) and, for the
    wall-bounded cases, the velocity, solid fraction and temperature across the gap at the last output.
    """
    import matplotlib.pyplot as plt

    from . import save

    case = str(ds.attrs["case"])
    rate = float(ds.attrs.get("shear_rate_per_s", 0.0))
    x, xlabel = (ds.time * rate, "strain γ̇t") if rate else (ds.time, "t [s]")
    panels = PANELS[case]
    profiles = case != "uniform-shear" and "normal" in ds.coords
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
