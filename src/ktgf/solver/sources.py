"""Collisional energy sink −(3/2)ρθζ, ζ = ζ0 + ζ_U∇·u (model.md §1).

The sink is integrated together with the fluxes by the SSP Runge–Kutta scheme.  Each SSP
stage is a convex combination of forward-Euler steps, and a forward-Euler step of
dθ/dt = −ζθ keeps θ positive whenever ζΔt < 1; :func:`~ktgf.solver.stepping.stable_dt`
limits Δt by ``cfl_source/max|ζ|`` (< 1), so the sink alone can never make θ non-positive.
"""

from __future__ import annotations

from typing import Any

from .physics import Physics


def cooling_source(W: Any, divu: Any, phys: Physics) -> tuple[Any, Any]:
    """Energy source −(3/2)ρθζ [W/m³] at the cells, and ζ itself [1/s]."""
    rho, theta = W[0], W[4]
    zeta = phys.cooling_rate(rho, theta, divu, phys.reduced(rho))
    return -1.5 * rho * theta * zeta, zeta

