"""The granular-gas physics the solver needs, all taken from a closure :class:`~ktgf.closures.Model`.

Nothing here depends on which model is used: every coefficient is the model's reduced one
(``Model.reduced(φ, e, check=False)``) times the reference scales of model.md §1
(:mod:`ktgf.closures.coefficients`).  Glossary: ``phi`` solid fraction, ``rho`` = ρ_s φ bulk
density, ``theta`` granular temperature per unit mass, ``r`` a :class:`~ktgf.closures.Reduced`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import jax
import jax.numpy as jnp

from ..closures.coefficients import Reduced, eta0, nu0
from ..closures.models import Model


@jax.tree_util.register_pytree_node_class
@dataclass(frozen=True)
class Physics:
    """Closure model plus the particle properties.

    A JAX pytree: the model is static (it selects the closure functions), the numbers are
    traced leaves, so changing e, d or ρ_s does not recompile.

    Parameters
    ----------
    model : Model
        Closure model (``ktgf.get_model(name)``).
    restitution : float
        Normal restitution coefficient e.
    diameter : float
        Particle diameter d [m].
    material_density : float
        Material density ρ_s [kg/m³].
    phi_stop : float
        A run stops with a diagnosis once any cell reaches this solid fraction.
    gravity : tuple of 3 floats or None
        Body force per unit mass g [m/s²] (None: none; :func:`~ktgf.solver.sources.body_force`).
    """

    model: Model
    restitution: float
    diameter: float
    material_density: float
    phi_stop: float
    gravity: Any = None

    def tree_flatten(self) -> tuple[tuple, Model]:
        return (self.restitution, self.diameter, self.material_density, self.phi_stop, self.gravity), self.model

    @classmethod
    def tree_unflatten(cls, model: Model, leaves: tuple) -> Physics:
        return cls(model, *leaves)

    def reduced(self, rho: Any) -> Reduced:
        """Reduced coefficients at bulk density ρ (φ = ρ/ρ_s), unchecked (jit-safe)."""
        phi = rho / self.material_density
        e = jnp.asarray(self.restitution, dtype=phi.dtype)
        return self.model.reduced(phi, e, check=False)

    def pressure(self, rho: Any, theta: Any, r: Reduced) -> Any:
        """Equation of state p = ρθp*(φ) [Pa] (model.md §1)."""
        return rho * theta * r.p

    def sound_factor(self, r: Reduced) -> Any:
        """g = C + 2p*²/3, so that c² = θ g (a function of φ alone, reconstructed to faces)."""
        return r.C + (2.0 / 3.0) * r.p * r.p

    def sound_speed(self, theta: Any, r: Reduced) -> Any:
        """Adiabatic sound speed c = √(θ(C + 2p*²/3)) [m/s].

        From c² = (∂p/∂ρ)_e + (p/ρ²)(∂p/∂e)_ρ with p = ρθp*(φ), e = 3θ/2 and
        C = ∂(φp*)/∂φ.
        """
        return jnp.sqrt(theta * self.sound_factor(r))

    def transport(self, rho: Any, theta: Any, r: Reduced) -> tuple[Any, Any, Any, Any]:
        """(η, λ_b, κ, ω) in SI at states (ρ, θ): η0 times the reduced values, ω = θκ0μ*/φ."""
        e0 = eta0(theta, self.diameter, self.material_density)
        phi = rho / self.material_density
        k0 = 3.75 * e0
        return e0 * r.eta, e0 * r.lambda_b, k0 * r.kappa, theta * k0 * r.mu / phi

    def cooling_rate(self, rho: Any, theta: Any, divu: Any, r: Reduced) -> Any:
        """ζ = ζ0 + ζ_U ∇·u [1/s] with ζ0 = ν0(φ, θ) ζ0*(φ) (model.md §1)."""
        phi = rho / self.material_density
        return nu0(phi, theta, self.diameter) * r.zeta0 + r.zeta_u * divu
