"""Finite-volume fluxes: MUSCL-reconstructed upwind convective flux and central viscous/heat fluxes.

Kernels work on tuples of field arrays (see :mod:`.state`).  Face ``i+1/2`` along axis ``a``
is stored at index ``i``.  The closures are evaluated once per cell and stage
(:func:`.friction.cell_coefficients`, called by :func:`.stepping.explicit_rhs`); nothing here
calls a closure.  The convective flux uses the granular
equation of state p = ρθp*(φ) and the sound speed c² = θg, g = C + 2p*²/3
(:class:`~ktgf.solver.physics.Physics`): the primitive variables (ρ, u, θ) and the cell values
of p* and g are reconstructed with the same slope limiter (face ρ, θ, p*, g stay within their
neighbours' range, so positive; p* and g are smooth functions of φ, so the face values are
second-order accurate like a closure evaluation at the reconstructed φ).  The viscous and heat
fluxes are second-order central differences with face coefficients = arithmetic mean of the two
cells' coefficients (η, λ_b, κ, ω):

    P = p I − η(∇u + ∇uᵀ − (2/3)∇·u I) − λ_b ∇·u I,     q = −κ∇θ − ω∇φ        (model.md §1)

Flux along a of (ρ, ρu, E):  (ρu_a,  ρu u_a + P·e_a,  E u_a + (P·u)_a + q_a).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from types import SimpleNamespace
from typing import Any

import jax
import jax.numpy as jnp

from .boundaries import lees_edwards_faces
from .grid import Grid, periodic
from .physics import Physics
from .state import conservative_fields
from .stencil import GHOST, LIMITERS, RIEMANN_SOLVERS  # noqa: F401  (fluxes.GHOST etc. are read elsewhere)


def limited_slope(dm: Any, dp: Any, limiter: str) -> Any:
    """Cell slope from the backward and forward differences (TVD limiters; ``none`` = central)."""
    if limiter == "none":
        return 0.5 * (dm + dp)
    prod = dm * dp
    if limiter == "vanleer":
        # 2 dm dp/(dm + dp) where dm dp > 0, else 0; |dm + dp| > 0 there.
        return jnp.where(prod > 0.0, 2.0 * prod / jnp.where(prod > 0.0, dm + dp, 1.0), 0.0)
    if limiter == "minmod":
        s = jnp.sign(dm) * jnp.minimum(jnp.abs(dm), jnp.abs(dp))
    elif limiter == "mc":
        s = jnp.sign(dm) * jnp.minimum(jnp.minimum(2.0 * jnp.abs(dm), 2.0 * jnp.abs(dp)), 0.5 * jnp.abs(dm + dp))
    else:  # pragma: no cover - validated by Numerics
        raise ValueError(f"unknown limiter {limiter!r}; valid: {LIMITERS}")
    return jnp.where(prod > 0.0, s, 0.0)


def materialise(x: Any) -> Any:
    """``x`` behind an optimisation barrier: XLA computes it once and stores it, instead of recomputing shared
    intermediates (padded fields, face states, wave speeds) inside each of their consumer fusions.

    Measured (docs/solver.md, Speed): the barriers keep the padded and primitive fields
    stored, but inside the per-axis flux fusion XLA CPU fuses straight through them.
    """
    return jax.lax.optimization_barrier(x)


def pad_fields(W: Sequence[Any], grid: Grid, t: Any = 0.0, velocity: int | None = None,
               affine: bool = True, theta: int | None = None, walls: Any = None) -> tuple[Any, ...]:
    """Fields with GHOST ghost cells per side, filled by the grid's boundaries (:func:`.boundaries.pad`)."""
    from .boundaries import pad

    if periodic(grid):
        return pad_periodic(W, grid.ndim)
    return materialise(pad(W, grid, GHOST, t, velocity, affine, theta, walls))


def has_walls(grid: Grid) -> bool:
    return grid.boundaries is not None and bool(grid.boundaries.wall_axes)


def pad_viscous(W: Sequence[Any], transport: Sequence[Any], grid: Grid, phys: Physics, t: Any = 0.0,
                walls: Any = None) -> tuple[Any, ...]:
    """Primitive fields (ρ, u, θ) padded for the viscous and heat fluxes: with walls, the ghost cells
    of the wall conditions (``walls``: frozen :func:`.boundaries.wall_terms`, else from W)."""
    if not has_walls(grid):
        return pad_fields(W, grid, t, velocity=1)
    from .boundaries import wall_terms

    if walls is None:
        walls = wall_terms(W[0], W[1:4], W[4], transport, grid, phys)
    return pad_fields(W, grid, t, velocity=1, theta=4, walls=walls)


def _switch(name: str) -> bool:
    return os.environ.get(name, "1").lower() not in ("0", "off", "false", "no")


#: Use the C++ kernel (:mod:`.flux_kernel`) for :func:`flux_divergence` where it applies (CPU, one device, a 3D
#: grid).  Default on; ``KTGF_FLUX_KERNEL=0`` switches it off.
FLUX_KERNEL = _switch("KTGF_FLUX_KERNEL")
#: Where the flux kernel applies, run each SSP-RK3 stage as one kernel call with the source and the stage update
#: fused in (:func:`.flux_kernel.ssprk_stage`).  ``KTGF_STAGE_KERNEL=0`` keeps the flux kernel for the fluxes only
#: (the A/B reference of ``benchmarks/bench_solver.py``).
STAGE_KERNEL = _switch("KTGF_STAGE_KERNEL")
#: Where the stage kernel runs, evaluate the cell closures inside it by a generated cell program
#: (:mod:`.cell_program`, :func:`.flux_kernel.ssprk_stage_cells`).  ``KTGF_CELL_PROGRAM=0`` keeps the XLA pass.
CELL_PROGRAM = _switch("KTGF_CELL_PROGRAM")


def pad_periodic(W: Sequence[Any], ndim: int) -> tuple[Any, ...]:
    """Fields with GHOST periodic ghost cells on each side of every grid axis: padding once per stage and then
    reading stencils as static slices keeps the loops free of the concatenations of ``jnp.roll``."""
    return materialise(tuple(jnp.pad(f, [(GHOST, GHOST)] * ndim, mode="wrap") for f in W))


def window(P: Any, cells: tuple[int, ...], axis: int, offset: int, extra: int, shift: tuple[int, ...] = ()) -> Any:
    """Block of padded field P: along ``axis`` cells offset … N−1+extra+offset, others interior.

    ``shift`` optionally moves the block by ±1 along other axes (tangential stencils).
    """
    start = [GHOST + (offset if b == axis else shift[b] if shift else 0) for b in range(len(cells))]
    stop = [s + n + (extra if b == axis else 0) for b, (s, n) in enumerate(zip(start, cells))]
    return jax.lax.slice(P, start, stop)


def reconstruct(P: Sequence[Any], cells: tuple[int, ...], axis: int, limiter: str) -> tuple[list[Any], list[Any]]:
    """Left and right states at the N+1 faces −1/2 … N−1/2 along ``axis`` (MUSCL)."""
    left, right = [], []
    for f in P:
        fm, fc, fp = (window(f, cells, axis, o, 2) for o in (-2, -1, 0))  # cells −1 … N
        half = 0.5 * limited_slope(fc - fm, fp - fc, limiter)
        n = cells[axis]
        left.append(jax.lax.slice_in_dim(fc + half, 0, n + 1, axis=axis))
        right.append(jax.lax.slice_in_dim(fc - half, 1, n + 2, axis=axis))
    return left, right


def _euler_flux(W: Sequence[Any], U: Sequence[Any], p: Any, a: int) -> list[Any]:
    un = W[1 + a]
    mom = [U[1 + j] * un + (p if j == a else 0.0) for j in range(3)]
    return [U[0] * un, *mom, (U[4] + p) * un]


def wall_flux(W: Sequence[Any], axis: int, side: int) -> list[Any]:
    """Convective flux through a wall face from the medium's face state W = (ρ, u, θ, p*, g) there.

    The HLL (and Rusanov) flux between W and its mirror image (u_n → −u_n): with s = |u_n| + c
    it is (0, ρu_n² + p ∓ sρu_n on the normal component, 0, 0) — − for the lower wall (medium on
    the right), + for the upper one.  At rest the wall pressure p; nothing else crosses.
    """
    rho, un = W[0], W[1 + axis]
    p = rho * W[4] * W[5]
    s = jnp.abs(un) + jnp.sqrt(W[4] * W[6])
    normal = rho * un * un + p + (-1.0 if side == 0 else 1.0) * s * rho * un
    zero = jnp.zeros_like(rho)
    return [zero, *(normal if j == axis else zero for j in range(3)), zero]


def convective_flux(P: Sequence[Any], cells: tuple[int, ...], axis: int, limiter: str, riemann: str,
                    walls: bool = False) -> list[Any]:
    """Upwind flux (HLL or Rusanov) of the Euler part at the N+1 faces along ``axis``.

    ``P`` = padded (ρ, u_x, u_y, u_z, θ, p*, g) cell fields (:func:`pad_periodic`); ``walls``:
    the first and last faces are walls (:func:`wall_flux` from the medium's side).
    """
    WL, WR = materialise(reconstruct(P, cells, axis, limiter))
    F = riemann_flux(WL, WR, axis, riemann)
    if not walls:
        return F
    n = cells[axis]
    lo = wall_flux([jax.lax.slice_in_dim(w, 0, 1, axis=axis) for w in WR], axis, 0)
    hi = wall_flux([jax.lax.slice_in_dim(w, n, n + 1, axis=axis) for w in WL], axis, 1)
    return [jnp.concatenate([a, jax.lax.slice_in_dim(f, 1, n, axis=axis), b], axis=axis) for a, f, b in zip(lo, F, hi)]


def riemann_flux(WL: Sequence[Any], WR: Sequence[Any], axis: int, riemann: str) -> list[Any]:
    """HLL or Rusanov flux between the left and right face states (ρ, u, θ, p*, g)."""
    pL, pR = WL[0] * WL[4] * WL[5], WR[0] * WR[4] * WR[5]
    cL, cR = jnp.sqrt(WL[4] * WL[6]), jnp.sqrt(WR[4] * WR[6])
    UL, UR = conservative_fields(WL[:5]), conservative_fields(WR[:5])
    FL, FR = _euler_flux(WL, UL, pL, axis), _euler_flux(WR, UR, pR, axis)
    uL, uR = WL[1 + axis], WR[1 + axis]
    pL, pR, cL, cR = materialise((pL, pR, cL, cR))
    if riemann == "rusanov":
        smax = jnp.maximum(jnp.abs(uL) + cL, jnp.abs(uR) + cR)
        return [0.5 * (fl + fr) - 0.5 * smax * (ur - ul) for fl, fr, ul, ur in zip(FL, FR, UL, UR)]
    # HLL with the Davis wave-speed estimates, written so supersonic faces reduce to upwinding.
    sl = jnp.minimum(jnp.minimum(uL - cL, uR - cR), 0.0)
    sr = jnp.maximum(jnp.maximum(uL + cL, uR + cR), 0.0)
    inv = 1.0 / (sr - sl)
    return [(sr * fl - sl * fr + sl * sr * (ur - ul)) * inv for fl, fr, ul, ur in zip(FL, FR, UL, UR)]


def _central(P: Any, grid: Grid, axis: int, b: int) -> Any:
    """∂f/∂x_b (b ≠ axis) by central differences at the cells −1 … N along ``axis``."""
    plus = tuple(1 if c == b else 0 for c in range(grid.ndim))
    minus = tuple(-1 if c == b else 0 for c in range(grid.ndim))
    fp = window(P, grid.cells, axis, -1, 2, plus)
    fm = window(P, grid.cells, axis, -1, 2, minus)
    return (fp - fm) * (0.5 / grid.spacing[b])


def face_mean(P: Any, cells: tuple[int, ...], axis: int) -> Any:
    """Arithmetic mean of the two cells of every face −1/2 … N−1/2 along ``axis`` (padded P)."""
    return 0.5 * (window(P, cells, axis, -1, 1) + window(P, cells, axis, 0, 1))


def face_jump(P: Any, cells: tuple[int, ...], axis: int) -> Any:
    """Right minus left cell value at every face along ``axis`` (padded P)."""
    return window(P, cells, axis, 0, 1) - window(P, cells, axis, -1, 1)


def face_coefficients(Pk: Sequence[Any], cells: tuple[int, ...], axis: int) -> tuple[Any, ...]:
    """Face values of padded cell coefficients: arithmetic mean of the two cells."""
    return tuple(face_mean(k, cells, axis) for k in Pk)


def stress(Pu: Sequence[Any], eta: Any, lam: Any, axis: int, grid: Grid) -> list[Any]:
    """Viscous stress τ·e_a at the N+1 faces along ``axis`` (padded velocities Pu, face η, λ_b).

    τ = η(∇u + ∇uᵀ − (2/3)∇·u I) + λ_b∇·u I.  Normal derivatives are two-point differences
    across the face; tangential ones the mean of the two cells' central differences.
    """
    a = axis
    inv_dx = 1.0 / grid.spacing[a]
    n = grid.cells[a]
    tangential = {}
    for b in range(grid.ndim):
        if b != a:
            for j in range(3):
                g = _central(Pu[j], grid, a, b)
                tangential[b, j] = 0.5 * (jax.lax.slice_in_dim(g, 0, n + 1, axis=a)
                                          + jax.lax.slice_in_dim(g, 1, n + 2, axis=a))
    tangential = materialise(tangential)

    def grad(b: int, j: int) -> Any:  # ∂u_j/∂x_b at the face
        if b == a:
            return face_jump(Pu[j], grid.cells, a) * inv_dx
        if b >= grid.ndim:
            return 0.0
        return tangential[b, j]

    divu = sum(grad(b, b) for b in range(grid.ndim))
    tau = [eta * (grad(a, j) + grad(j, a)) for j in range(3)]
    tau[a] = tau[a] + (lam - (2.0 / 3.0) * eta) * divu
    return tau


def heat_flux(Ptheta: Any, Prho: Any, kap: Any, omega: Any, axis: int, grid: Grid, rho_s: Any) -> Any:
    """q·e_a = −κ∂θ/∂x_a − ω∂φ/∂x_a at the N+1 faces along ``axis`` (face κ, ω)."""
    inv_dx = 1.0 / grid.spacing[axis]
    return (-kap * face_jump(Ptheta, grid.cells, axis) * inv_dx
            - omega * face_jump(Prho, grid.cells, axis) * (inv_dx / rho_s))


def stress_work(tau: Sequence[Any], Pu: Sequence[Any], cells: tuple[int, ...], axis: int) -> Any:
    """(τ·u)·e_a at the faces, with the face velocity the mean of the two cells."""
    return sum(tau[j] * face_mean(Pu[j], cells, axis) for j in range(3))


def viscous_flux(P: Sequence[Any], Pk: Sequence[Any], axis: int, grid: Grid, rho_s: Any) -> list[Any]:
    """Viscous and heat flux at the N+1 faces along ``axis``: (0, −τ·e_a, −(τ·u)_a + q_a).

    ``P`` padded primitive fields, ``Pk`` padded cell coefficients (η, λ_b, κ, ω).
    """
    eta, lam, kap, omega = materialise(face_coefficients(Pk, grid.cells, axis))
    Pu = P[1:4]
    tau = materialise(stress(Pu, eta, lam, axis, grid))
    q = heat_flux(P[4], P[0], kap, omega, axis, grid, rho_s)
    return [0.0, -tau[0], -tau[1], -tau[2], q - stress_work(tau, Pu, grid.cells, axis)]


def face_divergence(F: Any, grid: Grid, axis: int) -> Any:
    """−(F_{i+1/2} − F_{i−1/2})/Δx_a at the cells, from face values −1/2 … N−1/2 (leading axis kept)."""
    n = grid.cells[axis]
    ax = F.ndim - grid.ndim + axis
    return (jax.lax.slice_in_dim(F, 0, n, axis=ax) - jax.lax.slice_in_dim(F, 1, n + 1, axis=ax)) / grid.spacing[axis]


def flux_divergence(W: Sequence[Any], coefficients: tuple[tuple[Any, ...], tuple[Any, ...]], grid: Grid,
                    phys: Physics, limiter: str, riemann: str, viscous: bool = True,
                    t: Any = 0.0) -> tuple[list[Any], Any]:
    """−∇·F per field of the convective (+ viscous and heat, if ``viscous``) flux, and the cell ∇·u.

    ``coefficients`` = (eos, transport) cell fields (:meth:`.Physics.eos`, :meth:`.Physics.transport`); ``t`` the time (the
    Lees–Edwards images move).
    """
    eos, transport = coefficients
    if FLUX_KERNEL:
        from . import flux_kernel

        if flux_kernel.applies(grid, W[0].dtype, "rhs" if viscous else "euler", limiter, riemann):
            *fields, ghosts, fix = kernel_fields(W, eos, transport, grid, phys, limiter, riemann, viscous, t)
            dU, divu = flux_kernel.flux_divergence(*fields, grid, phys.material_density, limiter, riemann, viscous,
                                                   ghosts)
            return add_boundary_fluxes(dU, fix), divu
    P = pad_fields((*W, *eos), grid, t, velocity=1)
    Pk = pad_fields(transport, grid, t) if viscous else ()
    Pv = (pad_viscous(W, transport, grid, phys, t) if has_walls(grid) else P[:5]) if viscous else ()
    out: list[Any] = [0.0] * 5
    for a in range(grid.ndim):
        Fc = convective_flux(P, grid.cells, a, limiter, riemann, walls=has_walls(grid) and a in grid.boundaries.wall_axes)
        if viscous:
            Fv = viscous_flux(Pv, Pk, a, grid, phys.material_density)
            Fc = [Fc[i] + Fv[i] for i in range(5)]
        Fc = lees_edwards_faces(Fc, grid, a, t)  # conservative across a Lees-Edwards boundary
        # One stacked array of face fluxes: XLA then computes all five components in one
        # loop and materialises them, instead of recomputing the face state in each consumer.
        dF = face_divergence(jnp.stack(Fc), grid, a)
        out = [o + dF[i] for i, o in enumerate(out)]
    return out, cell_divergence(P[1:4], grid)


def cell_divergence(Pu: Sequence[Any], grid: Grid) -> Any:
    """Central ∇·u at the cells (padded velocities)."""
    return sum((window(Pu[b], grid.cells, b, 1, 0) - window(Pu[b], grid.cells, b, -1, 0)) * (0.5 / grid.spacing[b])
               for b in range(grid.ndim))


def kernel_fields(W: Sequence[Any], eos: Sequence[Any], transport: Sequence[Any], grid: Grid, phys: Physics,
                  limiter: str, riemann: str, viscous: bool, t: Any = 0.0) -> tuple:
    """The cell fields the C++ kernel sweeps (W, eos, transport), then the ghost planes and the boundary
    correction of :func:`boundary_terms` (None, None on a periodic grid: the kernel pads periodically)."""
    if periodic(grid):
        return W, eos, transport, None, None
    ends = grid_ends((*W, *eos, *transport), grid)
    return (W, eos, transport, *boundary_terms(ends, grid, phys, limiter, riemann, viscous, t))


def boundary_axis(grid: Grid) -> int:
    """The axis of a grid's Lees–Edwards boundary or, without one, of its first walls."""
    bc = grid.boundaries
    return bc.shear_axis if bc.shear_axis is not None else bc.wall_axes[0]


def grid_ends(fields: Sequence[Any], grid: Grid) -> SimpleNamespace:
    """The GHOST + 1 cells next to each end of the :func:`boundary_axis` ``a`` of ``fields`` (all of them on a grid
    of ≤ 2(GHOST + 1) cells along a): ``fields``, ``grid`` (the grid they fill: its boundaries see them as the whole
    axis, so the ghost cells of each end come from the cells of that end or, through a Lees–Edwards boundary, of the
    other), ``k`` (their number along a) and ``a``.  With walls, the fields come with the GHOST periodic ghost cells
    of the other axes (``grid.wrapped``)."""
    a = boundary_axis(grid)
    n, m = grid.cells[a], GHOST + 1
    k = min(n, 2 * m)
    if n > 2 * m:
        fields = [jnp.concatenate([jax.lax.slice_in_dim(f, 0, m, axis=a), jax.lax.slice_in_dim(f, n - m, n, axis=a)],
                                  axis=a) for f in fields]
    # With walls the other axes are periodic: their ghost cells are wrapped here, once, so that the paddings of the
    # fields that follow (pad) add only the walls' (64³ Couette: 96 XLA fusions a stage, not 118; ≈ 25 % less time).
    wrapped = grid.boundaries.shear_axis is None
    if wrapped:
        fields = [jnp.pad(f, [(0, 0) if b == a else (GHOST, GHOST) for b in range(grid.ndim)], mode="wrap")
                  for f in fields]
    thin = SimpleNamespace(cells=tuple(k if b == a else c for b, c in enumerate(grid.cells)), spacing=grid.spacing,
                           ndim=grid.ndim, lengths=grid.lengths, boundaries=grid.boundaries, wrapped=wrapped)
    return SimpleNamespace(fields=list(fields), grid=thin, k=k, a=a)


def boundary_terms(ends: SimpleNamespace, grid: Grid, phys: Physics, limiter: str, riemann: str, viscous: bool,
                   t: Any = 0.0) -> tuple:
    """What the C++ kernel needs at a wall or Lees–Edwards axis a, from the :func:`grid_ends` of the cell fields
    (W, eos, then with ``viscous`` transport): (a, ghost planes) and (a, {plane: five increments of −∇·F}).

    The ghost planes are the fields padded as the JAX path pads them for its convective flux (:func:`pad_fields`),
    GHOST planes per side of the padded shape of the other axes, which the kernel puts over its periodic padding.
    The increments are for the planes next to the boundary, where the JAX path's fluxes differ from what the
    kernel computes from those ghost cells — each difference from the same formulas on slabs one cell thick:

    * Lees–Edwards: the lower boundary face takes the upper one mapped through the boundary
      (:func:`.boundaries.lees_edwards_faces`);
    * walls: the convective flux through a wall face is :func:`wall_flux`, and the viscous and heat fluxes of
      the wall planes (through the wall face, and along the other axes, whose tangential derivatives reach the
      ghost cells) see the ghost cells of the wall conditions (:func:`pad_viscous`).
    """
    bc, rho_s, a, k = grid.boundaries, phys.material_density, ends.a, ends.k
    n, inv_dx = grid.cells[a], 1.0 / grid.spacing[a]
    P = pad_fields(ends.fields[:7], ends.grid, t, velocity=1)
    Pk = pad_fields(ends.fields[7:], ends.grid, t) if viscous else ()
    ghosts = jnp.stack([jnp.stack([jnp.moveaxis(jax.lax.slice_in_dim(f, lo, lo + GHOST, axis=a), a, 0)
                                   for lo in (0, k + GHOST)]) for f in (*P, *Pk)])
    slab = SimpleNamespace(cells=tuple(1 if b == a else c for b, c in enumerate(grid.cells)), spacing=grid.spacing,
                           ndim=grid.ndim, lengths=grid.lengths, boundaries=bc)

    def cuts(fields: Sequence[Any]) -> list[Any]:  # the end cells 0 and k - 1, G neighbours per side, stacked on a
        if k == 2 * (GHOST + 1):  # the padded ends are the two cuts side by side: a reshape, not a copy
            return [jnp.reshape(f, (*f.shape[:a], 2, 2 * GHOST + 1, *f.shape[a + 1:])) for f in fields]
        return [jnp.stack([jax.lax.slice_in_dim(f, lo, lo + 2 * GHOST + 1, axis=a) for lo in (0, k - 1)], axis=a)
                for f in fields]

    def ends_map(fn: Any, *args: Any) -> tuple[list[Any], list[Any]]:
        """fn of the stacked slabs of both ends at once (one traced computation; XLA's operation count is not lower:
        1,719 small operations per 64³ Couette step against 1,524 for two calls): its lists of fields at the end 0,
        at the end k - 1."""
        out = jax.vmap(fn, in_axes=a)(*args)
        return [f[0] for f in out], [f[1] for f in out]

    def slab_faces(walls: bool) -> Any:  # both faces along a of a slab (with walls: the viscous ghosts' slab Cv)
        def fn(C: Any, Ck: Any, Cv: Any = None) -> list[Any]:
            F = convective_flux(C, slab.cells, a, limiter, riemann, walls=walls)
            if not viscous:
                return F
            return [f + v for f, v in zip(F, viscous_flux(C[:5] if Cv is None else Cv, Ck, a, slab, rho_s))]
        return fn

    def face(F: Sequence[Any], side: int) -> list[Any]:
        return [jax.lax.slice_in_dim(f, side, side + 1, axis=a) for f in F]

    C, Ck = cuts(P), cuts(Pk)
    lo_own, hi_own = ends_map(slab_faces(False), C, Ck)
    if bc.shear_axis is not None:
        own = face(lo_own, 0)
        pair = [jnp.concatenate([lo_, hi], axis=a) for lo_, hi in zip(own, face(hi_own, 1))]
        mapped = face(lees_edwards_faces(pair, slab, a, t), 0)
        return (a, ghosts), (a, {0: [(m - f) * inv_dx for m, f in zip(mapped, own)]})
    Cv = cuts(pad_viscous(ends.fields[:5], ends.fields[7:], ends.grid, phys, t)) if viscous else []
    lo_true, hi_true = ends_map(slab_faces(True), C, Ck, *([Cv] if viscous else []))
    d = {}
    for plane, side, sign, true, own in ((0, 0, 1.0, lo_true, lo_own), (n - 1, 1, -1.0, hi_true, hi_own)):
        d[plane] = [sign * (x - y) * inv_dx for x, y in zip(face(true, side), face(own, side))]
    for b in range(grid.ndim) if viscous else ():
        if b != a:  # the wall planes' viscous fluxes along b, with the viscous ghosts less with the convective
            def along_b(Cv: Any, C: Any, Ck: Any, b: int = b) -> list[Any]:
                Fv, Fc = viscous_flux(Cv, Ck, b, slab, rho_s), viscous_flux(C[:5], Ck, b, slab, rho_s)
                return list(face_divergence(jnp.stack([x - y for x, y in zip(Fv[1:], Fc[1:])]), slab, b))
            for plane, dF in zip((0, n - 1), ends_map(along_b, Cv, C, Ck)):
                d[plane] = [d[plane][0], *(x + y for x, y in zip(d[plane][1:], dF))]
    return (a, ghosts), (a, d)


def add_boundary_fluxes(fields: Sequence[Any], fix: Any) -> Any:
    """``fields`` with the boundary corrections ``fix`` = (axis, {plane: increments}) of
    :func:`kernel_fields` added to those planes (unchanged for None)."""
    if fix is None:
        return fields
    a, planes = fix
    out = list(fields)
    for plane, d in planes.items():
        at = (slice(None),) * a + (slice(plane, plane + 1),)
        out = [f.at[at].add(c) for f, c in zip(out, d)]
    return type(fields)(out)
