"""The ``friction`` part of a :class:`~ktgf.closures.models.Model`: restitution law + optional frictional stress + blend.

A model is theory × RDF × viscosity law × dissipation × friction.  The friction part changes the
kinetic coefficients through the collisional dissipation (``docs/friction.md`` Eq. 1.1):

    ζ0* → ζ0* (1 − e_eff²)/(1 − e²),   e_eff from the restitution law at the part's μ,

and, with ``tangential_stress = "maxwellian"``, through the tangential impulses' collisional shear stress
(η* gains share × (3/5)λ_b*, and ζ0* the part of its work that does not heat θ at the local shear measure;
:meth:`Friction.tangential_coefficients`, ``Model.reduced``, ``docs/friction.md`` §7.1),

and it carries (for the solvers that add it: uniform shear, Couette) an optional rate-independent
frictional stress p_f(φ) w(φ) with a frictional viscosity (Johnson & Jackson 1987 with Schaeffer 1987
or Srivastava & Sundaresan 2003) and a blend w(φ).  The frictional jamming fraction is the RDF's
business (:class:`~ktgf.closures.friction.FrictionalChialvoSundaresan` carries μ; ``Model.with_options
(mu=...)`` routes μ to both parts).

The options are flat scalars (so that ``Model.with_options``, ``ktgf shear -O`` and model files
handle them like every other option); the sub-parts of :mod:`ktgf.closures.friction` are built from
them and validate them.  :class:`NoFriction` (the default of every model) has no options.

**Reduction at μ = 0**: the law's e_eff is e exactly, and :meth:`Friction.zeta0_factor` returns the
Python float 1.0 without touching ζ0 (and ``Model.reduced`` skips the tangential stress), so the
coefficients are bit-identical to the frictionless model's (tested).  The frictional stress does *not* depend on μ (it is the enduring-contact stress of
MFiX/OpenFOAM, a continuum law): it is off (``stress = "none"``) unless chosen.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Any, ClassVar

import numpy as np

from ...errors import InputError
from ..options import choice_option, real_option
from .blending import SigmoidBlend, TanhBlend
from .collisions import ChialvoSundaresanRestitution, RoughSphereRestitution, WaltonRestitution
from .stress import JohnsonJacksonPressure, SchaefferViscosity, SrivastavaSundaresanViscosity

#: φ_max of the Johnson–Jackson pressure for an RDF that does not diverge below 1 (model.md §2).
RANDOM_CLOSE_PACKING = 0.64
#: Restitution laws by option value.
RESTITUTIONS: tuple[str, ...] = ("walton", "rough-sphere", "chialvo-sundaresan-2013")
#: Frictional stresses by option value: none, or the Johnson–Jackson pressure with a frictional viscosity.
STRESSES: tuple[str, ...] = ("none", "schaeffer", "srivastava-sundaresan")
#: Blends of the frictional stress by option value.
BLEND_CHOICES: tuple[str, ...] = ("none", "tanh", "sigmoid")
#: Collisional stress of the tangential impulses by option value (docs/friction.md §7.1; Walton, rough spheres).
TANGENTIAL_STRESSES: tuple[str, ...] = ("none", "maxwellian")
#: μ at which Walton's rule is the constant-β (rough-sphere) law: its T_rot/T, HCS ratio and share equal the
#: rough-sphere closed forms to 10⁻¹³ there (tests/closures/test_friction_registry.py).
STICKING_MU = 1e8


@dataclass(frozen=True)
class NoFriction:
    """Frictionless particles: the model's coefficients unchanged, no frictional stress."""

    key: ClassVar[str] = "none"
    label: ClassVar[str] = "frictionless"
    reference: ClassVar[str] = ""
    mu: ClassVar[float] = 0.0
    has_stress: ClassVar[bool] = False

    def zeta0_factor(self, e: Any) -> Any:
        """Multiplier of ζ0*: 1."""
        return 1.0

    def hcs_zeta0_factor(self, e: Any, *, missing: str = "raise") -> Any:
        """Multiplier of ζ0* in the homogeneous cooling state: 1."""
        return 1.0

    def rotational_ratio(self, e: Any, shear2: Any = None) -> None:
        """T_rot/T is not modelled (no rotation): ``None``."""
        return None

    def tangential_coefficients(self, e: Any, *, hcs: bool = False) -> None:
        """No tangential impulses: ``None``."""
        return None

    def check_model(self, model: Any) -> None:
        """Nothing to check."""

    def check_state(self, e: Any) -> None:
        """Nothing to check."""

    def options(self) -> dict[str, Any]:
        return {}

    def params(self) -> dict[str, Any]:
        return {}

    def describe(self) -> str:
        return "none"


@dataclass(frozen=True)
class Friction:
    """Frictional particles: Coulomb friction μ in the collisions, optionally a frictional stress.

    Parameters (all model options)
    ------------------------------
    mu : float
        Particle (Coulomb) friction coefficient, ≥ 0.
    restitution : str
        ``walton`` (Coulomb + sticking β0, no fitted parameter), ``rough-sphere`` (constant
        tangential restitution ``tangential_beta``) or ``chialvo-sundaresan-2013`` (e_eff fit).
    beta0, tangential_beta, q, cs_amplitude, cs_decay : float
        Parameters of those laws (:mod:`ktgf.closures.friction.collisions`): Walton's sticking
        restitution β0 = 1, the rough-sphere β = −1, q = 4I/(md²) = 2/5, CS13's a = 3/2, b = 3.
    stress : str
        ``none``, ``schaeffer`` or ``srivastava-sundaresan``: Johnson–Jackson p_f with that viscosity.
    jj_Fr, jj_n, jj_p, jj_phi_min, jj_phi_max, jj_delta_min : float
        Johnson–Jackson constants (MFiX/OpenFOAM defaults 0.05 Pa, 2, 5, 0.5, packing limit, 0.05);
        ``jj_phi_max = 0`` means the model's packing limit (the RDF's φ_c, so φ_c(μ) with a frictional RDF;
        0.64 for Carnahan–Starling).
    phi_fr_deg, n_compression : float
        Angle of internal friction (28.5°) and Srivastava–Sundaresan's compression exponent (1.03).
    blend, blend_phi_star, blend_width : str, float, float
        ``none``, ``tanh`` or ``sigmoid``; φ* (required with a blend) and the relative width W/(1 − φ*)
        (unset: the MFiX value, 0.02 tanh, 0.04 sigmoid; 0 is refused — a zero-width blend is a step).
    regularisation : float
        ε of the rate-independent viscosity in a solver, as a fraction of the flow's shear-rate
        scale: √I2D → √(I2D + (ε γ̇_ref)²) (Schaeffer) — see ``docs/friction.md`` §8.
    tangential_stress : str
        ``none`` or ``maxwellian`` (Walton's rule or rough spheres): the collisional shear stress of the tangential impulses in
        local equilibrium, Δη* = share × (3/5)λ_b*, and the part of its work that does not heat translation
        dissipated (:meth:`tangential_coefficients`, ``docs/friction.md`` §7.1).
    """

    # defaults are the sub-parts' own (one source of every documented constant)
    mu: float = 0.0
    restitution: str = "walton"
    beta0: float = WaltonRestitution.beta0
    tangential_beta: float = RoughSphereRestitution.beta
    q: float = WaltonRestitution.q
    cs_amplitude: float = ChialvoSundaresanRestitution.amplitude
    cs_decay: float = ChialvoSundaresanRestitution.decay
    stress: str = "none"
    jj_Fr: float = JohnsonJacksonPressure.Fr
    jj_n: float = JohnsonJacksonPressure.n
    jj_p: float = JohnsonJacksonPressure.p
    jj_phi_min: float = JohnsonJacksonPressure.phi_min
    jj_phi_max: float = 0.0
    jj_delta_min: float = JohnsonJacksonPressure.delta_min
    phi_fr_deg: float = SchaefferViscosity.phi_fr_deg
    n_compression: float = SrivastavaSundaresanViscosity.n_compression
    blend: str = "none"
    blend_phi_star: float = 0.0
    blend_width: float | None = None
    regularisation: float = 1e-3
    tangential_stress: str = "none"
    key: ClassVar[str] = "coulomb"
    label: ClassVar[str] = "Coulomb friction"
    reference: ClassVar[str] = "docs/friction.md"

    def __post_init__(self) -> None:
        owner = "friction"
        real_option("mu", self.mu, owner=owner, low=0.0, low_open=False, why="particle friction coefficient")
        choice_option("restitution", self.restitution, RESTITUTIONS, owner=owner)
        choice_option("stress", self.stress, STRESSES, owner=owner)
        choice_option("blend", self.blend, BLEND_CHOICES, owner=owner)
        choice_option("tangential_stress", self.tangential_stress, TANGENTIAL_STRESSES, owner=owner)
        if self.tangential_stress != "none" and self.restitution == "chialvo-sundaresan-2013":
            raise InputError(f"option tangential_stress = {self.tangential_stress!r} of friction needs a restitution law "
                             "with tangential impulses (walton, rough-sphere; got 'chialvo-sundaresan-2013', an "
                             "effective restitution): set tangential_stress = 'none' with it")
        real_option("regularisation", self.regularisation, owner=owner, low=0.0, high=1.0,
                    why="epsilon as a fraction of the shear-rate scale")
        if self.blend_width is not None:
            real_option("blend_width", self.blend_width, owner=owner, low=0.0, why="a blend of zero width is a step")
        _ = self.law  # builds (and so validates) the restitution law
        if self.blend != "none":
            if not self.blend_phi_star > 0.0:
                raise InputError(f"option blend_phi_star = {self.blend_phi_star!r} of friction is required with "
                                 f"blend = {self.blend!r}: valid 0 < blend_phi_star < the packing limit")
            _ = self.blend_part

    # --- sub-parts ---------------------------------------------------------------------------
    @cached_property
    def law(self) -> Any:
        """The restitution law object (:mod:`ktgf.closures.friction.collisions`)."""
        if self.restitution == "walton":
            return WaltonRestitution(beta0=self.beta0, q=self.q)
        if self.restitution == "rough-sphere":
            return RoughSphereRestitution(beta=self.tangential_beta, q=self.q)
        return ChialvoSundaresanRestitution(amplitude=self.cs_amplitude, decay=self.cs_decay)

    def pressure_part(self, phi_max: float) -> JohnsonJacksonPressure:
        """The Johnson–Jackson pressure with φ_max = ``jj_phi_max`` or, when that is 0, the model's packing limit.

        (An RDF without a divergence below φ = 1, Carnahan–Starling, gives random close packing 0.64 instead.)
        """
        top = self.jj_phi_max if self.jj_phi_max > 0.0 else (float(phi_max) if phi_max < 1.0 else RANDOM_CLOSE_PACKING)
        return _johnson_jackson_pressure(Fr=self.jj_Fr, n=self.jj_n, p=self.jj_p, phi_min=self.jj_phi_min,
                                         phi_max=top, delta_min=self.jj_delta_min)

    @cached_property
    def viscosity_part(self) -> Any:
        """The frictional viscosity (Schaeffer or Srivastava–Sundaresan), ``None`` without a stress."""
        if self.stress == "schaeffer":
            return SchaefferViscosity(phi_fr_deg=self.phi_fr_deg)
        if self.stress == "srivastava-sundaresan":
            return SrivastavaSundaresanViscosity(phi_fr_deg=self.phi_fr_deg, n_compression=self.n_compression)
        return None

    @cached_property
    def blend_part(self) -> Any:
        """The blend w(φ) (``None``: w = 1)."""
        if self.blend == "tanh":
            return TanhBlend(self.blend_phi_star, relative_width=0.02 if self.blend_width is None else self.blend_width)
        if self.blend == "sigmoid":
            return SigmoidBlend(self.blend_phi_star, relative_width=0.04 if self.blend_width is None else self.blend_width)
        return None

    @property
    def has_stress(self) -> bool:
        return self.stress != "none"

    # --- what the model and the solvers use -----------------------------------------------------
    def zeta0_factor(self, e: Any) -> Any:
        """(1 − e_eff²)/(1 − e²), the multiplier of ζ0* (Python 1.0 at μ = 0: bit-exact reduction).

        The Walton law is a quadrature (SciPy), evaluated once per distinct value of e (under ``jax.jit``
        through a host callback, so e cannot be differentiated); the other laws are NumPy/JAX formulas.
        """
        if self.mu == 0.0:
            return 1.0
        if isinstance(self.law, WaltonRestitution):
            return _per_restitution(lambda v: self.law.inelasticity(v, self.mu) / (1.0 - v**2), e)
        return self.law.inelasticity(e, self.mu) / (1.0 - e**2)

    def _walton_view(self) -> tuple[Any, float]:
        """(law, μ) whose Walton closed forms (share, f, c_r) serve this part: constant β is Walton's rule where every
        collision sticks (β0 = β at :data:`STICKING_MU`)."""
        if isinstance(self.law, RoughSphereRestitution):
            return WaltonRestitution(beta0=self.law.beta, q=self.law.q), STICKING_MU
        return self.law, self.mu

    def tangential_coefficients(self, e: Any, *, hcs: bool = False) -> tuple[Any, Any] | None:
        """(share, loss) of the tangential impulses' collisional shear stress, ``None`` with ``tangential_stress = "none"``.

        share = :meth:`~ktgf.closures.friction.collisions.WaltonRestitution.tangential_shear_share` multiplies the
        local-equilibrium collisional viscosity (3/5)λ_b* into the extra Δη*; loss = (1 − f) share, f =
        :meth:`~ktgf.closures.friction.collisions.WaltonRestitution.tangential_work_fraction`, is the part of it
        whose work is dissipated instead of heating translation (``docs/friction.md`` §7.1).  ``hcs``: the share at
        the homogeneous cooling state's T_rot/T (no shear, so no loss).  Python floats (0.0, 0.0) at μ = 0.
        Evaluated per distinct e, as :meth:`zeta0_factor`.
        """
        if self.tangential_stress == "none":
            return None
        if self.mu == 0.0 or (self.restitution == "rough-sphere" and self.tangential_beta == -1.0):
            return 0.0, 0.0
        law, mu = self._walton_view()
        if hcs:
            return _per_restitution(lambda v: law.tangential_shear_share(v, mu, law.hcs_rotational_ratio(v, mu)), e), 0.0
        share = _per_restitution(lambda v: law.tangential_shear_share(v, mu), e)
        loss = _per_restitution(lambda v: (1.0 - law.tangential_work_fraction(v, mu)) * law.tangential_shear_share(v, mu),
                                e)
        return share, loss

    def hcs_zeta0_factor(self, e: Any, *, missing: str = "raise") -> Any:
        """(1 − e_HCS²)/(1 − e²): the multiplier of ζ0* in the homogeneous cooling state (Python 1.0 at μ = 0).

        In the HCS translation and rotation cool together at T_rot/T = r_HCS (the law's
        ``hcs_rotational_ratio``), so the translational cooling is the law's ``hcs_inelasticity`` at that
        ratio — not the steady-shear e_eff of :meth:`zeta0_factor`, where only translation is heated
        (``docs/friction.md`` §1, §7).  Walton's rule has no finite HCS ratio at weak friction (e.g. μ ≤ 0.3
        at e = 0.7): ``missing="raise"`` gives a one-line :class:`~ktgf.errors.InputError`, ``"nan"`` NaN
        there (maps).  The Chialvo–Sundaresan e_eff is a fit to sheared DEM without rotation: refused.
        """
        if self.mu == 0.0:
            return 1.0
        if self.restitution == "chialvo-sundaresan-2013":
            raise InputError("option restitution = 'chialvo-sundaresan-2013' of friction has no homogeneous cooling "
                             "state (a fit to sheared DEM, no rotation): valid for the HCS: walton, rough-sphere")
        if isinstance(self.law, RoughSphereRestitution):
            return self.law.hcs_inelasticity(e, self.mu) / (1.0 - e**2)
        values = np.asarray(e, dtype=float)
        uniq, inverse = np.unique(values, return_inverse=True)
        factors = np.array([self.law.hcs_inelasticity(float(v), self.mu) / (1.0 - float(v) ** 2) for v in uniq])
        if missing == "raise" and np.isnan(factors).any():
            bad = float(uniq[np.isnan(factors)][0])
            raise InputError(f"friction mu = {self.mu:g} has no homogeneous cooling state at e = {bad:g} "
                             f"(Walton's rule, beta0 = {self.beta0:g}: T_rot/T grows without bound): valid mu >= "
                             f"{self.law.hcs_friction_threshold(bad):.3g} at this e (docs/friction.md §1)")
        out = factors[inverse].reshape(values.shape)
        return float(out) if out.ndim == 0 and not isinstance(e, np.ndarray) else out

    def rotational_ratio(self, e: Any, shear2: Any = None) -> Any:
        """T_rot/T of steady homogeneous shear (``None`` if the law does not model rotation; 0 at μ = 0).

        With ``tangential_stress = "maxwellian"`` and the local shear measure's square ``shear2`` = s² =
        (γ̇d)²/θ, the ratio carries the mean strain's O(s²) shift r + c_r s²
        (:meth:`~ktgf.closures.friction.collisions.WaltonRestitution.rotational_shear_shift`), the shift whose
        effect on the translational energy is already in the tangential work fraction (``docs/friction.md`` §7.1).
        """
        if self.restitution == "chialvo-sundaresan-2013":
            return None
        if self.mu == 0.0:
            return 0.0
        ratio = self.law.rotational_ratio(e, self.mu)
        if shear2 is None or self.tangential_stress == "none":
            return ratio
        law, mu = self._walton_view()
        return ratio + _per_restitution(lambda v: law.rotational_shear_shift(v, mu), e) * shear2

    def check_state(self, e: Any) -> None:
        """Frictional dissipation at μ > 0 is written through 1/(1 − e²): e < 1 is required."""
        if self.mu > 0.0 and np.any(np.asarray(e, dtype=float) >= 1.0):
            raise InputError(f"restitution coefficient e = {float(np.max(e)):g} is out of range for friction mu = "
                             f"{self.mu:g}: valid 0 < e < 1 (docs/friction.md Eq. 1.1)")
        self.law.check(e, self.mu)

    def check_model(self, model: Any) -> None:
        """Thresholds must lie below the model's packing limit (one-line InputError naming the option)."""
        limit = float(model.phi_max)
        why = f"must lie below the packing limit {limit:.4g} of the model's RDF {model.rdf.describe()}"
        if self.jj_phi_max > limit:
            raise InputError(f"option jj_phi_max = {self.jj_phi_max:g} of friction is out of range: {why}")
        if self.has_stress:
            real_option("jj_phi_min", self.jj_phi_min, owner="friction", low=0.0, high=limit, high_open=True,
                        low_open=False, why=why)
            self.pressure_part(limit)  # validates n, p, δ_min against the band
        if self.blend != "none":
            real_option("blend_phi_star", self.blend_phi_star, owner="friction", low=0.0, high=limit,
                        high_open=True, why=why)

    def frictional_pressure(self, phi: Any, phi_max: float) -> Any:
        """w(φ) p_f(φ) [Pa] (0 without a stress)."""
        if not self.has_stress:
            return 0.0 * phi
        p_f = self.pressure_part(phi_max).pressure(phi)
        return p_f if self.blend_part is None else self.blend_part.weight(phi) * p_f

    def frictional_viscosity(self, p_f: Any, ss: Any, theta_over_d2: Any, reg2: Any, div_u: Any = 0.0) -> Any:
        """μ_f [Pa s] from w p_f [Pa], S:S [1/s²], θ/d² [1/s²] and the regularisation (ε γ̇_ref)² [1/s²].

        Schaeffer: p_f sin φ_fr/(2√(I2D + ε²γ̇_ref²)), I2D = S:S/2.  Srivastava–Sundaresan uses
        √(S:S + θ/d²), already regular where θ > 0; ε² is added there too so that θ → 0 stays finite.
        """
        visc = self.viscosity_part
        if visc is None:
            return 0.0 * p_f
        if isinstance(visc, SchaefferViscosity):
            return visc.viscosity(p_f, 0.5 * ss + reg2)
        return visc.viscosity(p_f, div_u, ss + 2.0 * reg2, theta_over_d2)

    def simple_shear_stress_ratio(self, temperature_ratio: Any) -> Any:
        """τ_f/(w p_f) in unregularised simple shear at θ/(γ̇d)²."""
        visc = self.viscosity_part
        if isinstance(visc, SrivastavaSundaresanViscosity):
            return visc.simple_shear_stress_ratio(temperature_ratio)
        return visc.shear_stress_ratio() + 0.0 * temperature_ratio

    def params(self) -> dict[str, Any]:
        from dataclasses import fields

        return {f.name: getattr(self, f.name) for f in fields(self)}

    def options(self) -> dict[str, Any]:
        return self.params()

    def describe(self) -> str:
        parts = [f"mu={self.mu:g}", self.restitution]
        if self.tangential_stress != "none":
            parts.append(f"tangential stress {self.tangential_stress}")
        if self.has_stress:
            parts.append(f"johnson-jackson+{self.stress}" + (f", {self.blend} blend" if self.blend != "none" else ""))
        return "coulomb(" + ", ".join(parts) + ")"


#: The pressure part, built (and its options validated) once per set of constants: the solvers ask for it at every
#: residual evaluation.  A refused set raises each time (lru_cache keeps no exception).
_johnson_jackson_pressure = lru_cache(maxsize=64)(JohnsonJacksonPressure)


def _per_restitution(fn: Any, e: Any) -> Any:
    """fn(e) of a scalar-only quadrature (SciPy) at every distinct value of e, in e's shape and dtype; under
    ``jax.jit`` (a traced e) through a host callback, so e cannot be differentiated."""
    if "jax" in type(e).__module__ and not _is_concrete(e):
        import jax

        e = jax.numpy.asarray(e)
        return jax.pure_callback(lambda v: _per_restitution(fn, np.asarray(v)), jax.ShapeDtypeStruct(e.shape, e.dtype),
                                 e, vmap_method="expand_dims")
    values = np.asarray(e, dtype=float)
    if values.ndim == 0:  # the solvers' one restitution: no np.unique round trip (the same float)
        out = np.array(fn(float(values)), dtype=float)
    else:
        uniq, inverse = np.unique(values, return_inverse=True)
        out = np.array([fn(float(v)) for v in uniq])[inverse].reshape(values.shape)
    return float(out) if out.ndim == 0 and not isinstance(e, np.ndarray) else out.astype(values.dtype)


def _is_concrete(x: Any) -> bool:
    try:
        np.asarray(x)
    except Exception:
        return False
    return True


#: Friction parts by key (``Model.with_options(friction=KEY)``).
FRICTIONS: dict[str, type] = {"none": NoFriction, "coulomb": Friction}

def with_friction(model: Any, mu: float | None) -> Any:
    """The model at friction coefficient μ: routed to its friction part, added if it has none.

    A frictionless model given μ > 0 gets the ``coulomb`` friction part with its defaults (Walton's rule,
    β0 = 1), its RDF unchanged; μ = 0 leaves a frictionless model as it is; ``None`` changes nothing.
    """
    if mu is None:
        return model
    from ._part import check_friction_coefficient

    check_friction_coefficient(mu)
    if model.friction.key == "none":
        return model if mu == 0.0 else model.with_options(friction="coulomb", mu=float(mu))
    return model.with_options(mu=float(mu))


__all__ = ["BLEND_CHOICES", "FRICTIONS", "Friction", "NoFriction", "RESTITUTIONS", "STRESSES", "with_friction"]
