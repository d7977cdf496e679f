"""Containers for transport coefficients and the reference scales that give them units.

Reduced coefficients are computed once per theory; SI values are the reduced ones times the
reference scales of ``model.md`` §1 — this module is the one place where units enter.

Reference scales (dilute elastic Chapman–Enskog, first Sonine), per unit mass temperature θ:

    η0 = (5√π/96) ρ_s d √θ          κ0 = (15/4) η0          ν0 = (96/5)(φ/d) √(θ/π)
    ℓ  = √(2θ)/ν0 = 5√(2π) d/(96 φ)
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from .._array import namespace

SQRT_PI = math.sqrt(math.pi)
#: ℓ φ / d = 5√(2π)/96, the mean-free-path constant of model.md §1.
MEAN_FREE_PATH_CONSTANT = 5.0 * math.sqrt(2.0 * math.pi) / 96.0
#: s = dγ̇/√θ = SHEAR_PER_ASTAR · φ · a*, a* = γ̇/ν0 the reduced shear rate (from ν0 above).
SHEAR_PER_ASTAR = 96.0 / (5.0 * math.sqrt(math.pi))


class Reduced(NamedTuple):
    """Dimensionless (reduced) coefficients of one closure set at states (φ, e).

    Attributes
    ----------
    p : p* = p/(ρθ), compressibility factor.
    eta : η* = η/η0, shear viscosity.
    lambda_b : λ_b* = λ_b/η0, bulk viscosity.
    kappa : κ* = κ/κ0, thermal conductivity (flux per ∇θ).
    mu : μ* = φω/(θκ0), density-gradient heat-flux coefficient.
    zeta0 : ζ0* = ζ0/ν0, cooling rate.
    zeta_u : ζ_U, coefficient of ∇·u in the cooling rate (dimensionless).
    g : ∂ln ζ0/∂ln n at fixed θ (the HCS stability matrix needs it).
    C : ∂(φ p*)/∂φ (the HCS stability matrix needs it).
    """

    p: Any
    eta: Any
    lambda_b: Any
    kappa: Any
    mu: Any
    zeta0: Any
    zeta_u: Any
    g: Any
    C: Any


class Dimensional(NamedTuple):
    """SI coefficients at states (φ, e, θ) for particles of diameter d and density ρ_s.

    Attributes
    ----------
    p : pressure [Pa].
    eta : shear viscosity [Pa s].
    lambda_b : bulk viscosity [Pa s].
    kappa : conductivity per ∇θ [kg/(m s)], so that q = −κ∇θ − ω∇φ is in W/m².
    omega : density-gradient coefficient [W/m] (per ∇φ).
    zeta0 : cooling rate [1/s].
    zeta_u : coefficient of ∇·u in ζ [–].
    """

    p: Any
    eta: Any
    lambda_b: Any
    kappa: Any
    omega: Any
    zeta0: Any
    zeta_u: Any


def eta0(theta: Any, d: Any, rho_s: Any) -> Any:
    """Dilute elastic viscosity η0 = (5√π/96) ρ_s d √θ [Pa s] (model.md §1)."""
    xp = namespace(theta)
    return (5.0 * SQRT_PI / 96.0) * rho_s * d * xp.sqrt(theta)


def kappa0(theta: Any, d: Any, rho_s: Any) -> Any:
    """Dilute elastic conductivity per ∇θ, κ0 = (15/4) η0 (model.md §1)."""
    return 3.75 * eta0(theta, d, rho_s)


def nu0(phi: Any, theta: Any, d: Any) -> Any:
    """Collision-frequency scale ν0 = ρθ/η0 = (96/5)(φ/d)√(θ/π) [1/s] (model.md §1)."""
    xp = namespace(phi, theta)
    return (96.0 / 5.0) * (phi / d) * xp.sqrt(theta / math.pi)


def mean_free_path(phi: Any, d: Any) -> Any:
    """Length scale ℓ = √(2θ)/ν0 = 5√(2π) d/(96 φ) [m] (model.md §1)."""
    return MEAN_FREE_PATH_CONSTANT * d / phi


def to_dimensional(r: Reduced, phi: Any, theta: Any, d: Any, rho_s: Any) -> Dimensional:
    """Multiply reduced coefficients by the reference scales of model.md §1.

    ω = θκ0μ*/φ is singular as φ → 0 unless μ* = 0; it is returned as 0 where μ* = 0 and
    ``inf`` at φ = 0 otherwise (the term ω∇φ = θκ0μ*∇ln φ has a logarithmic singularity).
    """
    xp = namespace(phi, theta, r.p)
    e0 = eta0(theta, d, rho_s)
    k0 = 3.75 * e0
    safe_phi = xp.where(phi > 0, phi, 1.0)
    omega = xp.where(r.mu == 0, 0.0, xp.where(phi > 0, theta * k0 * r.mu / safe_phi, xp.inf))
    return Dimensional(
        p=rho_s * phi * theta * r.p,
        eta=e0 * r.eta,
        lambda_b=e0 * r.lambda_b,
        kappa=k0 * r.kappa,
        omega=omega,
        zeta0=nu0(phi, theta, d) * r.zeta0,
        zeta_u=r.zeta_u,
    )
