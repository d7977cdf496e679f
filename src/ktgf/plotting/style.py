"""One palette for every figure: a model keeps its colour and dash across the report, the CLI and the docs."""

from __future__ import annotations

from typing import Any

import numpy as np

#: Same colour for a model in every figure (paper order: Enskog, RET, Visc.div., Proposed).
MODEL_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000")
#: Dash per model, so that models whose curves coincide remain visible on top of each other.
LINESTYLES = ("-", "--", "-.", ":")


def colour(i: int) -> str:
    """The colour of the i-th model of a figure."""
    return MODEL_COLOURS[i % len(MODEL_COLOURS)]


def dash(i: int) -> str:
    """The line style of the i-th model of a figure."""
    return LINESTYLES[i % len(LINESTYLES)]


def rc_style() -> dict[str, Any]:
    """Matplotlib settings of the compact single-panel figures."""
    return {"font.size": 9, "axes.labelsize": 9, "legend.fontsize": 8, "xtick.labelsize": 8, "ytick.labelsize": 8}


def panels(nrows: int, ncols: int, w: float = 4.6, h: float = 3.6) -> tuple[Any, np.ndarray]:
    """A figure of nrows × ncols panels of w × h inches each (axes always a 2D array)."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(nrows, ncols, figsize=(w * ncols, h * nrows), constrained_layout=True, squeeze=False)
    return fig, axes
