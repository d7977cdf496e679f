"""Couette figures: u/U, φ and √θ/U against the wall-normal coordinate in particle diameters."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import save
from .style import colour, dash


def plot_profiles(datasets: Mapping[str, Any], out: str | Path, *, dem: Any = None, title: str = "") -> Path:
    """One figure, three panels (u/U, φ, √θ/U vs y/d or r/d), one line per model; DEM points if given."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), sharey=True)
    for label, ds in datasets.items():
        coord = "y" if "y" in ds.coords else "r"
        params = ds.attrs
        d = _d(ds)
        U = float(params.get("velocity_scale", 1.0))
        x = ds[coord].values / d
        style = "--" if not int(params.get("physically_valid", 1)) else "-"
        tag = "" if int(params.get("physically_valid", 1)) else " (invalid: not physical)"
        axes[0].plot(ds["u"].values / U, x, style, label=f"{label}{tag}")
        axes[1].plot(ds["phi"].values, x, style)
        axes[2].plot(np.sqrt(ds["theta"].values) / U, x, style)
    if dem is not None:
        U = dem.case.wall_speed  # the DEM file's own case (header)
        kw = dict(marker="o", ls="none", mfc="none", color="k", ms=4, label="DEM")
        axes[0].plot(dem.u / U, dem.y, **kw)
        axes[1].plot(dem.phi, dem.y, **{**kw, "label": None})
        axes[2].plot(np.sqrt(dem.theta) / U, dem.y, **{**kw, "label": None})
    axes[0].set_ylabel(f"{coord} / d")
    for ax, lab in zip(axes, ("u / U", "φ", "√θ / U")):
        ax.set_xlabel(lab)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    if title:
        fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return save(fig, out)


def _d(ds: Any) -> float:
    import json

    return float(json.loads(ds.attrs["parameters"])["d"])


def plot_sweep(rows: list[dict[str, Any]], out: str | Path, *, quantity: str = "slip_over_U") -> Path:
    """A swept quantity against the specularity, one line per wall restitution."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4))
    ews = sorted({r["wall_restitution"] for r in rows})
    for ew in ews:
        sel = sorted((r for r in rows if r["wall_restitution"] == ew and r["converged"]), key=lambda r: r["specularity"])
        ax.semilogx([r["specularity"] for r in sel], [r[quantity] for r in sel], "o-", label=f"e_w = {ew:g}")
    ax.set_xlabel("specularity φ'")
    ax.set_ylabel(quantity)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return save(fig, out)


def plot_profile_comparison(ds: Any, out: str | Path) -> Path:
    """u/U, φ and θ/U² across the gap from one Dataset of several models, DEM points with error bars."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter


    U = float(ds["wall_speed"])
    scale = {"u": U, "phi": 1.0, "theta": U**2}
    labels = {"u": "velocity $u/U$", "phi": r"solid fraction $\phi$", "theta": r"temperature $\theta/U^2$ (log)"}
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.4), constrained_layout=True)
    for ax, var in zip(axes, ("u", "phi", "theta")):
        for i in range(ds.sizes["model"]):
            ax.plot(ds[var][i] / scale[var], ds.y, dash(i), color=colour(i),
                    label=str(ds.label[i].values))
        if f"{var}_dem" in ds:
            occupied = ds.phi_dem.values > 0.05  # bins inside the wall layers hold no flowing particles
            ax.errorbar(ds[f"{var}_dem"].values[occupied] / scale[var], ds.y_dem.values[occupied],
                        xerr=ds[f"{var}_dem_sem"].values[occupied] / scale[var], fmt="k.", ms=4, label="DEM")
        ax.set_xlabel(labels[var])
        ax.set_ylabel("y / d")
        ax.grid(True, which="both", alpha=0.3)
    ax = axes[2]
    ax.set_xscale("log")
    # θ spans about one decade: label 1-2-5 steps so that the axis shows several readable numbers
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    fmt = ScalarFormatter()
    fmt.set_scientific(False)
    ax.xaxis.set_major_formatter(fmt)
    ax.xaxis.set_minor_formatter(NullFormatter())
    axes[0].legend(fontsize=8)
    fig.suptitle(f"Planar Couette cell: profiles across the gap (walls at u/U = ±1/2, U = {U:g})")
    return save(fig, out)
