"""Frictional uniform shear as compositions of parts, and the μ(I) alternative.

A :class:`FrictionalShearParts` composes a frictionless closure model with frictional parts
(:mod:`ktgf.closures.friction`):

1. an RDF whose divergence is moved to the frictional jamming fraction φ_c(μ) (RDFs without a
   divergence point, e.g. Carnahan–Starling, are used unchanged);
2. the collisional dissipation of an effective restitution, ζ0* → ζ0* (1 − e_eff²)/(1 − e²); pressure
   and viscosity keep e;
3. optionally the dense-inertial temperature floor of Chialvo & Sundaresan (2013),
   θ/(γ̇d)² = max(kinetic value, α1/√(φ_c − φ));
4. optionally a frictional (enduring-contact) stress p_f, τ_f = p_f × (τ/p)_f, weighted by a blend
   w(φ), added to the kinetic stress; its work is taken to be dissipated without feeding θ.

It is turned into a registry model with that friction part and solved by
:func:`~ktgf.shear.steady.steady_shear`.  At μ = 0 every part reduces to the frictionless model (tested).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..closures.friction import (
    ChialvoSundaresanRestitution,
    FrictionalChialvoSundaresan,
    JammingFraction,
    RoughSphereRestitution,
    SchaefferViscosity,
    WaltonRestitution,
    with_jamming_fraction,
)
from ..closures.friction._part import check_friction_coefficient
from ..closures.friction.model_slot import Friction
from ..closures.models import Model, get_model
from ..errors import InputError
from .steady import ShearState, add_frictional_stress, steady_shear


@dataclass(frozen=True)
class FrictionalShearParts:
    """The parts of a frictional uniform-shear prediction (a composition, not a registry entry yet).

    Parameters
    ----------
    model : Model
        Frictionless closure model (theory × RDF × viscosity law), e.g. ``get_model("ret")``.
    restitution : law with ``inelasticity(e, mu)`` and ``rotational_ratio(e, mu)``
        :class:`~ktgf.closures.friction.ChialvoSundaresanRestitution` (default) or
        :class:`~ktgf.closures.friction.RoughSphereRestitution`.
    jamming : JammingFraction
        φ_c(μ) for RDF families with a ``phi_c`` field; its φ_rcp is replaced by the RDF's own φ_c so
        that μ = 0 leaves the RDF unchanged.  (A :class:`FrictionalChialvoSundaresan` RDF carries its own.)
    dense_temperature : DenseInertialTemperature or None
        Chialvo–Sundaresan dense-inertial temperature floor (off by default).
    frictional_pressure : JohnsonJacksonPressure or None
        Enduring-contact pressure p_f(φ) [Pa] (off by default).
    frictional_viscosity : SchaefferViscosity or SrivastavaSundaresanViscosity
        Gives τ_f/p_f in simple shear.
    blend : TanhBlend, SigmoidBlend or None
        Weight w(φ) of the frictional stress (None: w = 1).
    stress_scale : float or None
        ρ_s d² γ̇² [Pa] of the flow, needed to express the (SI) p_f in the reduced units; required
        when ``frictional_pressure`` is given.
    """

    model: Model
    restitution: Any = field(default_factory=ChialvoSundaresanRestitution)
    jamming: JammingFraction = field(default_factory=JammingFraction)
    dense_temperature: Any = None
    frictional_pressure: Any = None
    frictional_viscosity: Any = field(default_factory=SchaefferViscosity)
    blend: Any = None
    stress_scale: float | None = None

    def __post_init__(self) -> None:
        if self.frictional_pressure is not None and self.stress_scale is None:
            raise InputError("stress_scale (rho_s d^2 gdot^2 in Pa) is required with a frictional_pressure")
        if self.stress_scale is not None and not self.stress_scale > 0.0:
            raise InputError(f"stress_scale = {self.stress_scale} is out of range: valid stress_scale > 0 (Pa)")

    def model_at(self, mu: float) -> Model:
        """The closure model at friction coefficient μ: its RDF's divergence moved to φ_c(μ)."""
        check_friction_coefficient(mu)
        rdf = self.model.rdf
        if isinstance(rdf, FrictionalChialvoSundaresan) or "mu" in {f.name for f in dataclasses.fields(rdf)}:
            return self.model.replace(rdf=dataclasses.replace(rdf, mu=float(mu)))  # the RDF carries its own φ_J(μ)
        if "phi_c" in {f.name for f in dataclasses.fields(rdf)}:
            jam = dataclasses.replace(self.jamming, phi_rcp=float(rdf.phi_c))
            return self.model.replace(rdf=with_jamming_fraction(rdf, float(mu), jam))
        return self.model


def friction_from_law(law: Any, mu: float, tangential_stress: str = "none") -> Friction:
    """The model's ``friction`` part for a restitution-law object at μ (flat options, see :class:`Friction`);
    ``tangential_stress`` is kept with Walton's rule (the only law that has it)."""
    if isinstance(law, WaltonRestitution):
        return Friction(mu=float(mu), restitution="walton", beta0=law.beta0, q=law.q, tangential_stress=tangential_stress)
    if isinstance(law, RoughSphereRestitution):
        return Friction(mu=float(mu), restitution="rough-sphere", tangential_beta=law.beta, q=law.q)
    if isinstance(law, ChialvoSundaresanRestitution):
        return Friction(mu=float(mu), restitution="chialvo-sundaresan-2013", cs_amplitude=law.amplitude,
                        cs_decay=law.decay)
    raise InputError(f"unknown restitution law {law!r}")


def frictional_uniform_shear(parts: FrictionalShearParts, phi: Any, e: float, mu: float) -> ShearState:
    """Uniform-shear prediction for frictional spheres at solid fractions φ, restitution e < 1, friction μ ≥ 0.

    The composition is turned into a registry model (:meth:`FrictionalShearParts.model_at` with the
    friction part of its restitution law) and solved by :func:`~ktgf.shear.steady.steady_shear`; a frictional
    stress given as parts (SI pressure object, any φ_max) is added the same way.
    Raises :class:`~ktgf.errors.InputError` for μ < 0, e outside (0, 1) and φ outside [0, φ_c(μ)).
    """
    check_friction_coefficient(mu)
    if not 0.0 < e < 1.0:
        raise InputError(f"restitution coefficient e = {e:g} is out of range: valid 0 < e < 1 (uniform shear needs dissipation)")
    parts.restitution.check(e, mu)
    model = parts.model_at(mu)
    model = model.replace(friction=friction_from_law(parts.restitution, mu,
                                                     getattr(model.friction, "tangential_stress", "none")))
    s = steady_shear(model, np.atleast_1d(np.asarray(phi, dtype=float)), e, dense_temperature=parts.dense_temperature)
    if parts.frictional_pressure is None:
        return s
    weight = 1.0 if parts.blend is None else parts.blend.weight(s.phi)
    p_f = weight * parts.frictional_pressure.pressure(s.phi) / parts.stress_scale
    visc = parts.frictional_viscosity
    ratio = visc.simple_shear_stress_ratio(s.T) if hasattr(visc, "simple_shear_stress_ratio") else visc.shear_stress_ratio()
    tau, p_star, p_nT = add_frictional_stress(s.tau_over_p, s.p_star, s.p_over_nT, s.phi * s.T, p_f, ratio)
    return s._replace(p_star=p_star, tau_over_p=tau, p_over_nT=p_nT)


def mu_i_uniform_shear(rheology: Any, dilatancy: Any, phi: Any) -> ShearState:
    """Uniform shear from μ(I) with dilatancy φ(I): I = I(φ), p/(ρ_s d² γ̇²) = 1/I², τ/p = μ(I).

    (I = γ̇ d/√(p/ρ_s) gives p/(ρ_s d² γ̇²) = 1/I².)  The rheology has no temperature, so T,
    T_rot/T and p/(nT) are NaN.  Raises :class:`~ktgf.errors.InputError` for φ outside [0, φ_max).
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    dilatancy.check(phi)
    inertial = dilatancy.inertial_number(phi)
    nan = np.full_like(phi, np.nan)
    return ShearState(phi=phi, T=nan, Trot_over_T=nan.copy(), p_star=1.0 / inertial**2,
                      tau_over_p=rheology.friction(inertial), p_over_nT=nan.copy(), eta_star=nan.copy(),
                      eta_over_eta0=nan.copy(), astar=nan.copy(), L_over_d=nan.copy())


def recommended_parts(theory: str = "ret") -> FrictionalShearParts:
    """The registered ``frictional`` composition as parts (``docs/friction.md`` §6), with another theory if asked.

    ``theory`` (RET by default) with the χ of ``frictional`` diverging at φ_J(μ), its EKT correlation
    length and Walton's collision rule with β0 = 1 — for RET the registered model ``frictional`` itself
    (the same numbers: tested).
    """
    model = get_model("frictional")
    if theory != "ret":
        model = model.replace(theory=get_model(theory).theory)
    return FrictionalShearParts(model, restitution=WaltonRestitution(beta0=1.0))
