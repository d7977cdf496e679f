"""Figures of the 3D cooling-gas runs: time series against Haff's law and mid-plane slices."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from . import save


def plot_time_series(ds: Any, out: str | Path) -> Path:
    """θ/θ_Haff, mean-flow energy and density contrast against time, one line per run."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(14, 4), constrained_layout=True)
    for r in range(ds.sizes["run"]):
        lab = str(ds.run.values[r])
        axes[0].plot(ds.time, ds.theta_over_haff[r], label=lab)
        axes[1].semilogy(ds.time, ds.flow_energy[r], label=lab)
        axes[2].semilogy(ds.time, ds.phi_std[r], label=lab)
    for ax, t in zip(axes, (r"$\theta/\theta_\mathrm{Haff}$", "mean-flow / thermal energy", r"std($\phi$)/mean($\phi$)")):
        ax.set_xlabel(r"time $t\,\nu_0(\theta_0)$")
        ax.set_ylabel(t)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("3D cooling gas: departure from Haff's law, flow energy and density contrast")
    return save(fig, out)


def plot_slices(ds: Any, out: str | Path) -> Path:
    """Solid fraction and in-plane velocity in the mid-plane at the final time, one column per run."""
    import matplotlib.pyplot as plt

    n = ds.sizes["run"]
    fig, axes = plt.subplots(2, n, figsize=(3.6 * n, 7.6), constrained_layout=True, squeeze=False)
    for r in range(n):
        x, y = ds.x.values[r], ds.y.values[r]
        im = axes[0, r].pcolormesh(x, y, ds.phi_slice[r].T, shading="auto", cmap="viridis")
        fig.colorbar(im, ax=axes[0, r], label=r"$\phi$", shrink=0.8, location="bottom", pad=0.02)  # below: no overlap with the next panel
        speed = np.hypot(ds.ux_slice[r], ds.uy_slice[r]).T
        im = axes[1, r].pcolormesh(x, y, speed, shading="auto", cmap="magma")
        step = max(1, x.size // 16)
        axes[1, r].quiver(x[::step], y[::step], ds.ux_slice[r].T[::step, ::step], ds.uy_slice[r].T[::step, ::step], color="w")
        fig.colorbar(im, ax=axes[1, r], label="|u| in plane", shrink=0.8, location="bottom", pad=0.02)
        axes[0, r].set_title(str(ds.run.values[r]), fontsize=9)
        for ax in axes[:, r]:
            ax.set_aspect("equal")
            ax.set_xlabel("x / d")
            ax.set_ylabel("y / d")
    fig.suptitle("Mid-plane slices at the final time: solid fraction (top), in-plane velocity (bottom)")
    return save(fig, out)


def plot_cooling_run(ds: Any, out: str | Path) -> Path:
    """θ/θ_Haff and the mean-flow energies and density variance of one ``ktgf run`` cooling box against τ."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ax[0].plot(ds.tau, ds.theta_mean / ds.theta_haff)
    ax[0].set_xlabel("τ")
    ax[0].set_ylabel("θ / θ_Haff")
    for name, label in (("ke_transverse", "K⊥/θ"), ("ke_longitudinal", "K∥/θ"), ("density_variance", "var φ/φ²")):
        ax[1].semilogy(ds.tau, ds[name] / (ds.theta_mean if name.startswith("ke") else 1.0), label=label)
    ax[1].set_xlabel("τ")
    ax[1].legend()
    fig.suptitle(f"{ds.attrs.get('model_label', '')} HCS")
    return save(fig, out)
