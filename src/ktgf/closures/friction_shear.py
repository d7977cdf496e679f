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
    SchaefferViscosity,
    modified_cooling_rate,
    with_jamming_fraction,
)
from .friction._part import check_friction_coefficient
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


@dataclass(frozen=True)
class _EffectiveDissipation:
    """A model whose cooling rate carries the frictional dissipation (so uniform_shear can be reused)."""

    model: Model
    restitution: Any
    mu: float

    def reduced(self, phi: Any, e: Any, *, check: bool = True):
        r = self.model.reduced(phi, e, check=check)
        inel = self.restitution.inelasticity(np.asarray(e, dtype=float), self.mu)
        return r._replace(zeta0=modified_cooling_rate(r.zeta0, np.asarray(e, dtype=float), inel))

    def __getattr__(self, name: str) -> Any:
        # everything else (RDF, dissipation part, ...) is the wrapped model's
        return getattr(self.model, name)


def frictional_uniform_shear(parts: FrictionalShearParts, phi: Any, e: float, mu: float) -> FrictionalShear:
    """Uniform-shear prediction for frictional spheres at solid fractions φ, restitution e < 1, friction μ ≥ 0.

    Raises :class:`~ktgf.errors.InputError` for μ < 0, e outside (0, 1) and φ outside [0, φ_c(μ)).
    """
    check_friction_coefficient(mu)
    if not 0.0 < e < 1.0:
        raise InputError(f"restitution coefficient e = {e:g} is out of range: valid 0 < e < 1 (uniform shear needs dissipation)")
    parts.restitution.check(e, mu)
    model = parts.model_at(mu)
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    state = uniform_shear(_EffectiveDissipation(model, parts.restitution, float(mu)), phi, e)
    T = np.asarray(state.temperature_ratio, dtype=float)
    if parts.dense_temperature is not None:
        T = np.maximum(T, parts.dense_temperature.temperature_ratio(phi, model.phi_max))
    r = model.reduced(phi, e)
    p_star = phi * np.asarray(r.p, dtype=float) * T
    tau_star = ETA0_CONSTANT * np.asarray(r.eta, dtype=float) * np.sqrt(T)
    if parts.frictional_pressure is not None:
        weight = 1.0 if parts.blend is None else parts.blend.weight(phi)
        p_f = weight * parts.frictional_pressure.pressure(phi) / parts.stress_scale
        visc = parts.frictional_viscosity
        ratio = visc.simple_shear_stress_ratio(T) if hasattr(visc, "simple_shear_stress_ratio") else visc.shear_stress_ratio()
        p_star, tau_star = p_star + p_f, tau_star + ratio * p_f
    rot = parts.restitution.rotational_ratio(e, mu)
    trot = np.full_like(phi, np.nan) if rot is None else np.broadcast_to(np.asarray(rot, dtype=float), phi.shape).copy()
    return FrictionalShear(phi=phi, T=T, Trot_over_T=trot, p_star=p_star, tau_over_p=tau_star / p_star,
                           p_over_nT=p_star / (phi * T))


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
    """The provisional ``frictional`` composition of ``docs/friction.md`` §6 (nothing fitted).

    ``theory`` (RET by default) with the Chialvo–Sundaresan χ diverging at φ_c(μ) and Walton's collision
    rule with β0 = 1.  Not registered yet: the registry entry waits for the dense-regime issue.
    """
    from .friction import WaltonRestitution
    from .models import get_model

    return FrictionalShearParts(get_model(theory).replace(rdf=FrictionalChialvoSundaresan()),
                                restitution=WaltonRestitution(beta0=1.0))
