"""Multi-model figures of the report's HCS section (single-model HCS figures are in :mod:`ktgf.plotting.hcs`)."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..plotting import save
from ..plotting.hcs import LINESTYLES, MODEL_COLOURS


def _fig(nrows: int, ncols: int, w: float = 4.6, h: float = 3.6) -> tuple[Any, np.ndarray]:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(nrows, ncols, figsize=(w * ncols, h * nrows), constrained_layout=True, squeeze=False)
    return fig, axes


def plot_cooling_errors(ds: xr.Dataset, out: Any) -> Any:
    """Relative error of each model's cooling rate against the DEM (early window), per e, against φ."""
    es = np.unique(ds.e.values)
    fig, axes = _fig(1, len(es))
    for j, e in enumerate(es):
        ax = axes[0, j]
        sel = ds.e.values == e
        phi = ds.phi.values[sel]
        unc = 100 * ds.dem_rel_sem.values[sel]
        ax.fill_between(phi, -np.maximum(unc, 0.5), np.maximum(unc, 0.5), color="0.85", label="DEM ±0.5 % (or s.e.m.)")
        for i, m in enumerate(ds.model.values):
            ax.plot(phi, 100 * ds.error_early.values[i, sel], marker="o", ls=LINESTYLES[i % 4], color=MODEL_COLOURS[i % len(MODEL_COLOURS)],
                    label=str(ds.label[i].values))
        ax.axhline(0, color="k", lw=0.8)
        ax.set_title(f"e = {e:g}")
        ax.set_xlabel(r"solid fraction $\phi$")
        ax.set_ylabel(r"$A_\mathrm{model}/A_\mathrm{DEM} - 1$  [%]")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Cooling rate A = ζ/√T against DEM (fit over T0 → T0/2)")
    return save(fig, out)


def plot_dispersion(ds: xr.Dataset, out: Any) -> Any:
    """Growth rates of the transverse mode and real parts of the three longitudinal modes against k*."""
    fig, axes = _fig(1, 2, w=5.6)
    k = ds.kstar.values
    colors = [MODEL_COLOURS[i % len(MODEL_COLOURS)] for i in range(ds.sizes["model"])]
    for i in range(ds.sizes["model"]):
        lab = str(ds.label[i].values)
        axes[0, 0].plot(k, ds.s_perp[i], color=colors[i], ls=LINESTYLES[i % 4], label=lab)
        axes[0, 0].plot([float(ds.k_perp[i])], [0.0], "o", color=colors[i])
        for b in range(ds.sizes["branch"]):
            axes[0, 1].plot(k, ds.s_par_real[i, :, b], color=colors[i], ls=LINESTYLES[i % 4], lw=1.2,
                            label=lab if b == 0 else None)
        axes[0, 1].plot([float(ds.k_par[i])], [0.0], "o", color=colors[i])
    for ax, title in zip(axes[0], ("transverse (vortex) mode  s⊥", "longitudinal modes  Re s")):
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xlabel(r"$k^* = k\ell$")
        ax.set_ylabel(r"growth rate / $\nu_0$")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
    axes[0, 1].set_ylim(bottom=max(float(np.nanmin(ds.s_par_real)), -3.0 * float(np.nanmax(np.abs(ds.s_perp)))))
    axes[0, 0].legend()
    fig.suptitle(f"HCS dispersion relations at φ = {float(ds.phi):g}, e = {float(ds.e):g} (dots: closed-form k⊥*, k∥*)")
    return save(fig, out)


