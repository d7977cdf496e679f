"""Steady homogeneous (Lees–Edwards) shear: one solver and one result type, frictionless and frictional.

The closed forms of model.md §9.  In uniform shear at rate γ̇ the energy balance η γ̇² = (3/2)ρθζ0
fixes the temperature.  With a* = γ̇/ν0 and the reduced coefficients (ρθ/η0 = ν0):

    a*² = 3ζ0*/(2η*),   |P_xy|/p = η* a*/p*,   θ/(γ̇d)² = 25π/(9216 φ² a*²) = 25π η*/(13824 φ² ζ0*).

With a dissipation correction of extended kinetic theory (:mod:`ktgf.closures.dissipation`),
ζ0* → ζ0* d/L with L/d = max(1, Λ s) and s = dγ̇/√θ = k a*, k = (96/5) φ/√π.  The energy
balance is then solved consistently: a*² = 3ζ0*/(2η* max(1, Λ k a*)), whose root is

    a* = a0                        if Λ k a0 ≤ 1   (L = d, the standard theory),
    a* = (a0²/(Λ k))^(1/3)         otherwise,       a0 = √(3ζ0*/(2η*)).

A model's friction part (:mod:`ktgf.closures.friction`) enters through its ζ0 (the factor
(1 − e_eff²)/(1 − e²)), T_rot/T, an optional enduring-contact stress w p_f with
τ_f = (τ_f/p_f) w p_f of unregularised simple shear, its work dissipated without feeding θ, and an
optional collisional stress of the tangential impulses (``tangential_stress``, docs/friction.md §7.1): Δη*
in η*, of whose work the part Δη*_loss (:meth:`~ktgf.closures.models.Model.tangential_work_loss`) is
dissipated, so the energy balance above has η* − Δη*_loss where it has η*.
Frictionless models give their Navier–Stokes uniform shear unchanged.

:class:`ShearState` is in the columns of the DEM files (``ktgf.data``, d = m = 1, γ̇ = 1):
T = θ/(γ̇d)², Trot_over_T, p_star = p/(ρ_s d² γ̇²) = φ p* T, tau_over_p = |P_xy|/p,
p_over_nT = p*, eta_star = η d²/√(mT) = (5/(16√π)) η*, eta_over_eta0 = η*, astar = γ̇/ν0
with ν0 = (16/5)√π n √T, and L_over_d.  Kinetic shear stress τ/(ρ_s d² γ̇²) = (5√π/96) η* √T.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from .._array import asarray, namespace
from ..closures.coefficients import SHEAR_PER_ASTAR
from ..closures.models import Model
from ..errors import InputError

#: η0 d²/√(mT) = 5/(16√π): converts η* = η/η0 to the DEM file's η d²/√(mT).
ETA0_DEM = 5.0 / (16.0 * math.sqrt(math.pi))
#: τ/(ρ_s d² γ̇²) = ETA0_CONSTANT η* √T, with η0 = (5√π/96) ρ_s d √θ (model.md §1).
ETA0_CONSTANT = 5.0 * math.sqrt(math.pi) / 96.0


class ShearState(NamedTuple):
    """Steady uniform shear in the DEM files' columns (arrays broadcast over φ and e)."""

    phi: Any
    T: Any
    Trot_over_T: Any
    p_star: Any
    tau_over_p: Any
    p_over_nT: Any
    eta_star: Any
    eta_over_eta0: Any
    astar: Any
    L_over_d: Any

def _solve(model: Any, phi: Any, e: Any, check: bool = True) -> tuple[Any, Any, Any, Any]:
    """(reduced coefficients without shear, a*, L/d, η*) of the steady uniform shear.

    NumPy in, NumPy out; JAX values pass through, so with ``check=False`` (options that are JAX
    tracers have no value to check) ``jax.jacfwd`` differentiates it exactly (used by calibration).
    """
    phi, e = asarray(phi), asarray(e)
    r = model.reduced(phi, e, check=check)
    a, length = _balance(model, phi, e, r, None)
    if getattr(model.rdf, "shear_dependent", False):
        # χ(φ, s) with s = dγ̇/√θ = k0 φ a*: the balance's a* moves χ, which moves a*; a fixed point, contracting
        # (docs/dense_physics.md §8), iterated a fixed number of times so that JAX traces it
        for _ in range(STRUCTURE_ITERATIONS):
            s = SHEAR_PER_ASTAR * phi * a
            r = model.reduced(phi, e, check=False, chi_shear=s)
            a, length = _balance(model, phi, e, r, s)
    return r, a, length, r.eta


#: Fixed-point iterations of steady uniform shear with a shear-dependent χ (converged to round-off: tested).
STRUCTURE_ITERATIONS = 40


def _balance(model: Any, phi: Any, e: Any, r: Any, chi_shear: Any) -> tuple[Any, Any]:
    """(a*, L/d) from the energy balance (3/2)ζ0 d/L = (η* − Δη*_loss) a*² with the EKT length L/d = max(1, Λ k0 φ a*)."""
    xp = namespace(phi, e)
    a0 = (1.5 * r.zeta0 / (r.eta - model.tangential_work_loss(e, r.lambda_b))) ** 0.5
    lam = model.dissipation.coefficient(phi, e, model.chi(phi, chi_shear))
    k = SHEAR_PER_ASTAR * phi
    x = lam * k * a0
    correlated = xp.isfinite(x) & (x > 1.0)
    safe = xp.where(correlated, lam * k, 1.0)
    a = xp.where(correlated, (a0**2 / safe) ** (1.0 / 3.0), a0)
    return a, xp.where(correlated, lam * k * a, 1.0)


def steady_temperature(model: Model, phi: Any, e: Any, *, check: bool = True) -> Any:
    """T = θ/(γ̇d)² of steady uniform shear (the energy balance alone: a frictional stress's work does not feed θ).

    The same number as ``steady_shear(...).T`` without a dense-temperature floor, for callers that need the
    temperature scale of a flow (Couette and chute starts, 3D base states, stability) and no stress scale.
    """
    _, a, _, _ = _solve(model, phi, e, check)
    return 25.0 * math.pi / (9216.0 * asarray(phi) ** 2 * a**2)


def steady_shear(model: Model, phi: Any, e: Any, *, stress_scale: float | None = None,
                 dense_temperature: Any = None, check: bool = True) -> ShearState:
    """Steady uniform shear of ``model`` at solid fraction φ and restitution e < 1 (module docstring).

    NumPy in, NumPy out; JAX values pass through (with ``check=False`` — options that are JAX tracers
    have no value to check — ``jax.jacfwd`` differentiates it exactly).  A model with a frictional
    stress needs ``stress_scale`` = ρ_s d² γ̇² [Pa]; ``dense_temperature`` (e.g.
    :class:`~ktgf.closures.friction.DenseInertialTemperature`) floors T.  Raises
    :class:`~ktgf.errors.InputError` for e outside (0, 1) and φ outside [0, φ_max).
    """
    friction = model.friction
    if check:
        if np.any(~((np.asarray(e) > 0.0) & (np.asarray(e) < 1.0))):
            bad = float(np.asarray(e, dtype=float).ravel()[~((np.asarray(e) > 0.0) & (np.asarray(e) < 1.0)).ravel()][0])
            raise InputError(f"restitution coefficient e = {bad:g} is out of range: valid 0 < e < 1 "
                             "(uniform shear needs dissipation)")
        if friction.has_stress and stress_scale is None:
            raise InputError(f"model {model.name!r} has a frictional stress (stress = {friction.stress!r}): give the "
                             "stress scale rho_s d^2 gdot^2 in Pa (ktgf shear --stress-scale)")
        if stress_scale is not None and not stress_scale > 0.0:
            raise InputError(f"stress scale = {stress_scale:g} is out of range: valid stress_scale > 0 (Pa)")
    r, a, length, eta = _solve(model, phi, e, check)
    phi = asarray(phi)
    xp = namespace(phi, a)
    T = 25.0 * math.pi / (9216.0 * phi**2 * a**2)  # as steady_temperature
    if dense_temperature is not None:
        T = xp.maximum(T, dense_temperature.temperature_ratio(phi, model.phi_max))
    p_star, p_over_nT, tau_over_p = phi * r.p * T, r.p + 0.0 * T, eta * a / r.p
    if dense_temperature is not None:  # the kinetic stress ratio no longer follows from a* alone
        tau_over_p = ETA0_CONSTANT * eta * xp.sqrt(T) / p_star
    if friction.has_stress:
        p_f = friction.frictional_pressure(phi, model.phi_max) / stress_scale
        tau_over_p, p_star, p_over_nT = add_frictional_stress(tau_over_p, p_star, p_over_nT, phi * T, p_f,
                                                              friction.simple_shear_stress_ratio(T))
    rot = friction.rotational_ratio(e, 1.0 / T)  # the shear measure s = γ̇d/√θ is 1/√T here
    trot = T * math.nan if rot is None else rot + 0.0 * T
    return ShearState(phi=phi + 0.0 * T, T=T, Trot_over_T=trot, p_star=p_star, tau_over_p=tau_over_p + 0.0 * T,
                      p_over_nT=p_over_nT, eta_star=ETA0_DEM * eta + 0.0 * T, eta_over_eta0=eta + 0.0 * T,
                      astar=a + 0.0 * T, L_over_d=length + 0.0 * T)


def add_frictional_stress(tau_over_p: Any, p_star: Any, p_over_nT: Any, phi_T: Any, p_f: Any, ratio: Any) -> tuple[Any, Any, Any]:
    """(τ/p, p*, p/(nT)) with a frictional pressure p_f (in units of ρ_s d² γ̇²) and its τ_f = ratio p_f added.

    Where p_f = 0 the kinetic values are returned bit for bit.
    """
    xp = namespace(p_star, p_f)
    total = p_star + p_f
    tau = xp.where(p_f > 0.0, (tau_over_p * p_star + ratio * p_f) / total, tau_over_p)
    return tau, total, p_over_nT + p_f / phi_T
