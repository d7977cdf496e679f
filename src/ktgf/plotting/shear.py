"""Figures of homogeneous shear: the closed-form curves of several models against DEM points."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from . import save
from .style import colour


def plot_shear_curves(ds: Any, dem: dict[str, np.ndarray] | None, out: str | Path) -> Path:
    """2 × 2 panels (T, η*, p*, p/(nT) against φ), one colour per model, line style per e, DEM points with error bars."""
    import matplotlib.pyplot as plt


    fig, axes = plt.subplots(2, 2, figsize=(11, 8), constrained_layout=True)
    styles = ("-", "--", ":")
    for ax, k in zip(axes.ravel(), ds.data_vars):
        for i in range(ds.sizes["model"]):
            for j, e in enumerate(ds.e.values):
                ax.plot(ds.phi, ds[k][i, j], styles[j % 3], color=colour(i),
                        label=f"{ds.label.values[i]}, e = {e:g}" if k == "T" else None)
        if dem is not None:
            for j, e in enumerate(ds.e.values):
                sel = dem["e"] == e
                if sel.any():
                    ax.errorbar(dem["phi"][sel], dem[k][sel], yerr=dem[f"d{k}"][sel], fmt="ko" if j == 0 else "ks", mfc="none",
                                ms=6, capsize=3, label=f"DEM, e = {e:g}" if k == "T" else None)
        ax.set_xlabel("solid fraction φ")
        ax.set_ylabel(ds[k].attrs["long_name"])
        ax.grid(True, alpha=0.3)
        if k != "T":
            ax.set_yscale("log")
    axes[0, 0].legend(fontsize=7, ncol=2)
    fig.suptitle("Uniform shear (Navier–Stokes closed forms) against frictionless DEM")
    return save(fig, out)


def plot_frictional_shear(ds: Any, rows: list[dict[str, float]] | None, out: str | Path, *, title: str) -> Path:
    """2 × 2 panels against φ, colour per model, line style per μ, DEM points (``rows``) with error bars."""
    import matplotlib.pyplot as plt


    fig, axes = plt.subplots(2, 2, figsize=(11, 8), constrained_layout=True)
    styles = ("--", "-")
    for ax, k in zip(axes.ravel(), ds.data_vars):
        for i in range(ds.sizes["model"]):
            for j, mu in enumerate(ds.mu.values):
                if ds.model.values[i] == "ret" and mu > 0:
                    continue  # frictionless RET does not depend on μ
                ax.plot(ds.phi, ds[k][i, j], styles[j % 2], color=colour(i),
                        label=f"{ds.label.values[i]}" + (f", μ = {mu:g}" if ds.model.values[i] != "ret" else "") if k == "T" else None)
        for r, mark in zip(rows or [], ("ks", "ko", "ko")):
            ax.errorbar([r["phi"]], [r[k]], yerr=[r["d" + k]], fmt=mark, mfc="none" if r["mu"] == 0 else "k", ms=6, capsize=3,
                        label=(f"DEM, μ = {r['mu']:g}" if k == "T" and (r["mu"] == 0 or r["phi"] == 0.4) else None))
        ax.set_xlabel("solid fraction φ")
        ax.set_ylabel(ds[k].attrs["long_name"])
        ax.grid(True, alpha=0.3)
        if k == "p_star":
            ax.set_yscale("log")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(title)
    return save(fig, out)
