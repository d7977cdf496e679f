"""The junction of a piecewise closure at the freezing point φ_f: C⁰ (model.md §2) or C¹.

The piecewise RDFs (Torquato, viscosity divergence) and the Bocquet viscosity factor switch at
φ_f from a dilute branch f_lo to a dense branch f_hi.  Both branches meet with the same value at
φ_f, but not with the same slope (χ' jumps from 29.7 to 66.4 for the viscosity-divergence RDF):
μ*, g and C, which hold χ', then jump too, and Newton's method stalls when a node crosses φ_f.

``junction="c1"`` (the default) replaces the dense branch on the window [φ_f, φ_f + w] by the
quintic Hermite interpolant that matches value, slope and curvature of f_lo at φ_f and of f_hi
at φ_f + w, so value, slope and curvature are continuous everywhere (C², more than the C¹ the
name promises: the analytic slope then also agrees with finite differences across the window
ends, and Newton's Jacobian, which holds χ'', is continuous).  Below
φ_f the closure is unchanged (the model.md numbers at φ ≤ φ_f hold exactly), and above φ_f + w it
is the published dense branch.  ``junction="c0"`` keeps the plain switch of model.md §2.
The window width w (``junction_width``, default 0.01) is an option.
"""

from __future__ import annotations

from typing import Any

import numpy as np

JUNCTIONS: tuple[str, ...] = ("c1", "c0")
DEFAULT_WIDTH = 0.01


def hermite(x: Any, x0: float, x1: float, lo: tuple[Any, Any, Any], hi: tuple[Any, Any, Any]) -> tuple[Any, Any]:
    """Quintic Hermite interpolant on [x0, x1] with end (value, slope, curvature) ``lo`` and ``hi``.

    Returns (value, slope) at ``x``; t = (x − x0)/(x1 − x0), standard quintic Hermite basis.
    End values that are NumPy scalars are used as Python floats: JAX takes those as weakly typed, so a
    float32 evaluation stays float32 (a NumPy float64 would promote the whole bridge to float64).
    """
    lo, hi = (tuple(float(v) if isinstance(v, np.generic) else v for v in end) for end in (lo, hi))
    h = x1 - x0
    t = (x - x0) / h
    t2, t3, t4, t5 = t**2, t**3, t**4, t**5
    f0, s0, c0 = lo
    f1, s1, c1 = hi
    value = (
        (1 - 10 * t3 + 15 * t4 - 6 * t5) * f0
        + (t - 6 * t3 + 8 * t4 - 3 * t5) * h * s0
        + (0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5) * h**2 * c0
        + (10 * t3 - 15 * t4 + 6 * t5) * f1
        + (-4 * t3 + 7 * t4 - 3 * t5) * h * s1
        + (0.5 * t3 - t4 + 0.5 * t5) * h**2 * c1
    )
    slope = (
        (-30 * t2 + 60 * t3 - 30 * t4) * (f0 - f1) / h
        + (1 - 18 * t2 + 32 * t3 - 15 * t4) * s0
        + (t - 4.5 * t2 + 6 * t3 - 2.5 * t4) * h * c0
        + (-12 * t2 + 28 * t3 - 15 * t4) * s1
        + (1.5 * t2 - 4 * t3 + 2.5 * t4) * h * c1
    )
    return value, slope
