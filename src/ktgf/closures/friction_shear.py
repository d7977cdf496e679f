"""Uniform simple shear of frictional particles: kinetic theory with frictional closure parts.

The closed forms of model.md §9 (:func:`ktgf.couette.uniform_shear.uniform_shear`) with

1. an RDF whose divergence is moved to the frictional jamming fraction φ_c(μ)
   (:mod:`ktgf.closures.friction.jamming`; RDFs without a divergence point, e.g. Carnahan–Starling,
   are used unchanged);
2. the collisional dissipation of an effective restitution, ζ0* → ζ0* (1 − e_eff²)/(1 − e²)
   (:mod:`ktgf.closures.friction.collisions`); pressure and viscosity keep e;
3. optionally the dense-inertial temperature floor of Chialvo & Sundaresan (2013),
   θ/(γ̇d)² = max(kinetic value, α1/√(φ_c − φ));
4. optionally a frictional (enduring-contact) stress p_f, τ_f = p_f × (τ/p)_f, weighted by a
   blend w(φ), added to the kinetic stress.  Its work is taken to be dissipated without feeding θ.

Outputs are in the definitions of ``shared/data/dem_uniform_shear_friction.csv``:
T = θ/(γ̇d)², p_star = p/(ρ_s d² γ̇²), tau_over_p = τ/p, p_over_nT = p/(n m θ), Trot_over_T.
Kinetic stresses: p/(ρ_s d² γ̇²) = φ p* T and τ/(ρ_s d² γ̇²) = (5√π/96) η* √T (model.md §1).
At μ = 0 every part reduces to the frictionless model (tested).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ..couette.uniform_shear import uniform_shear
from ..errors import InputError
from .friction import (
    ChialvoSundaresanRestitution,
    FrictionalChialvoSundaresan,
    JammingFraction,
    RoughSphereRestitution,
    SchaefferViscosity,
    WaltonRestitution,
    with_jamming_fraction,
)
from .friction._part import check_friction_coefficient
from .friction.model_slot import Friction
from .models import Model

#: τ/(ρ_s d² γ̇²) = ETA0_CONSTANT η* √T, with η0 = (5√π/96) ρ_s d √θ (model.md §1).
ETA0_CONSTANT = 5.0 * math.sqrt(math.pi) / 96.0


class FrictionalShear(NamedTuple):
    """Uniform-shear state in the DEM file's definitions (arrays broadcast over φ)."""

    phi: Any
    T: Any
    Trot_over_T: Any
    p_star: Any
    tau_over_p: Any
    p_over_nT: Any


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
        if isinstance(rdf, FrictionalChialvoSundaresan):
            return self.model.replace(rdf=dataclasses.replace(rdf, mu=float(mu)))
        if "phi_c" in {f.name for f in dataclasses.fields(rdf)}:
            jam = dataclasses.replace(self.jamming, phi_rcp=float(rdf.phi_c))
            return self.model.replace(rdf=with_jamming_fraction(rdf, float(mu), jam))
        return self.model


def friction_from_law(law: Any, mu: float) -> Friction:
    """The model's ``friction`` part for a restitution-law object at μ (flat options, see :class:`Friction`)."""
    if isinstance(law, WaltonRestitution):
        return Friction(mu=float(mu), restitution="walton", beta0=law.beta0, q=law.q)
    if isinstance(law, RoughSphereRestitution):
        return Friction(mu=float(mu), restitution="rough-sphere", tangential_beta=law.beta, q=law.q)
    if isinstance(law, ChialvoSundaresanRestitution):
        return Friction(mu=float(mu), restitution="chialvo-sundaresan-2013", cs_amplitude=law.amplitude,
                        cs_decay=law.decay)
    raise InputError(f"unknown restitution law {law!r}")


def model_uniform_shear(model: Model, phi: Any, e: float, *, stress_scale: float | None = None,
                        dense_temperature: Any = None) -> FrictionalShear:
    """Uniform shear of a registry model (its friction part included) in the DEM file's definitions.

    The closed forms of model.md §9 with the model's ζ0 (which carries the friction part's
    (1 − e_eff²)/(1 − e²)); T_rot/T from the friction part (NaN where not modelled); the friction
    part's frictional stress w p_f (Pa, so ``stress_scale`` = ρ_s d² γ̇² [Pa] is then required) added
    with τ_f = (τ_f/p_f) w p_f of unregularised simple shear, its work dissipated without feeding θ.
    Frictionless models give their Navier–Stokes uniform shear unchanged.  Raises
    :class:`~ktgf.errors.InputError` for e outside (0, 1) and φ outside [0, φ_max).
    """
    if not 0.0 < e < 1.0:
        raise InputError(f"restitution coefficient e = {e:g} is out of range: valid 0 < e < 1 (uniform shear needs dissipation)")
    friction = model.friction
    if friction.has_stress and stress_scale is None:
        raise InputError(f"model {model.name!r} has a frictional stress (stress = {friction.stress!r}): give the stress "
                         "scale rho_s d^2 gdot^2 in Pa (ktgf shear --stress-scale)")
    if stress_scale is not None and not stress_scale > 0.0:
        raise InputError(f"stress scale = {stress_scale:g} is out of range: valid stress_scale > 0 (Pa)")
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    model.check(phi, e)
    state = uniform_shear(model, phi, e)
    T = np.asarray(state.temperature_ratio, dtype=float)
    if dense_temperature is not None:
        T = np.maximum(T, dense_temperature.temperature_ratio(phi, model.phi_max))
    r = model.reduced(phi, e)
    p_star = phi * np.asarray(r.p, dtype=float) * T
    tau_star = ETA0_CONSTANT * np.asarray(r.eta, dtype=float) * np.sqrt(T)
    if friction.has_stress:
        p_f = np.asarray(friction.frictional_pressure(phi, model.phi_max), dtype=float) / stress_scale
        p_star, tau_star = p_star + p_f, tau_star + friction.simple_shear_stress_ratio(T) * p_f
    rot = friction.rotational_ratio(e)
    trot = np.full_like(phi, np.nan) if rot is None else np.full_like(phi, float(rot))
    return FrictionalShear(phi=phi, T=T, Trot_over_T=trot, p_star=p_star, tau_over_p=tau_star / p_star,
                           p_over_nT=p_star / (phi * T))


def frictional_uniform_shear(parts: FrictionalShearParts, phi: Any, e: float, mu: float) -> FrictionalShear:
    """Uniform-shear prediction for frictional spheres at solid fractions φ, restitution e < 1, friction μ ≥ 0.

    The composition is turned into a registry model (:meth:`FrictionalShearParts.model_at` with the
    friction part of its restitution law) and solved by :func:`model_uniform_shear`; a frictional
    stress given as parts (SI pressure object, any φ_max) is added the same way.
    Raises :class:`~ktgf.errors.InputError` for μ < 0, e outside (0, 1) and φ outside [0, φ_c(μ)).
    """
    check_friction_coefficient(mu)
    if not 0.0 < e < 1.0:
        raise InputError(f"restitution coefficient e = {e:g} is out of range: valid 0 < e < 1 (uniform shear needs dissipation)")
    parts.restitution.check(e, mu)
    model = parts.model_at(mu).replace(friction=friction_from_law(parts.restitution, mu))
    s = model_uniform_shear(model, phi, e, dense_temperature=parts.dense_temperature)
    if parts.frictional_pressure is None:
        return s
    p_star, tau_star = s.p_star, s.tau_over_p * s.p_star
    weight = 1.0 if parts.blend is None else parts.blend.weight(s.phi)
    p_f = weight * parts.frictional_pressure.pressure(s.phi) / parts.stress_scale
    visc = parts.frictional_viscosity
    ratio = visc.simple_shear_stress_ratio(s.T) if hasattr(visc, "simple_shear_stress_ratio") else visc.shear_stress_ratio()
    p_star, tau_star = p_star + p_f, tau_star + ratio * p_f
    return s._replace(p_star=p_star, tau_over_p=tau_star / p_star, p_over_nT=p_star / (s.phi * s.T))


def mu_i_uniform_shear(rheology: Any, dilatancy: Any, phi: Any) -> FrictionalShear:
    """Uniform shear from μ(I) with dilatancy φ(I): I = I(φ), p/(ρ_s d² γ̇²) = 1/I², τ/p = μ(I).

    (I = γ̇ d/√(p/ρ_s) gives p/(ρ_s d² γ̇²) = 1/I².)  The rheology has no temperature, so T,
    T_rot/T and p/(nT) are NaN.  Raises :class:`~ktgf.errors.InputError` for φ outside [0, φ_max).
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    dilatancy.check(phi)
    inertial = dilatancy.inertial_number(phi)
    nan = np.full_like(phi, np.nan)
    return FrictionalShear(phi=phi, T=nan, Trot_over_T=nan.copy(), p_star=1.0 / inertial**2,
                           tau_over_p=rheology.friction(inertial), p_over_nT=nan.copy())


def recommended_parts(theory: str = "ret") -> FrictionalShearParts:
    """The registered ``frictional`` composition as parts (``docs/friction.md`` §6), with another theory if asked.

    ``theory`` (RET by default) with the Chialvo–Sundaresan χ diverging at φ_c(μ), the EKT correlation
    length of ``frictional`` (c fitted, :mod:`ktgf.closures.friction.calibrated`) and Walton's collision rule
    with β0 = 1 — for RET the registered model ``frictional`` itself (the same numbers: tested).
    """
    from .models import get_model

    model = get_model("frictional")
    if theory != "ret":
        model = model.replace(theory=get_model(theory).theory)
    return FrictionalShearParts(model, restitution=WaltonRestitution(beta0=1.0))
