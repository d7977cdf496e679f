"""Boundary conditions of the finite-volume solver as data: one kind per grid axis.

Every stencil of :mod:`.fluxes` and :mod:`.imex` reads fields padded with :data:`~.fluxes.GHOST`
ghost cells per side; the boundaries only decide what the ghost cells hold (:func:`pad`).

``periodic``
    The ghost cells are the cells at the other end of the axis (the cooling box; the code path
    is the one of :func:`~.fluxes.pad_periodic`, so periodic runs are unchanged bit for bit).
``lees-edwards``
    Shearing-periodic images (Lees & Edwards 1972, *J. Phys. C* 5, 1921): along the gradient
    axis a (length L_a) the image boxes above and below move with velocity ±γ̇L_a along the
    flow direction f and are displaced by ±Δ(t), Δ = γ̇L_a t mod L_f.  A ghost cell above the
    box at position x_f holds the state of the cell it images,

        W(x_f, L_a + s) = W(x_f − Δ, s) + γ̇L_a e_f      (below: W(x_f + Δ, L_a − s) − γ̇L_a e_f)

    with the velocity jump on the flow component only (ρ, θ and the closures are unchanged).
    Δ is not a whole number of cells: the image is interpolated linearly between the two
    cells it straddles (second order, like the reconstruction).  If the flow direction is not
    a grid axis (a 1D grid along the gradient, or a 2D grid x–y with flow along z) there is no
    displacement to make and only the jump remains.  Uniform shear u_f = γ̇(x_a − L_a/2) is then
    an exact steady solution of the discrete momentum balance (a linear profile continues
    across the boundary).

The velocity jump is the affine part of the boundary: an operator linear in the velocity
(the implicit viscous operator of the IMEX stage solves) is applied with ``affine=False``
and the jump goes into its right-hand side (:func:`~.imex.implicit_stage`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import jax
import jax.numpy as jnp

PERIODIC = "periodic"
LEES_EDWARDS = "lees-edwards"
KINDS = (PERIODIC, LEES_EDWARDS)
AXES = "xyz"


@jax.tree_util.register_pytree_node_class
@dataclass(frozen=True)
class Boundaries:
    """Boundary kind of every grid axis, and the Lees–Edwards shear if there is one.

    A JAX pytree: the kinds and the flow component are static, the shear rate a traced leaf.

    Parameters
    ----------
    kinds : tuple of str
        One of :data:`KINDS` per grid axis.
    shear_rate : float
        Lees–Edwards shear rate γ̇ [1/s] (du_f/dx_a of the images).
    flow : int
        Velocity component of the Lees–Edwards flow direction (0, 1, 2 = x, y, z; not the gradient axis).
    """

    kinds: tuple[str, ...]
    shear_rate: float = 0.0
    flow: int = 0

    def __post_init__(self) -> None:
        from ..errors import InputError

        kinds = tuple(self.kinds)
        object.__setattr__(self, "kinds", kinds)
        for a, k in enumerate(kinds):
            if k not in KINDS:
                raise InputError(f"boundary kind {k!r} on axis {AXES[a]} is unknown; valid: {', '.join(KINDS)}")
        if kinds.count(LEES_EDWARDS) > 1:
            raise InputError("at most one axis can be Lees-Edwards (one shear-gradient direction)")
        if LEES_EDWARDS in kinds:
            a = kinds.index(LEES_EDWARDS)
            if self.flow == a or not 0 <= self.flow <= 2:
                raise InputError(f"Lees-Edwards flow direction {AXES[self.flow] if 0 <= self.flow <= 2 else self.flow} "
                                 f"must differ from the gradient axis {AXES[a]}")
            if self.flow < len(kinds) and kinds[self.flow] != PERIODIC:
                raise InputError(f"Lees-Edwards flow axis {AXES[self.flow]} must be periodic")

    def tree_flatten(self) -> tuple[tuple, tuple]:
        return (self.shear_rate,), (self.kinds, self.flow)

    @classmethod
    def tree_unflatten(cls, aux: tuple, leaves: tuple) -> Boundaries:
        obj = object.__new__(cls)
        object.__setattr__(obj, "kinds", aux[0])
        object.__setattr__(obj, "flow", aux[1])
        object.__setattr__(obj, "shear_rate", leaves[0])
        return obj

    @classmethod
    def periodic(cls, ndim: int) -> Boundaries:
        return cls((PERIODIC,) * ndim)

    @property
    def all_periodic(self) -> bool:
        return all(k == PERIODIC for k in self.kinds)

    @property
    def shear_axis(self) -> int | None:
        """The Lees–Edwards gradient axis, or None."""
        return self.kinds.index(LEES_EDWARDS) if LEES_EDWARDS in self.kinds else None


def base_velocity(grid: Any, x_a: Any) -> Any:
    """Velocity of the Lees–Edwards base flow γ̇(x_a − L_a/2) along the flow direction at coordinate x_a."""
    bc = grid.boundaries
    a = bc.shear_axis
    return bc.shear_rate * (x_a - 0.5 * grid.lengths[a])


def _shifted(f: Any, s: Any, axis: int) -> Any:
    """f(i − s) along ``axis`` (periodic), linear interpolation for a fractional s ≥ 0."""
    k = jnp.floor(s)
    w = (s - k).astype(f.dtype)
    k = k.astype(jnp.int32)
    return (1.0 - w) * jnp.roll(f, k, axis=axis) + w * jnp.roll(f, k + 1, axis=axis)


def _lees_edwards(f: Any, grid: Any, t: Any, jump: Any, G: int) -> Any:
    """f with G Lees–Edwards ghost layers on each side of the gradient axis (others not yet padded)."""
    bc = grid.boundaries
    a = bc.shear_axis
    n = grid.cells[a]
    U = bc.shear_rate * grid.lengths[a]
    low = jax.lax.slice_in_dim(f, n - G, n, axis=a)  # images of the top cells below the box
    high = jax.lax.slice_in_dim(f, 0, G, axis=a)     # images of the bottom cells above the box
    fl = bc.flow
    if fl < grid.ndim:
        # Δ/Δx_f in cells, reduced modulo the period in float64 (t can be large).
        s = jnp.mod(jnp.asarray(U, jnp.float64) * jnp.asarray(t, jnp.float64) / grid.lengths[fl], 1.0) * grid.cells[fl]
        high = _shifted(high, s, fl)
        low = _shifted(low, -s + grid.cells[fl], fl)
    if jump is not None:
        high = high + jnp.asarray(jump * U, f.dtype)
        low = low - jnp.asarray(jump * U, f.dtype)
    return jnp.concatenate([low, f, high], axis=a)


def pad(fields: Sequence[Any], grid: Any, G: int, t: Any = 0.0, velocity: int | None = None,
        affine: bool = True) -> tuple[Any, ...]:
    """Fields with G ghost cells per side of every grid axis, filled as the boundaries say.

    ``velocity``: index in ``fields`` of the x velocity component (the three components follow
    it), so that the Lees–Edwards jump reaches the flow component; None if the fields hold no
    velocity.  ``affine=False`` leaves out the jump (the linear part of the boundary operator).
    """
    bc = grid.boundaries
    ndim = grid.ndim
    if bc is None or bc.all_periodic:
        return tuple(jnp.pad(f, [(G, G)] * ndim, mode="wrap") for f in fields)
    out = []
    for i, f in enumerate(fields):
        flow_comp = velocity is not None and affine and i == velocity + bc.flow
        f = _lees_edwards(f, grid, t, 1.0 if flow_comp else None, G)
        widths = [(0, 0) if b == bc.shear_axis else (G, G) for b in range(ndim)]
        out.append(jnp.pad(f, widths, mode="wrap"))
    return tuple(out)
