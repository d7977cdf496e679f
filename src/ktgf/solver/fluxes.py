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

from typing import Any, Sequence

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


def reconstruct(W: Sequence[Any], axis: int, limiter: str) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
    """Left and right primitive states at the faces i+1/2 along spatial ``axis`` (MUSCL)."""
    left, right = [], []
    for f in W:
        fm, fp = jnp.roll(f, 1, axis), jnp.roll(f, -1, axis)
        half = 0.5 * limited_slope(f - fm, fp - f, limiter)
        left.append(f + half)
        right.append(jnp.roll(f - half, -1, axis))
    return tuple(left), tuple(right)


def _euler_flux(W: Sequence[Any], U: Sequence[Any], p: Any, a: int) -> list[Any]:
    un = W[1 + a]
    mom = [U[1 + j] * un + (p if j == a else 0.0) for j in range(3)]
    return [U[0] * un, *mom, (U[4] + p) * un]


def convective_flux(W: Sequence[Any], axis: int, phys: Physics, limiter: str, riemann: str) -> list[Any]:
    """Upwind flux (HLL or Rusanov) of the Euler part at the faces along ``axis``."""
    WL, WR = reconstruct(W, axis, limiter)
    rL, rR = phys.reduced(WL[0]), phys.reduced(WR[0])
    pL, pR = phys.pressure(WL[0], WL[4], rL), phys.pressure(WR[0], WR[4], rR)
    cL, cR = phys.sound_speed(WL[4], rL), phys.sound_speed(WR[4], rR)
    UL, UR = conservative_fields(WL), conservative_fields(WR)
    FL, FR = _euler_flux(WL, UL, pL, axis), _euler_flux(WR, UR, pR, axis)
    uL, uR = WL[1 + axis], WR[1 + axis]
    if riemann == "rusanov":
        smax = jnp.maximum(jnp.abs(uL) + cL, jnp.abs(uR) + cR)
        return [0.5 * (fl + fr) - 0.5 * smax * (ur - ul) for fl, fr, ul, ur in zip(FL, FR, UL, UR)]
    # HLL with the Davis wave-speed estimates, written so supersonic faces reduce to upwinding.
    sl = jnp.minimum(jnp.minimum(uL - cL, uR - cR), 0.0)
    sr = jnp.maximum(jnp.maximum(uL + cL, uR + cR), 0.0)
    inv = 1.0 / (sr - sl)
    return [(sr * fl - sl * fr + sl * sr * (ur - ul)) * inv for fl, fr, ul, ur in zip(FL, FR, UL, UR)]


def cell_gradients(u: Sequence[Any], grid: Grid) -> list[list[Any]]:
    """Central differences G[b][j] = ∂u_j/∂x_b at cell centres (b over grid axes, j over 3 components)."""
    return [
        [(jnp.roll(u[j], -1, b) - jnp.roll(u[j], 1, b)) * (0.5 / grid.spacing[b]) for j in range(3)]
        for b in range(grid.ndim)
    ]


def viscous_flux(W: Sequence[Any], G: list[list[Any]], axis: int, grid: Grid, phys: Physics) -> list[Any]:
    """Viscous and heat flux at the faces along ``axis``: (0, −τ·e_a, −(τ·u)_a + q_a).

    Normal derivatives are two-point differences across the face; tangential ones the mean
    of the two cells' central differences.  Coefficients use the face state (mean of cells).
    """
    a = axis
    inv_dx = 1.0 / grid.spacing[a]
    Wn = [jnp.roll(f, -1, a) for f in W]
    rho_f, th_f = 0.5 * (W[0] + Wn[0]), 0.5 * (W[4] + Wn[4])
    u_f = [0.5 * (W[1 + j] + Wn[1 + j]) for j in range(3)]

    def grad(b: int, j: int) -> Any:  # ∂u_j/∂x_b at the face
        if b == a:
            return (Wn[1 + j] - W[1 + j]) * inv_dx
        if b >= grid.ndim:
            return 0.0
        return 0.5 * (G[b][j] + jnp.roll(G[b][j], -1, a))

    divu = sum(grad(b, b) for b in range(grid.ndim))
    r = phys.reduced(rho_f)
    eta, lam, kap, omega = phys.transport(rho_f, th_f, r)
    tau = [eta * (grad(a, j) + grad(j, a)) for j in range(3)]
    tau[a] = tau[a] + (lam - (2.0 / 3.0) * eta) * divu
    q = -kap * (Wn[4] - W[4]) * inv_dx - omega * (Wn[0] - W[0]) * (inv_dx / phys.material_density)
    work = tau[0] * u_f[0] + tau[1] * u_f[1] + tau[2] * u_f[2]
    return [0.0, -tau[0], -tau[1], -tau[2], q - work]


def flux_divergence(W: Sequence[Any], grid: Grid, phys: Physics, limiter: str, riemann: str) -> tuple[list[Any], Any]:
    """−∇·F of the total (convective + viscous + heat) flux per field, and the cell-centred ∇·u."""
    G = cell_gradients(W[1:4], grid)
    out: list[Any] = [0.0] * 5
    for a in range(grid.ndim):
        Fc = convective_flux(W, a, phys, limiter, riemann)
        Fv = viscous_flux(W, G, a, grid, phys)
        inv_dx = 1.0 / grid.spacing[a]
        for i in range(5):
            F = Fc[i] + Fv[i]
            out[i] = out[i] - (F - jnp.roll(F, 1, a)) * inv_dx
    divu = sum(G[b][b] for b in range(grid.ndim))
    return out, divu
