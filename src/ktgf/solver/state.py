"""Conservative and primitive variables of the granular gas.

Conservative state ``U`` (array of shape ``(5, *grid.cells)``):

    U = (ρ, ρu_x, ρu_y, ρu_z, E),   E = ρ(|u|²/2 + 3θ/2)

with ρ = ρ_s φ the bulk density [kg/m³], u the mean velocity [m/s] and θ the granular
temperature per unit mass [m²/s²] (model.md §1).  Primitive state ``W`` = (ρ, u_x, u_y, u_z, θ).
"""

from __future__ import annotations

from typing import Any

import jax.numpy as jnp

NVAR = 5
#: Names of the conservative and primitive components (for output and diagnoses).
CONSERVATIVE_NAMES = ("density", "momentum_x", "momentum_y", "momentum_z", "total_energy")
PRIMITIVE_NAMES = ("density", "velocity_x", "velocity_y", "velocity_z", "temperature")


def conservative(rho: Any, u: Any, theta: Any) -> Any:
    """Stack (ρ, ρu, E) from density, velocity (3, ...) and temperature."""
    rho = jnp.asarray(rho)
    u = jnp.asarray(u)
    energy = rho * (0.5 * jnp.sum(u * u, axis=0) + 1.5 * theta)
    return jnp.concatenate([rho[None], rho[None] * u, energy[None]], axis=0)


def primitive(U: Any) -> Any:
    """(ρ, u_x, u_y, u_z, θ) from the conservative state (works on any leading shape ``(5, ...)``)."""
    rho = U[0]
    u = U[1:4] / rho
    theta = (U[4] / rho - 0.5 * jnp.sum(u * u, axis=0)) / 1.5
    return jnp.concatenate([rho[None], u, theta[None]], axis=0)


def from_primitive(W: Any) -> Any:
    """Inverse of :func:`primitive`."""
    return conservative(W[0], W[1:4], W[4])
