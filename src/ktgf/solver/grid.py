"""Uniform Cartesian grids in 1, 2 or 3 dimensions (the dimension is data), with their boundaries.

A :class:`Grid` is a JAX pytree: the cell counts are static (they fix array shapes), the
box lengths are traced leaves, so boxes of different size share one compiled kernel.  The
boundary kind of every axis (:class:`~ktgf.solver.boundaries.Boundaries`; default periodic)
travels with the grid, so every stencil that pads fields sees it.  Cell ``i`` along axis ``a`` covers ``[i Δx_a, (i+1) Δx_a)``; its centre is
``(i + 1/2) Δx_a``.  Fields are stored as arrays of shape ``grid.cells`` (one axis per
spatial dimension); the velocity always has three components (a 1D or 2D grid is a
3D flow that does not vary along the missing axes), so transverse modes exist in 1D.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import jax
import numpy as np

from ..errors import InputError

#: Fewer cells than this along an axis cannot hold the 5-point stencil of the scheme.
MIN_CELLS = 4


@jax.tree_util.register_pytree_node_class
@dataclass(frozen=True)
class Grid:
    """Box of ``cells[a]`` cells of width ``lengths[a]/cells[a]`` along axis ``a``.

    Parameters
    ----------
    cells : tuple of int
        Number of cells per axis (1 to 3 entries).
    lengths : tuple of float
        Box side per axis [m].
    boundaries : Boundaries or None
        Boundary kind per axis (None: periodic on every axis).
    """

    cells: tuple[int, ...]
    lengths: tuple[float, ...]
    boundaries: Any = None

    def __post_init__(self) -> None:
        cells = tuple(int(n) for n in self.cells)
        lengths = tuple(float(v) for v in self.lengths)
        object.__setattr__(self, "cells", cells)
        object.__setattr__(self, "lengths", lengths)
        if not 1 <= len(cells) <= 3:
            raise InputError(f"grid cells has {len(cells)} entries: valid 1, 2 or 3 (the dimension)")
        if len(lengths) != len(cells):
            raise InputError(f"grid lengths has {len(lengths)} entries but cells has {len(cells)}: give one per axis")
        for a, n in enumerate(cells):
            if n < MIN_CELLS:
                raise InputError(f"grid cells[{a}] = {n} is out of range: valid cells >= {MIN_CELLS} (stencil width)")
        for a, v in enumerate(lengths):
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"grid lengths[{a}] = {v:g} is out of range: valid 0 < length (m)")
        if self.boundaries is not None and len(self.boundaries.kinds) != len(cells):
            raise InputError(f"grid boundaries has {len(self.boundaries.kinds)} axes but cells has {len(cells)}")

    def tree_flatten(self) -> tuple[tuple, tuple[int, ...]]:
        return (self.lengths, self.boundaries), self.cells

    @classmethod
    def tree_unflatten(cls, cells: tuple[int, ...], children: tuple) -> Grid:
        obj = object.__new__(cls)  # no validation: leaves may be tracers
        for name, v in zip(("cells", "lengths", "boundaries"), (cells, tuple(children[0]), children[1])):
            object.__setattr__(obj, name, v)
        return obj

    @property
    def ndim(self) -> int:
        """Number of spatial dimensions (1, 2 or 3)."""
        return len(self.cells)

    @property
    def spacing(self) -> tuple[float, ...]:
        """Cell widths Δx_a [m]."""
        return tuple(L / n for L, n in zip(self.lengths, self.cells))

    @property
    def size(self) -> int:
        """Total number of cells."""
        return int(np.prod(self.cells))

    def centres(self, axis: int) -> np.ndarray:
        """Cell-centre coordinates along one axis [m]."""
        return (np.arange(self.cells[axis]) + 0.5) * self.spacing[axis]

    def mesh(self) -> list[np.ndarray]:
        """Cell-centre coordinate arrays of shape ``cells`` (``indexing="ij"``)."""
        return np.meshgrid(*(self.centres(a) for a in range(self.ndim)), indexing="ij")

    def wavevector(self, mode: tuple[int, ...]) -> np.ndarray:
        """Wavevector k = 2π n_a/L_a (3 components, zero along missing axes) of integer mode ``n``."""
        k = np.zeros(3)
        k[:len(mode)] = [2.0 * math.pi * n / L for n, L in zip(mode, self.lengths)]
        return k


def periodic(grid: Any) -> bool:
    """Whether every axis of ``grid`` (a :class:`Grid` or a grid-like namespace) is periodic."""
    return grid.boundaries is None or grid.boundaries.all_periodic
