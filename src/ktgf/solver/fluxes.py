"""Finite-volume fluxes: MUSCL-reconstructed upwind convective flux and central viscous/heat fluxes.

Kernels work on tuples of five field arrays (see :mod:`.state`).  Face ``i+1/2`` along axis
``a`` is stored at index ``i``.  The convective flux uses the granular equation of state
p = ρθp*(φ) and the sound speed c² = θ(C + 2p*²/3) of :class:`~ktgf.solver.physics.Physics`;
the primitive variables (ρ, u, θ) are reconstructed with a slope limiter, so face values of
ρ and θ stay within their neighbours' range (positive).  The viscous and heat fluxes are
second-order central differences with the closure coefficients evaluated at the face state
(arithmetic mean of the two cells):

    P = p I − η(∇u + ∇uᵀ − (2/3)∇·u I) − λ_b ∇·u I,     q = −κ∇θ − ω∇φ        (model.md §1)

Flux along a of (ρ, ρu, E):  (ρu_a,  ρu u_a + P·e_a,  E u_a + (P·u)_a + q_a).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import jax
import jax.numpy as jnp

from .grid import Grid
from .physics import Physics
from .state import conservative_fields

LIMITERS = ("minmod", "vanleer", "mc", "none")
RIEMANN_SOLVERS = ("hll", "rusanov")


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


#: Ghost cells per side: the MUSCL stencil of a face reaches two cells away.
GHOST = 2
#: Materialise shared intermediates (padded fields, face states, wave speeds, transport
#: coefficients) with ``lax.optimization_barrier`` so XLA does not recompute them inside every
#: consumer fusion (there are 5 flux components × 2 faces per cell consuming each).
MATERIALISE = True  # switch for A/B timing of the barriers


def materialise(x: Any) -> Any:
    """``x`` behind an optimisation barrier: XLA computes it once and stores it."""
    return jax.lax.optimization_barrier(x) if MATERIALISE else x


def pad_periodic(W: Sequence[Any], ndim: int) -> tuple[Any, ...]:
    """Fields with GHOST periodic ghost cells on each side of every grid axis.

    Padding once per stage and then reading stencils as static slices keeps the fused loops
    free of the concatenations that ``jnp.roll`` would put in every one of them.
    """
    return materialise(tuple(jnp.pad(f, [(GHOST, GHOST)] * ndim, mode="wrap") for f in W))


def window(P: Any, cells: tuple[int, ...], axis: int, offset: int, extra: int, shift: tuple[int, ...] = ()) -> Any:
    """Block of padded field P: along ``axis`` cells offset … N−1+extra+offset, others interior.

    ``shift`` optionally moves the block by ±1 along other axes (tangential stencils).
    """
    start, stop = [], []
    for b, n in enumerate(cells):
        d = shift[b] if shift else 0
        if b == axis:
            start.append(GHOST + offset)
            stop.append(GHOST + offset + n + extra)
        else:
            start.append(GHOST + d)
            stop.append(GHOST + d + n)
    return jax.lax.slice(P, start, stop)


def reconstruct(P: Sequence[Any], cells: tuple[int, ...], axis: int, limiter: str) -> tuple[list[Any], list[Any]]:
    """Left and right primitive states at the N+1 faces −1/2 … N−1/2 along ``axis`` (MUSCL)."""
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


def convective_flux(
    P: Sequence[Any], cells: tuple[int, ...], axis: int, phys: Physics, limiter: str, riemann: str
) -> list[Any]:
    """Upwind flux (HLL or Rusanov) of the Euler part at the N+1 faces along ``axis`` (padded input P)."""
    WL, WR = materialise(reconstruct(P, cells, axis, limiter))
    rL, rR = phys.reduced(WL[0]), phys.reduced(WR[0])
    pL, pR = phys.pressure(WL[0], WL[4], rL), phys.pressure(WR[0], WR[4], rR)
    cL, cR = phys.sound_speed(WL[4], rL), phys.sound_speed(WR[4], rR)
    UL, UR = conservative_fields(WL), conservative_fields(WR)
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


def viscous_flux(P: Sequence[Any], axis: int, grid: Grid, phys: Physics) -> list[Any]:
    """Viscous and heat flux at the N+1 faces along ``axis``: (0, −τ·e_a, −(τ·u)_a + q_a).

    Normal derivatives are two-point differences across the face; tangential ones the mean
    of the two cells' central differences.  Coefficients use the face state (mean of cells).
    """
    a = axis
    inv_dx = 1.0 / grid.spacing[a]
    Wl = [window(f, grid.cells, a, -1, 1) for f in P]  # cells −1 … N−1
    Wr = [window(f, grid.cells, a, 0, 1) for f in P]  # cells 0 … N
    rho_f, th_f = 0.5 * (Wl[0] + Wr[0]), 0.5 * (Wl[4] + Wr[4])
    u_f = [0.5 * (Wl[1 + j] + Wr[1 + j]) for j in range(3)]

    n = grid.cells[a]
    # Tangential derivatives at the faces: mean of the central differences of the two cells.
    tangential = {}
    for b in range(grid.ndim):
        if b != a:
            for j in range(3):
                g = _central(P[1 + j], grid, a, b)
                tangential[b, j] = 0.5 * (
                    jax.lax.slice_in_dim(g, 0, n + 1, axis=a) + jax.lax.slice_in_dim(g, 1, n + 2, axis=a)
                )
    tangential = materialise(tangential)

    def grad(b: int, j: int) -> Any:  # ∂u_j/∂x_b at the face
        if b == a:
            return (Wr[1 + j] - Wl[1 + j]) * inv_dx
        if b >= grid.ndim:
            return 0.0
        return tangential[b, j]

    divu = sum(grad(b, b) for b in range(grid.ndim))
    r = phys.reduced(rho_f)
    eta, lam, kap, omega = materialise(phys.transport(rho_f, th_f, r))
    tau = [eta * (grad(a, j) + grad(j, a)) for j in range(3)]
    tau[a] = tau[a] + (lam - (2.0 / 3.0) * eta) * divu
    tau = materialise(tau)
    q = -kap * (Wr[4] - Wl[4]) * inv_dx - omega * (Wr[0] - Wl[0]) * (inv_dx / phys.material_density)
    work = tau[0] * u_f[0] + tau[1] * u_f[1] + tau[2] * u_f[2]
    return [0.0, -tau[0], -tau[1], -tau[2], q - work]


def flux_divergence(W: Sequence[Any], grid: Grid, phys: Physics, limiter: str, riemann: str) -> tuple[list[Any], Any]:
    """−∇·F of the total (convective + viscous + heat) flux per field, and the cell-centred ∇·u."""
    P = pad_periodic(W, grid.ndim)
    out: list[Any] = [0.0] * 5
    for a in range(grid.ndim):
        Fc = convective_flux(P, grid.cells, a, phys, limiter, riemann)
        Fv = viscous_flux(P, a, grid, phys)
        inv_dx = 1.0 / grid.spacing[a]
        n = grid.cells[a]
        # One stacked array of face fluxes: XLA then computes all five components in one
        # loop and materialises them, instead of recomputing the face state in each consumer.
        F = jnp.stack([Fc[i] + Fv[i] for i in range(5)])
        dF = jax.lax.slice_in_dim(F, 1, n + 1, axis=a + 1) - jax.lax.slice_in_dim(F, 0, n, axis=a + 1)
        out = [o - dF[i] * inv_dx for i, o in enumerate(out)]
    divu = sum(
        (window(P[1 + b], grid.cells, b, 1, 0) - window(P[1 + b], grid.cells, b, -1, 0)) * (0.5 / grid.spacing[b])
        for b in range(grid.ndim)
    )
    return out, divu
