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
        Body force per unit mass g [m/s²] (None: none; :func:`~ktgf.solver.sources.add_body_force`).
    hcs : bool
        The case is a freely cooling gas: the closures' homogeneous-cooling dissipation
        (``Model.reduced(hcs=True)``, frictional models: rotation at its HCS ratio) instead of the
        steady-shear one of the sheared cases (static; :meth:`ktgf.solver.cases.Case.physics`).
    shear_rate_scale : float
        γ̇_ref [1/s] of the case (U/H, Lees–Edwards γ̇): the scale of the frictional viscosity's
        regularisation ε γ̇_ref (``docs/friction.md`` §8; 0 for a case without one).

    The cell coefficients ``r`` of the methods are the model's :class:`~ktgf.closures.Reduced` or,
    for a model with a frictional stress, a :class:`~ktgf.solver.friction.FrictionalReduced`
    (the same fields plus the frictional pressure, viscosity and work at the cells), which the
    methods below add to the kinetic-theory ones.
    """

    model: Model
    restitution: float
    diameter: float
    material_density: float
    phi_stop: float
    gravity: Any = None
    hcs: bool = False
    shear_rate_scale: float = 0.0

    def tree_flatten(self) -> tuple[tuple, tuple]:
        leaves = (self.restitution, self.diameter, self.material_density, self.phi_stop, self.gravity,
                  self.shear_rate_scale)
        if self._static_restitution:
            return leaves[1:], (self.model, self.hcs, self.restitution)
        return leaves, (self.model, self.hcs)

    @classmethod
    def tree_unflatten(cls, aux: tuple, leaves: tuple) -> Physics:
        model, hcs, *e = aux
        *first, rate = (*e, *leaves)
        return cls(model, *first, hcs=hcs, shear_rate_scale=rate)

    @property
    def _static_restitution(self) -> bool:
        """Frictional collisions (μ > 0): e is static, so that the friction part's restitution law (a
        SciPy quadrature) is evaluated once on the host at trace time, not through a host callback."""
        return self.model.friction.mu > 0.0

    def reduced(self, rho: Any, shear: Any = None) -> Reduced:
        """Reduced coefficients at bulk density ρ (φ = ρ/ρ_s), unchecked (jit-safe).

        ``shear``: the local dγ̇/√θ of a dissipation correction (sheared cases,
        :func:`~ktgf.solver.friction.cell_coefficients`); the cooling case takes the HCS dissipation.
        """
        phi = rho / self.material_density
        e = float(self.restitution) if self._static_restitution else jnp.asarray(self.restitution, dtype=phi.dtype)
        if self.hcs:
            return self.model.reduced(phi, e, check=False, hcs=True)
        return self.model.reduced(phi, e, check=False, shear=shear)

    def pressure(self, rho: Any, theta: Any, r: Reduced) -> Any:
        """Equation of state p = ρθp*(φ) [Pa] (model.md §1), plus the frictional pressure w p_f if any."""
        p = rho * theta * r.p
        return p + r.p_f if is_frictional(r) else p

    def eos(self, rho: Any, theta: Any, r: Reduced) -> tuple[Any, Any]:
        """(p*, g) of the convective flux, p = ρθp* and c² = θg; with a frictional stress
        p* + w p_f/(ρθ) and g + c_f²/θ (c_f² = d(w p_f)/dρ), so that both include it."""
        g = self.sound_factor(r)
        if not is_frictional(r):
            return r.p, g
        return r.p + r.p_f / (rho * theta), g + r.c2_f / theta

    def sound_factor(self, r: Reduced) -> Any:
        """g = C + 2p*²/3, so that c² = θ g (a function of φ alone, reconstructed to faces)."""
        return r.C + (2.0 / 3.0) * r.p * r.p

    def sound_speed(self, theta: Any, r: Reduced) -> Any:
        """Adiabatic sound speed c = √(θ(C + 2p*²/3)) [m/s].

        From c² = (∂p/∂ρ)_e + (p/ρ²)(∂p/∂e)_ρ with p = ρθp*(φ), e = 3θ/2 and
        C = ∂(φp*)/∂φ.
        """
        c2 = theta * self.sound_factor(r)
        return jnp.sqrt(c2 + r.c2_f if is_frictional(r) else c2)

    def transport(self, rho: Any, theta: Any, r: Reduced) -> tuple[Any, Any, Any, Any]:
        """(η, λ_b, κ, ω) in SI at states (ρ, θ): η0 times the reduced values, ω = θκ0μ*/φ."""
        e0 = eta0(theta, self.diameter, self.material_density)
        phi = rho / self.material_density
        k0 = 3.75 * e0
        eta = e0 * r.eta + r.mu_f if is_frictional(r) else e0 * r.eta  # μ_f frozen with r (docs/friction.md §7)
        return eta, e0 * r.lambda_b, k0 * r.kappa, theta * k0 * r.mu / phi

    def cooling_rate(self, rho: Any, theta: Any, divu: Any, r: Reduced) -> Any:
        """ζ = ζ0 + ζ_U ∇·u [1/s] with ζ0 = ν0(φ, θ) ζ0*(φ) (model.md §1).

        With a frictional stress also its work, −σ_f:∇u/((3/2)ρθ) (``r.zeta_f`` and the p_f part
        of ``r.zeta_u``, :class:`~ktgf.solver.friction.FrictionalReduced`): dissipated at the contacts.
        """
        zeta = nu0(rho / self.material_density, theta, self.diameter) * r.zeta0 + r.zeta_u * divu
        return zeta + r.zeta_f if is_frictional(r) else zeta


def is_frictional(r: Any) -> bool:
    """Whether the cell coefficients carry a frictional stress (static: decided by the pytree's type)."""
    return hasattr(r, "mu_f")
