"""Finite-volume fluxes: MUSCL-reconstructed upwind convective flux and central viscous/heat fluxes.

Face ``i+1/2`` along axis ``a`` is stored at index ``i``.  The convective flux uses the
granular equation of state p = ρθp*(φ) and the sound speed c² = θ(C + 2p*²/3) of
:class:`~ktgf.solver.physics.Physics`; the primitive variables (ρ, u, θ) are reconstructed
with a slope limiter so θ and ρ stay within their neighbours' range.  The viscous and heat
fluxes are second-order central differences with the closure coefficients evaluated at the
face state (arithmetic mean of the two cells):

    P = p I − η(∇u + ∇uᵀ − (2/3)∇·u I) − λ_b ∇·u I,     q = −κ∇θ − ω∇φ        (model.md §1)

Flux along a of (ρ, ρu, E):  (ρu_a,  ρu u_a + P·e_a,  E u_a + (P·u)_a + q_a).
"""

from __future__ import annotations

from typing import Any

import jax.numpy as jnp

from .grid import Grid
from .physics import Physics
from .state import from_primitive

LIMITERS = ("minmod", "vanleer", "mc", "none")
RIEMANN_SOLVERS = ("hll", "rusanov")


def limited_slope(dm: Any, dp: Any, limiter: str) -> Any:
    """Cell slope from the backward and forward differences (TVD limiters; ``none`` = central)."""
    if limiter == "none":
        return 0.5 * (dm + dp)
    same = dm * dp > 0.0
    if limiter == "minmod":
        s = jnp.sign(dm) * jnp.minimum(jnp.abs(dm), jnp.abs(dp))
    elif limiter == "vanleer":
        s = 2.0 * dm * dp / jnp.where(same, dm + dp, 1.0)
    elif limiter == "mc":
        s = jnp.sign(dm) * jnp.minimum(jnp.minimum(2.0 * jnp.abs(dm), 2.0 * jnp.abs(dp)), 0.5 * jnp.abs(dm + dp))
    else:  # pragma: no cover - validated by the config
        raise ValueError(f"unknown limiter {limiter!r}; valid: {LIMITERS}")
    return jnp.where(same, s, 0.0)


def reconstruct(W: Any, axis: int, limiter: str) -> tuple[Any, Any]:
    """Left and right primitive states at the faces i+1/2 along spatial ``axis`` (MUSCL)."""
    ax = axis + 1
    dm = W - jnp.roll(W, 1, ax)
    dp = jnp.roll(W, -1, ax) - W
    half = 0.5 * limited_slope(dm, dp, limiter)
    return W + half, jnp.roll(W - half, -1, ax)


def _euler_flux(W: Any, U: Any, p: Any, a: int) -> Any:
    un = W[1 + a]
    mom = W[0] * W[1:4] * un
    mom = mom.at[a].add(p)
    return jnp.concatenate([U[0:1] * un, mom, ((U[4] + p) * un)[None]], axis=0)


def convective_flux(W: Any, axis: int, phys: Physics, limiter: str, riemann: str) -> Any:
    """Upwind flux (HLL or Rusanov) of the Euler part at the faces along ``axis``."""
    WL, WR = reconstruct(W, axis, limiter)
    rL, rR = phys.reduced(WL[0]), phys.reduced(WR[0])
    pL, pR = phys.pressure(WL[0], WL[4], rL), phys.pressure(WR[0], WR[4], rR)
    cL, cR = phys.sound_speed(WL[4], rL), phys.sound_speed(WR[4], rR)
    UL, UR = from_primitive(WL), from_primitive(WR)
    FL, FR = _euler_flux(WL, UL, pL, axis), _euler_flux(WR, UR, pR, axis)
    uL, uR = WL[1 + axis], WR[1 + axis]
    if riemann == "rusanov":
        smax = jnp.maximum(jnp.abs(uL) + cL, jnp.abs(uR) + cR)
        return 0.5 * (FL + FR) - 0.5 * smax * (UR - UL)
    # HLL with the Davis wave-speed estimates, written so supersonic faces reduce to upwinding.
    sl = jnp.minimum(jnp.minimum(uL - cL, uR - cR), 0.0)
    sr = jnp.maximum(jnp.maximum(uL + cL, uR + cR), 0.0)
    return (sr * FL - sl * FR + sl * sr * (UR - UL)) / (sr - sl)


def cell_gradients(u: Any, grid: Grid) -> list[list[Any]]:
    """Central differences G[b][j] = ∂u_j/∂x_b at cell centres (b over grid axes, j over 3 components)."""
    return [
        [(jnp.roll(u[j], -1, b) - jnp.roll(u[j], 1, b)) / (2.0 * grid.spacing[b]) for j in range(3)]
        for b in range(grid.ndim)
    ]


def viscous_flux(W: Any, G: list[list[Any]], axis: int, grid: Grid, phys: Physics) -> Any:
    """Viscous and heat flux at the faces along ``axis``: (0, −τ·e_a, −(τ·u)_a + q_a).

    Normal derivatives are two-point differences across the face; tangential ones the mean
    of the two cells' central differences.  Coefficients use the face state (mean of cells).
    """
    a = axis
    dx = grid.spacing[a]
    Wn = jnp.roll(W, -1, a + 1)
    Wf = 0.5 * (W + Wn)
    rho_f, u_f, th_f = Wf[0], Wf[1:4], Wf[4]
    dW = (Wn - W) / dx

    def grad(b: int, j: int) -> Any:  # ∂u_j/∂x_b at the face
        if b == a:
            return dW[1 + j]
        if b >= grid.ndim:
            return 0.0
        return 0.5 * (G[b][j] + jnp.roll(G[b][j], -1, a))

    divu = sum(grad(b, b) for b in range(grid.ndim))
    r = phys.reduced(rho_f)
    eta, lam, kap, omega = phys.transport(rho_f, th_f, r)
    tau = [eta * (grad(a, j) + grad(j, a)) for j in range(3)]
    tau[a] = tau[a] + (lam - (2.0 / 3.0) * eta) * divu
    q = -kap * dW[4] - omega * dW[0] / phys.material_density
    work = tau[0] * u_f[0] + tau[1] * u_f[1] + tau[2] * u_f[2]
    zero = jnp.zeros_like(rho_f)
    return jnp.stack([zero, -tau[0], -tau[1], -tau[2], q - work], axis=0)


def flux_divergence(W: Any, grid: Grid, phys: Physics, limiter: str, riemann: str) -> tuple[Any, Any]:
    """−∇·F of the total (convective + viscous + heat) flux, and the cell-centred ∇·u."""
    G = cell_gradients(W[1:4], grid)
    out = 0.0
    for a in range(grid.ndim):
        F = convective_flux(W, a, phys, limiter, riemann) + viscous_flux(W, G, a, grid, phys)
        out = out - (F - jnp.roll(F, 1, a + 1)) / grid.spacing[a]
    divu = sum(G[b][b] for b in range(grid.ndim))
    return out, divu
