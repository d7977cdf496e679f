"""Conservative and primitive variables of the granular gas.

Conservative state ``U`` (array of shape ``(5, *grid.cells)``, or inside kernels a tuple of
five field arrays — XLA fuses separate fields better than slices of one stacked array):

    U = (ρ, ρu_x, ρu_y, ρu_z, E),   E = ρ(|u|²/2 + 3θ/2)

with ρ = ρ_s φ the bulk density [kg/m³], u the mean velocity [m/s] and θ the granular
temperature per unit mass [m²/s²] (model.md §1).  Primitive state ``W`` = (ρ, u_x, u_y, u_z, θ).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import jax.numpy as jnp

NVAR = 5
#: Names of the primitive components (for diagnoses).
PRIMITIVE_NAMES = ("density", "velocity_x", "velocity_y", "velocity_z", "temperature")


def _ke(u: Sequence[Any]) -> Any:
    return 0.5 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2])


def conservative_fields(W: Sequence[Any]) -> tuple[Any, ...]:
    """(ρ, ρu_x, ρu_y, ρu_z, E) from primitive fields (ρ, u_x, u_y, u_z, θ)."""
    rho, u, theta = W[0], W[1:4], W[4]
    return (rho, rho * u[0], rho * u[1], rho * u[2], rho * (_ke(u) + 1.5 * theta))


def primitive_fields(U: Sequence[Any]) -> tuple[Any, ...]:
    """(ρ, u_x, u_y, u_z, θ) from conservative fields."""
    inv = 1.0 / U[0]
    u = (U[1] * inv, U[2] * inv, U[3] * inv)
    return (U[0], *u, (U[4] * inv - _ke(u)) / 1.5)


def conservative(rho: Any, u: Any, theta: Any) -> Any:
    """Stacked conservative state (5, ...) from density, velocity (3, ...) and temperature."""
    return jnp.stack(conservative_fields((jnp.asarray(rho), *jnp.asarray(u), jnp.asarray(theta))))


def primitive(U: Any) -> Any:
    """Stacked primitive state (ρ, u_x, u_y, u_z, θ) of a stacked conservative state."""
    return jnp.stack(primitive_fields(U))

