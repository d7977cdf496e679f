"""Maps of 3D-solver fields: line plots (1D), maps (2D) or the mid-plane z = L_z/2 (3D)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from . import save


def save_slices(path: str | Path, grid: Any, fields: dict[str, np.ndarray], title: str = "") -> Path:
    """PNG of scalar fields: line plots (1D), maps (2D) or the mid-plane z = L_z/2 (3D)."""
    import matplotlib.pyplot as plt

    n = len(fields)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n, 3.6), squeeze=False)
    for ax, (name, f) in zip(axes[0], fields.items()):
        f = np.asarray(f)
        if grid.ndim == 1:
            ax.plot(grid.centres(0) / grid.lengths[0], f)
            ax.set_xlabel("x / L")
        else:
            sl = f if grid.ndim == 2 else f[:, :, grid.cells[2] // 2]
            im = ax.imshow(sl.T, origin="lower", extent=(0, 1, 0, grid.lengths[1] / grid.lengths[0]), cmap="viridis")
            fig.colorbar(im, ax=ax, shrink=0.8)
            ax.set_xlabel("x / L")
            ax.set_ylabel("y / L")
        ax.set_title(name)
    if title:
        fig.suptitle(title)
    return save(fig, path)
