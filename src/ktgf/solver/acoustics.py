"""Implicit acoustics (``numerics.acoustics = "implicit"``): the pressure waves in the implicit part
of the IMEX scheme, so the step is set by the flow speed |u| instead of |u| + c.

Split of the convective flux (docs/solver.md, "Implicit acoustics").  Along axis a with the
face velocity ū = mean of the two cells' u_a, the face density ρ̄, pressure p̄ = mean of ρθp* and
h₀ = (E + p)/ρ, the enthalpy of the step start Uⁿ (frozen for the whole step):

    total      F = ū U_up + (0, p̄ e_a, p̄ ū)                 (U_up: MUSCL state upwind of ū)
    implicit   G = (ρ̄ū, p̄ e_a, h₀ ρ̄ū)                        f_I = −∇·G + viscous + heat
    explicit   F − G = (ū(ρ_up − ρ̄), ū m_up, ū E_up + p̄ū − h₀ρ̄ū)

This is the linear/non-linear split of Giraldo, Kelly & Constantinescu (2013), SIAM J. Sci.
Comput. 35(5), B1162 (§3: f_I the acoustic operator linearised about a reference state, f_E
the rest; here the reference enthalpy is Uⁿ's): linearised about a state at rest the explicit
flux F − G is pure advection with speed ū (mass: an upwind dissipation ū(ρ_up − ρ̄); energy:
ū(E + p) − h₀ρū = 0 to first order), so its Courant limit is |u|Δt/Δx, while G carries the
whole sound speed: ∂ρ/∂t = −∇·m, ∂m/∂t = −∇p, ∂E/∂t = −h₀∇·m give ∂p/∂t = −(∂p/∂ρ|ε +
h₀∂p/∂ε|ρ)∇·m = −c²∇·m with c² = θ(C + 2p*²/3) (:meth:`~.physics.Physics.sound_speed`).

Stage solve (in :func:`~.imex.implicit_stage`): the stage equation U = Û + aΔt f_I(U) with the
pressure of the stage linearised about the latest iterate U_k (Û in the first sweep, whose
predictor holds no compression),

    p(U) ≈ p(U_k) − aΔt ρc² (∇·u − ∇·u_k)        (u_k = 0 in the first sweep)

— the Schur complement of the mass and energy equations, as in the pressure equation of
Kwatra, Su, Grétarsson & Fedkiw (2009), J. Comput. Phys. 228, 4146, eq. (10) — turns the momentum
equation into the viscous one with the extra bulk viscosity λ_ac = aΔtρc²:

    ρ_k u − aΔt∇·τ[η, λ_b + λ_ac](u) = m̂ − aΔt∇(p(U_k) + λ_ac∇·u_k)

(a Helmholtz problem (I − (aΔt)²c²∇∇·)u for the compressive part, solved by the same BiCGSTAB
with the same FFT preconditioner: :func:`~.imex.momentum_preconditioner` handles any bulk
viscosity).  The face divergence is the compact one of the viscous stress (two-point normal
derivative), so the pressure correction does not decouple odd and even cells.  Then mass and
energy follow conservatively: ρ = ρ̂ − aΔt∇·(ρ̄ū), E = Ê − aΔt∇·(h₀ρ̄ū) + viscous and heat (the heat
problem solved for θ at the new ρ).  At least two sweeps: the second linearises about the first
sweep's state, so that a steady state of the scheme is a steady state of f_E + f_I (with one
sweep the pressure of the predictor Û, which lacks the implicit heating, would bias it).

Boundaries: periodic, walls (no flux of mass or energy through a wall face, where the momentum
flux is the pressure of the extrapolated ghost state plus the viscous wall stress) and Lees–Edwards.
Across a Lees–Edwards boundary the face fluxes of both parts are mapped to the lower image as the
explicit fluxes are (:func:`~.boundaries.lees_edwards_faces`), and the Galilean change makes the
implicit mass flux carry flow momentum, −Uρ̄ū e_f (U = γ̇L_a): that term is linear in u and sits in the
momentum operator of the stage solve (:func:`implicit_fluxes`).  (h₀'s ghost cells are the image's, not
shifted to the box's frame: h₀ multiplies ρ̄ū in both parts, so the frame changes the split only at O(Δt),
which tests/solver/test_solver_acoustic.py did not resolve.)
"""

from __future__ import annotations

from typing import Any, NamedTuple

import jax
import jax.numpy as jnp

from .boundaries import lees_edwards_faces
from .fluxes import cell_divergence, face_divergence, face_mean, has_walls, materialise, pad_fields, reconstruct
from .grid import Grid
from .physics import Physics
from .state import conservative_fields, primitive_fields

MODES = ("explicit", "implicit")
#: Picard sweeps of an implicit-acoustics stage at least (module docstring).
MIN_SWEEPS = 2


class AcousticStage(NamedTuple):
    """What the implicit stage needs beyond the viscous problem: the frozen enthalpy h₀ = (E+p)/ρ of
    the step start (cells) and the closures as a function of the primitive fields (to re-evaluate
    p* at the density of a sweep)."""

    enthalpy: Any
    coefficients: Any


def pressure(rho: Any, theta: Any, r: Any, phys: Physics) -> Any:
    """p = ρθp* of the convective flux (with a frictional pressure if the model has one)."""
    return rho * theta * phys.eos(rho, theta, r)[0]


def enthalpy(U: Any, r: Any, phys: Physics) -> Any:
    """h = (E + p)/ρ at the cells."""
    W = primitive_fields(U)
    return (U[4] + pressure(W[0], W[4], r, phys)) / W[0]


def _wall_faces(F: list[Any], grid: Grid, a: int) -> list[Any]:
    """Face fluxes along ``a`` with the two wall faces set to 0 when ``a`` is a wall axis."""
    if not (has_walls(grid) and a in grid.boundaries.wall_axes):
        return F
    n = grid.cells[a]

    def zero_ends(f: Any) -> Any:
        zero = jnp.zeros_like(jax.lax.slice_in_dim(f, 0, 1, axis=a))
        return jnp.concatenate([zero, jax.lax.slice_in_dim(f, 1, n, axis=a), zero], axis=a)

    return [f if jnp.ndim(f) == 0 else zero_ends(f) for f in F]


def advective_divergence(W: tuple, eos: tuple, h0: Any, grid: Grid, limiter: str, t: Any = 0.0) -> tuple[list, Any]:
    """−∇·(F − G), the explicit part of the convective flux (module docstring), and the cell ∇·u."""
    p_cell = W[0] * W[4] * eos[0]
    P = pad_fields((*W, p_cell, h0), grid, t, velocity=1)
    out: list[Any] = [0.0] * 5
    for a in range(grid.ndim):
        WL, WR = materialise(reconstruct(P[:5], grid.cells, a, limiter))
        ubar = face_mean(P[1 + a], grid.cells, a)
        up = [jnp.where(ubar > 0.0, l, r) for l, r in zip(conservative_fields(WL), conservative_fields(WR))]
        m_bar = face_mean(P[0], grid.cells, a) * ubar  # ρ̄ū
        F = [ubar * up[0] - m_bar, ubar * up[1], ubar * up[2], ubar * up[3],
             ubar * (up[4] + face_mean(P[5], grid.cells, a)) - face_mean(P[6], grid.cells, a) * m_bar]
        F = lees_edwards_faces(_wall_faces(F, grid, a), grid, a, t)
        dF = face_divergence(jnp.stack(F), grid, a)
        out = [o + dF[i] for i, o in enumerate(out)]
    return out, cell_divergence(P[1:4], grid)


def pressure_divergence(P_faces: list[Any], grid: Grid, t: Any = 0.0) -> list[Any]:
    """−∇P per momentum component from face pressures along each axis (conservative; a Lees–Edwards face
    takes its image's pressure, as every flux there)."""
    out: list[Any] = [0.0, 0.0, 0.0]
    for a in range(grid.ndim):
        F: list[Any] = [0.0] * 5
        F[1 + a] = P_faces[a]
        out[a] = out[a] + face_divergence(lees_edwards_faces(F, grid, a, t)[1 + a][None], grid, a)[0]
    return out


def implicit_fluxes(rho: Any, u: tuple, h0: Any, grid: Grid, t: Any = 0.0,
                    walls: Any = None, affine: bool = True) -> tuple[Any, list[Any], Any]:
    """(−∇·(ρ̄ū), momentum, −∇·(h₀ρ̄ū)): the implicit mass and energy parts of the convective flux at (ρ, u),
    and the flow momentum −Uρ̄ū e_f that the mass flux carries across a Lees–Edwards boundary (module
    docstring; three zeros elsewhere).  ``h0`` None: the energy is not computed (0).  ``affine=False``: u
    padded without the boundary's velocity jump, which ρ̄ū does not see (so that the map is linear in u)."""
    # ρ apart from u: one optimisation barrier over both would make ρ look linear in u to the Krylov solve
    P = (*pad_fields((rho,), grid, t, walls=walls), *pad_fields(u, grid, t, velocity=0, walls=walls, affine=affine))
    H = pad_fields((h0,), grid, t, walls=walls)[0] if h0 is not None else None
    sheared = grid.boundaries is not None and grid.boundaries.shear_axis is not None
    d_rho, d_m, d_E = 0.0, [0.0, 0.0, 0.0], 0.0
    for a in range(grid.ndim):
        m = face_mean(P[0], grid.cells, a) * face_mean(P[1 + a], grid.cells, a)  # ρ̄ū (walls: ū = 0 by the ghosts)
        zero = jnp.zeros(m.shape, m.dtype) if sheared else 0.0  # an array, so the Galilean change can fill it
        F = lees_edwards_faces(_wall_faces([m, zero, zero, zero, face_mean(H, grid.cells, a) * m if H is not None
                                            else zero], grid, a), grid, a, t)
        d_rho = d_rho + face_divergence(F[0][None], grid, a)[0]
        d_E = d_E + (face_divergence(F[4][None], grid, a)[0] if H is not None else 0.0)
        if sheared and a == grid.boundaries.shear_axis:
            f = grid.boundaries.flow
            d_m[f] = d_m[f] + face_divergence(F[1 + f][None], grid, a)[0]
    return d_rho, d_m, d_E
