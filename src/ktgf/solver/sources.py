"""Sources: the collisional energy sink −(3/2)ρθζ, ζ = ζ0 + ζ_U∇·u (model.md §1), and a body force.

Both are integrated explicitly with the convective fluxes (the sink implicitly with ``numerics.sink =
"implicit"``, :mod:`.imex`).  Each SSP-RK3 stage is a convex combination of forward-Euler steps, and a
forward-Euler step of dθ/dt = −ζθ keeps θ positive whenever ζΔt < 1: Δt ≤ ``cfl_source/max|ζ|`` (< 1;
:func:`~ktgf.solver.stepping.step_limits`), so the sink alone never makes θ non-positive.  (The explicit part of
the IMEX scheme is not SSP; the same limit applies.)
"""

from __future__ import annotations

from typing import Any

from ..closures.coefficients import Reduced
from .physics import Physics


def cooling_source(W: Any, divu: Any, phys: Physics, r: Reduced) -> tuple[Any, Any]:
    """Energy source −(3/2)ρθζ [W/m³] at the cells, and ζ itself [1/s] (``r``: cell coefficients)."""
    rho, theta = W[0], W[4]
    zeta = phys.cooling_rate(rho, theta, divu, r)
    return -1.5 * rho * theta * zeta, zeta


def add_body_force(dU: Any, W: Any, phys: Physics, scale: Any = 1.0) -> list[Any]:
    """dU (ρ, ρu, E) plus ``scale`` × the momentum source ρg [N/m³] and its power ρg·u [W/m³] (gravity at any
    angle, ``phys.gravity`` = (g_x, g_y, g_z) per unit mass; explicit, like the convective terms; dU without it)."""
    if phys.gravity is None:
        return list(dU)
    force = tuple(W[0] * g for g in phys.gravity)
    power = sum(f * v for f, v in zip(force, W[1:4]))
    return [dU[0], *(d + scale * f for d, f in zip(dU[1:4], force)), dU[4] + scale * power]
