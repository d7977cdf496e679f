"""Figure: reduced transport coefficients of several models against φ."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from ..closures.models import Model
from . import save

PANELS = (("p", "$p^*$"), ("eta", r"$\eta^*$"), ("kappa", r"$\kappa^*$"), ("mu", r"$\mu^*$"), ("zeta0", r"$\zeta_0^*$"))


def plot_reduced_coefficients(
    models: Sequence[Model], *, e: float, phi_max: float = 0.6, out: str | Path, n: int = 300
) -> Path:
    """Plot p*, η*, κ*, μ*, ζ0* and χ against φ for ``models`` at restitution ``e``; return the file path.

    Each model is drawn up to min(phi_max, 0.995 × its packing limit).
    """
    import matplotlib.pyplot as plt

    from .hcs import LINESTYLES, MODEL_COLOURS

    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5), constrained_layout=True)
    for i, m in enumerate(models):
        top = min(phi_max, 0.995 * m.phi_max)
        phi = np.linspace(1e-3, top, n)
        r = m.reduced(phi, e)
        # colour and dash per model: curves that coincide (below φ_f) stay visible under each other
        style = {"color": MODEL_COLOURS[i % len(MODEL_COLOURS)], "ls": LINESTYLES[i % len(LINESTYLES)], "label": m.label or m.name}
        for ax, (key, label) in zip(axes.flat, PANELS):
            ax.semilogy(phi, np.broadcast_to(getattr(r, key), phi.shape), **style)
            ax.set_ylabel(label)
        axes.flat[5].semilogy(phi, m.chi(phi), **style)
    axes.flat[5].set_ylabel(r"$\chi = g_0(\phi)$")
    # μ* = 0 for Lun-based models by default (no ∇φ heat flux): say so rather than leave a blank.
    zero_mu = [m.label or m.name for m in models if not np.any(np.asarray(m.reduced(0.3, e).mu))]
    if zero_mu:
        axes.flat[3].set_title(f"$\\mu^* = 0$: {', '.join(zero_mu)}", fontsize=9)
    for ax in axes.flat:
        ax.set_xlabel(r"solid fraction $\phi$")
        ax.grid(True, which="both", alpha=0.3)
    axes.flat[0].legend()
    fig.suptitle(f"Reduced transport coefficients, e = {e:g}")
    return save(fig, out)
