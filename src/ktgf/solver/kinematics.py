"""The imposed shear of a case and the velocity gradients at the cells (read by the flows and the friction parts)."""

from __future__ import annotations

from typing import Any

import jax.numpy as jnp

from .fluxes import window
from .grid import Grid


def gradient_axis(grid: Grid) -> int | None:
    """The Lees–Edwards or wall axis (the direction of the velocity gradient), or None."""
    bc = grid.boundaries
    if bc is None:
        return None
    return bc.shear_axis if bc.shear_axis is not None else (bc.wall_axes[0] if bc.wall_axes else None)


def shear_rate(grid: Grid) -> float:
    """The imposed shear rate [1/s]: γ̇ of Lees–Edwards, U/L of the walls (0 for a periodic box)."""
    bc = grid.boundaries
    a = gradient_axis(grid)
    if a is None:
        return 0.0
    if bc.shear_axis is not None:
        return float(bc.shear_rate)
    lower, upper = bc.walls[a]
    return (upper.velocity[bc.flow] - lower.velocity[bc.flow]) / grid.lengths[a]


def velocity_gradients(Pu: tuple, grid: Grid) -> list[list[Any]]:
    """∂u_j/∂x_b at the cells (central differences of padded u; 0 along missing axes), rows b, columns j."""
    zero = jnp.zeros(grid.cells, Pu[0].dtype)
    return [[(window(Pu[j], grid.cells, b, 1, 0) - window(Pu[j], grid.cells, b, -1, 0)) * (0.5 / grid.spacing[b])
             if b < grid.ndim else zero for j in range(3)] for b in range(3)]
