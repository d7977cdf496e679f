"""Figures of the homogeneous cooling state: cooling curves, stability maps and dispersion relations."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..closures.models import Model
from . import save
from .style import LINESTYLES, MODEL_COLOURS, colour, dash, panels, rc_style



def plot_haff(ds: Any, out: str | Path) -> Path:
    """θ(t)/θ0 of each model: Haff's law (line) and the integrated ODE (markers), log–log axes."""
    import matplotlib.pyplot as plt

    with plt.rc_context(rc_style()):
        fig, ax = plt.subplots(figsize=(4.2, 3.2), constrained_layout=True)
        t = ds["t"].values
        theta0 = ds["theta_haff"].values[:, 0]
        every = max(1, t.size // 20)
        reduced = ds["t"].attrs.get("units") == "1"  # d = θ0 = 1: time in units of d/√θ0
        t_unit = r"$d/\sqrt{\theta_0}$" if reduced else "s"
        for i, name in enumerate(ds["model"].values):
            c = MODEL_COLOURS[i % len(MODEL_COLOURS)]
            label = f"{ds['model_label'].values[i]} ($t_0$ = {float(ds['t0'].values[i]):.3g} {t_unit})"
            ax.loglog(t[1:], ds["theta_haff"].values[i, 1:] / theta0[i], LINESTYLES[i % len(LINESTYLES)], color=c, label=label)
            ax.loglog(t[1::every], ds["theta_numeric"].values[i, 1::every] / theta0[i], "o", color=c, ms=3, mfc="none")
        ax.set_xlabel(r"time $t\sqrt{\theta_0}/d$" if reduced else "time $t$ [s]")
        ax.set_ylabel(r"$\theta/\theta_0$")
        ax.plot([], [], "k-", label="Haff's law")
        ax.plot([], [], "ko", ms=3, mfc="none", label=r"$d\theta/dt=-\zeta_0(\theta)\theta$ (numerical)")
        ax.legend(frameon=False)
        ax.grid(True, which="both", alpha=0.25)
        ax.set_title(f"Homogeneous cooling, $\\phi$ = {_param(ds, 'phi')}, e = {_param(ds, 'e')}")
        return save(fig, out)


def _param(ds: Any, key: str) -> str:
    import json

    return f"{json.loads(ds.attrs['parameters'])[key]:g}"


def plot_stability_map(ds: Any, e_values: Sequence[float], out: str | Path) -> Path:
    """L⊥/d (solid) and L∥/d (dashed) against φ for every model in ``ds``, one panel per e (log y).

    ``ds`` is a :func:`ktgf.hcs.stability_map` Dataset; each requested e is taken at the nearest
    grid value (shown in the panel title).  Boxes below a curve stay homogeneous for that mode.
    """
    import matplotlib.pyplot as plt

    e_values = list(e_values)
    n = len(e_values)
    with plt.rc_context(rc_style()):
        fig, axes = plt.subplots(1, n, figsize=(3.4 * n, 3.0), sharey=True, constrained_layout=True, squeeze=False)
        phi = ds["phi"].values
        for ax, e in zip(axes[0], e_values):
            sel = ds.sel(e=e, method="nearest")
            for i, name in enumerate(ds["model"].values):
                c = MODEL_COLOURS[i % len(MODEL_COLOURS)]
                for var, ls in (("L_perp", "-"), ("L_par", "--")):
                    y = sel[var].values[i]
                    y = np.where(np.isfinite(y) & (y > 0), y, np.nan)  # L = 0 or inf cannot be drawn on log axes
                    ax.semilogy(phi, y, ls, color=c, lw=1.3, label=str(ds["model_label"].values[i]) if var == "L_perp" else None)
            ax.set_title(f"e = {float(sel['e']):.3g}")
            ax.set_xlabel(r"solid fraction $\phi$")
            ax.grid(True, which="both", alpha=0.25)
        axes[0, 0].set_ylabel("critical box side $L/d$")
        axes[0, 0].plot([], [], "k-", label=r"$L_\perp$ (vortices)")
        axes[0, 0].plot([], [], "k--", label=r"$L_\parallel$ (clusters)")
        axes[0, 0].legend(frameon=False)
        return save(fig, out)


def plot_dispersion(
    model: Model,
    phi: float,
    e: float,
    out: str | Path,
    *,
    k_max: float | None = None,
    box: float | None = None,
    n: int = 600,
) -> Path:
    """Growth rates s(k*) of the shear mode and the three longitudinal modes, unstable bands shaded.

    The bands where s⊥ > 0 (vortices) and max Re s∥ > 0 (clusters) are shaded from the computed
    curves; ``box`` (L/d) marks the lowest wavenumber of that periodic cube.
    """
    import matplotlib.pyplot as plt

    from ..hcs.dispersion import dispersion_relation
    from ..hcs.stability import box_wavenumber, critical_wavenumbers

    r = model.reduced(phi, e, hcs=True)
    kc = [float(k) for k in critical_wavenumbers(r) if np.isfinite(k) and k > 0]
    if k_max is None:
        k_max = 2.0 * max(kc) if kc else 1.0
    k = np.linspace(0.0, k_max, n)
    disp = dispersion_relation(r, k)
    with plt.rc_context(rc_style()):
        fig, ax = plt.subplots(figsize=(5.6, 3.3), constrained_layout=True)
        trans = ax.get_xaxis_transform()
        ax.fill_between(k, 0, 1, where=disp.transverse > 0, transform=trans, color="#0072B2", alpha=0.12, lw=0,
                        label="vortex band")
        ax.fill_between(k, 0, 1, where=disp.largest_longitudinal > 0, transform=trans, color="#D55E00", alpha=0.22,
                        lw=0, label="cluster band")
        ax.plot(k, disp.transverse, color="#0072B2", lw=1.5, label=r"$s_\perp$ (2 shear modes)")
        styles = ("-", "--", ":")
        for j in range(3):
            ax.plot(k, disp.longitudinal[:, j].real, styles[j], color="#D55E00", lw=1.2,
                    label=rf"Re $s_{{\parallel,{j + 1}}}$")
        ax.axhline(0.0, color="k", lw=0.6)
        if box is not None:
            kb = float(box_wavenumber(phi, box))
            ax.axvline(kb, color="0.3", lw=0.8, ls="-.", label=f"box L/d = {box:g}")
        ax.set_xlim(0.0, k_max)
        top = float(max(disp.transverse.max(), disp.largest_longitudinal.max()))
        if top > 0:  # the stable branches fall like -k*²; keep the unstable band readable
            ax.set_ylim(-2.0 * top, 1.4 * top)
        ax.set_xlabel(r"reduced wavenumber $k^* = k\ell$")
        ax.set_ylabel(r"growth rate $s/\nu_0$")
        ax.set_title(f"{model.label or model.name}: $\\phi$ = {phi:g}, e = {e:g}")
        ax.legend(frameon=False, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        ax.grid(True, alpha=0.25)
        return save(fig, out)


def plot_cooling_errors(ds: Any, out: str | Path) -> Path:
    """Relative error of each model's cooling rate against the DEM (early window), per e, against φ."""
    es = np.unique(ds.e.values)
    fig, axes = panels(1, len(es))
    for j, e in enumerate(es):
        ax = axes[0, j]
        sel = ds.e.values == e
        phi = ds.phi.values[sel]
        unc = 100 * ds.dem_rel_sem.values[sel]
        ax.fill_between(phi, -np.maximum(unc, 0.5), np.maximum(unc, 0.5), color="0.85", label="DEM ±0.5 % (or s.e.m.)")
        for i, m in enumerate(ds.model.values):
            ax.plot(phi, 100 * ds.error_early.values[i, sel], marker="o", ls=dash(i), color=colour(i),
                    label=str(ds.label[i].values))
        ax.axhline(0, color="k", lw=0.8)
        ax.set_title(f"e = {e:g}")
        ax.set_xlabel(r"solid fraction $\phi$")
        ax.set_ylabel(r"$A_\mathrm{model}/A_\mathrm{DEM} - 1$  [%]")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Cooling rate A = ζ/√T against DEM (fit over T0 → T0/2)")
    return save(fig, out)


def plot_dispersion_comparison(ds: Any, out: str | Path) -> Path:
    """Several models' growth rates of the transverse mode and real parts of the three longitudinal modes against k*."""
    fig, axes = panels(1, 2, w=5.6)
    k = ds.kstar.values
    colors = [colour(i) for i in range(ds.sizes["model"])]
    for i in range(ds.sizes["model"]):
        lab = str(ds.label[i].values)
        axes[0, 0].plot(k, ds.s_perp[i], color=colors[i], ls=dash(i), label=lab)
        axes[0, 0].plot([float(ds.k_perp[i])], [0.0], "o", color=colors[i])
        for b in range(ds.sizes["branch"]):
            axes[0, 1].plot(k, ds.s_par_real[i, :, b], color=colors[i], ls=dash(i), lw=1.2,
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
