"""Which models' curves lie on top of each other: detected from the numbers, said on the page.

A reader of a figure where two models draw the same line sees one model and wonders where the
other went.  These helpers find, from the plotted values, the groups of models that coincide
(within a relative tolerance well below what a line width resolves) and phrase a caption sentence.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

#: Relative difference below which two curves are drawn on top of each other (a line width ≈ 1 % of an axis).
OVERLAP_RTOL = 0.01


def _label(name: str) -> str:
    from ..closures.models import get_model

    return get_model(name).label or name


def _close(a: Any, b: Any, rtol: float) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    both = np.isfinite(a) & np.isfinite(b)
    if not both.any():
        return False
    scale = np.maximum(np.abs(a[both]), np.abs(b[both]))
    return bool(np.all(np.abs(a[both] - b[both]) <= rtol * np.where(scale > 0, scale, 1.0)))


def overlap_groups(values: dict[str, Any], rtol: float = OVERLAP_RTOL) -> list[list[str]]:
    """Groups (of two or more, in the input order) of models whose values agree within ``rtol`` everywhere."""
    groups: list[list[str]] = []
    for name, v in values.items():
        for g in groups:
            if _close(values[g[0]], v, rtol):
                g.append(name)
                break
        else:
            groups.append([name])
    return [g for g in groups if len(g) > 1]


def _join(names: Sequence[str]) -> str:
    labels = [_label(n) for n in names]
    return labels[0] if len(labels) == 1 else ", ".join(labels[:-1]) + " and " + labels[-1]


def overlap_sentence(values: dict[str, Any], what: str, rtol: float = OVERLAP_RTOL) -> str:
    """' The curves of A and B overlap (their <what> differ by less than 1 %).' or '' when none do."""
    groups = overlap_groups(values, rtol)
    if not groups:
        return ""
    if len(groups) == 1 and len(groups[0]) == len(values):
        return f" All {len(values)} curves overlap: the models' {what} differ by less than {100 * rtol:g} %."
    parts = "; ".join(_join(g) for g in groups)
    return f" Overlapping curves (their {what} differ by less than {100 * rtol:g} %): {parts}."


def coincide_below(phi: Any, a: Any, b: Any, rtol: float = OVERLAP_RTOL) -> float | None:
    """The largest φ of the grid up to which curve ``b`` stays within ``rtol`` of ``a`` (from the first point).

    None if they differ already at the first point; the last φ if they never part.
    """
    phi, a, b = (np.asarray(x, dtype=float) for x in (phi, a, b))
    scale = np.maximum(np.abs(a), np.abs(b))
    off = np.abs(a - b) > rtol * np.where(scale > 0, scale, 1.0)
    if off[0]:
        return None
    return float(phi[np.argmax(off) - 1]) if off.any() else float(phi[-1])
