"""Named closure models: compositions theory × RDF × viscosity law × dissipation correction × friction, and their registry.

A :class:`Model` is a small frozen (hashable) object, so solvers can take it as a static
argument of ``jax.jit``.  Solvers never branch on model names: they call
:meth:`Model.reduced` or :meth:`Model.coefficients`.  The registry (:func:`get_model`,
:func:`list_models`, :func:`register_model`) also drives the CLI, the docs and the
parametrised tests.

The four models of the paper (``model.md`` §§3–6):

=========== ===================== ========================== ==========================
name        theory                RDF                        viscosity law
=========== ===================== ========================== ==========================
enskog      Lun et al. (1984)     Carnahan–Starling          theory's own
ret         Garzó & Dufty (1999)  Carnahan–Starling          theory's own
visc-div    Lun et al. (1984)     Torquato                   Bocquet et al. divergence
proposed    Garzó & Dufty (1999)  viscosity-divergence RDF   theory's own
=========== ===================== ========================== ==========================

and one recommended family for all friction coefficients μ (``docs/dense.md``, ``docs/friction.md``):
RET × Carnahan–Starling plus a Chialvo–Sundaresan jamming term diverging at the contact-number
φ_J(μ), its amplitude growing with the reduced shear rate (:class:`~ktgf.closures.jamming.FrictionalPowerLaw`)
× the EKT correlation length, with Walton's collision rule for μ > 0 — ``dense`` is its member at μ = 0 (a, b,
c, A fitted to frictionless DEM uniform shear, cooling p/(nT) and the static χ, :mod:`ktgf.closures.dense`), ``frictional`` the member at μ (default 0.5; μ_Z and k
fitted to frictional DEM uniform shear, :mod:`ktgf.closures.friction.calibrated`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Protocol

from .._array import asarray, like, namespace
from ..errors import InputError, UnknownModelError
from ..validation import check_positive, check_state
from .coefficients import SHEAR_PER_ASTAR, Dimensional, Reduced, to_dimensional
from .garzo_dufty1999 import GarzoDufty1999
from .lun1984 import Lun1984
from .rdf import CarnahanStarling, RadialDistribution, Torquato, ViscosityDivergence
from .dense import DENSE_PARAMETERS
from .dissipation import DISSIPATIONS, CorrelationLength, NoDissipationCorrection
from .friction.calibrated import FAMILY_FRICTION, FRICTIONAL_PARAMETERS
from .jamming import FrictionalPowerLaw, check_below_jamming
from .friction.model_slot import FRICTIONS, Friction, NoFriction
from .viscosity_divergence import NoViscosityCorrection, ViscosityDivergenceLaw


class Theory(Protocol):
    """What a theory provides: reduced coefficients from (φ, e, χ, χ')."""

    key: str
    label: str
    reference: str

    def reduced(self, phi: Any, e: Any, chi: Any, dchi: Any) -> Reduced: ...

    def options(self) -> dict[str, Any]: ...


class ViscosityLaw(Protocol):
    """What a viscosity law provides: a multiplier of η* as a function of φ."""

    key: str
    label: str

    def factor(self, phi: Any) -> Any: ...

    def options(self) -> dict[str, Any]: ...


@dataclass(frozen=True)
class Model:
    """A closure model: a theory, a radial distribution function and a viscosity law.

    Parameters
    ----------
    name : str
        Registry name (e.g. ``"ret"``).
    theory : Theory
        :class:`~ktgf.closures.garzo_dufty1999.GarzoDufty1999` or
        :class:`~ktgf.closures.lun1984.Lun1984` (or any object with ``reduced``).
    rdf : RadialDistribution
        χ(φ) and χ'(φ).
    viscosity : ViscosityLaw
        Multiplier of the shear viscosity (default: none).
    dissipation : DissipationCorrection
        Multiplier of the cooling rate ζ0 (default: none; :class:`~ktgf.closures.dissipation.
        CorrelationLength` is extended kinetic theory, active only where a shear rate is given).
    friction : NoFriction or Friction
        Frictional particles (default: none): multiplies ζ0 by (1 − e_eff²)/(1 − e²) and carries the
        optional frictional stress that the uniform-shear and Couette solvers add
        (:mod:`ktgf.closures.friction.model_slot`).
    label, description : str
        Display name and one-line description.

    Examples
    --------
    >>> from ktgf import get_model
    >>> ret = get_model("ret")
    >>> r = ret.reduced(0.3, 0.9)          # reduced p*, η*, λ_b*, κ*, μ*, ζ0*, ζ_U, g, C
    >>> c = ret.coefficients(0.3, 0.9, theta=0.01, d=1e-3, rho_s=1500.0)   # SI values
    """

    name: str
    theory: Any
    rdf: RadialDistribution
    viscosity: Any = field(default_factory=NoViscosityCorrection)
    dissipation: Any = field(default_factory=NoDissipationCorrection)
    friction: Any = field(default_factory=NoFriction)
    label: str = ""
    description: str = ""

    def __post_init__(self) -> None:
        self.friction.check_model(self)

    @property
    def phi_max(self) -> float:
        """Packing limit of the model's RDF: valid states have φ < phi_max."""
        return float(self.rdf.phi_max)

    def check(self, phi: Any, e: Any, theta: Any = None) -> None:
        """Raise :class:`~ktgf.errors.InputError` if (φ, e, θ) is outside the model's domain."""
        for name, value in (("solid fraction phi", phi), ("restitution coefficient e", e)):
            if value is None:
                raise InputError(f"{name} is missing (None); give a number or an array")
        law = getattr(self.rdf, "jamming_law", None)
        if law is not None:  # name the model's jamming fraction phi_J(mu) (issue 33, item 6)
            check_below_jamming(phi, self.rdf.mu, law)
        check_state(phi, e, theta, phi_max=self.phi_max, rdf_name=self.rdf.describe())
        self.friction.check_state(e)

    def reduced(self, phi: Any, e: Any, *, check: bool = True, shear: Any = None, hcs: bool = False,
                chi_shear: Any = None) -> Reduced:
        """Reduced coefficients at solid fraction φ and restitution e (broadcast together).

        Works on NumPy arrays and on JAX arrays (also under ``jit``/``grad``, where the range
        check is skipped).  Raises :class:`~ktgf.errors.InputError` for φ outside
        [0, phi_max), e outside (0, 1] or NaN.  ``shear`` is the local shear measure dγ̇/√θ,
        used by a dissipation correction (extended kinetic theory) and by a shear-dependent RDF
        (χ(φ, s), e.g. ``FrictionalPowerLaw(shear_amplitude=...)``); without it ζ0 and χ are the
        theory's own.  ``chi_shear`` gives the RDF a shear measure alone (the closed form of steady uniform
        shear applies the dissipation correction itself).  g and C always refer to the theory's own ζ0
        and p* (they serve the HCS, where there is no shear).

        ``hcs=True`` gives the homogeneous cooling state's coefficients (``docs/friction.md`` §7): the
        friction part's HCS dissipation (rotation at its HCS ratio, :meth:`Friction.hcs_zeta0_factor`)
        instead of the steady-shear one, and no shear (``shear`` must be ``None``: the dissipation
        correction's correlation length is d there).  Frictionless models: identical to ``hcs=False``.
        """
        if check:
            self.check(phi, e)
        if hcs and (shear is not None or chi_shear is not None):
            raise InputError("the homogeneous cooling state has no shear: give shear = None with hcs = True")
        phi, e_host = asarray(phi), asarray(e)
        e = like(e_host, phi)  # a static (host) e: in the cells' precision
        chi, dchi = self.rdf.chi(phi), self.rdf.dchi(phi)
        structure = shear if chi_shear is None else chi_shear
        if structure is not None and getattr(self.rdf, "shear_dependent", False):
            chi, dchi = chi + self.rdf.shear_chi(phi, structure), dchi + self.rdf.shear_dchi(phi, structure)
        r = self.theory.reduced(phi, e, chi, dchi)
        zeta0 = r.zeta0 * self.dissipation.factor(phi, e, chi, shear)
        eta = r.eta
        if self.friction.mu > 0.0:  # frictionless (μ = 0): ζ0 and η untouched, bit for bit
            factor = self.friction.hcs_zeta0_factor(e_host) if hcs else self.friction.zeta0_factor(e_host)
            zeta0 = zeta0 * like(factor, phi)
            tangential = self.friction.tangential_coefficients(e_host, hcs=hcs)
            if tangential is not None:  # docs/friction.md §7.1: Δη* = share (3/5)λ_b*, its lost work a sink
                share, loss = (like(v, phi) for v in tangential)
                eta = eta + share * 0.6 * r.lambda_b
                if shear is not None and not hcs:  # (1 − f)Δη* a*² over (3/2), a* = s/(k φ)
                    xp = namespace(phi, shear)
                    astar = shear / (SHEAR_PER_ASTAR * xp.where(phi > 0.0, phi, 1.0))
                    zeta0 = zeta0 + loss * 0.6 * r.lambda_b * astar**2 / 1.5
        return r._replace(eta=eta * self.viscosity.factor(phi), zeta0=zeta0)

    @property
    def shear_dependent(self) -> bool:
        """Whether the coefficients depend on the local shear measure dγ̇/√θ (``reduced(shear=...)``): a dissipation
        correction (EKT length), the lost work of the tangential impulses' stress, or a shear-dependent χ."""
        tangential = self.friction.mu > 0.0 and getattr(self.friction, "tangential_stress", "none") != "none"
        return self.dissipation.key != "none" or tangential or getattr(self.rdf, "shear_dependent", False)

    def tangential_work_loss(self, e: Any, lambda_b: Any) -> Any:
        """Δη*_loss = (1 − f) share (3/5)λ_b*: the part of the tangential impulses' viscosity whose work is dissipated
        (0 without ``tangential_stress``; docs/friction.md §7.1).  In steady uniform shear the energy balance has
        η* − Δη*_loss where it has η*; in a solver :meth:`reduced` with ``shear`` adds Δη*_loss a*²/(3/2) to ζ0*."""
        tangential = self.friction.tangential_coefficients(e) if self.friction.mu > 0.0 else None
        if tangential is None:
            return 0.0
        return like(tangential[1], asarray(lambda_b)) * 0.6 * lambda_b

    def coefficients(
        self, phi: Any, e: Any, theta: Any, *, d: Any, rho_s: Any, check: bool = True, shear: Any = None,
        hcs: bool = False,
    ) -> Dimensional:
        """SI coefficients (p [Pa], η, λ_b [Pa s], κ, ω, ζ0 [1/s], ζ_U) at (φ, e, θ [m²/s²]).

        ``d`` is the particle diameter [m] and ``rho_s`` the material density [kg/m³]; ``shear``
        the local dγ̇/√θ for a dissipation correction; ``hcs`` the homogeneous cooling state (see :meth:`reduced`).
        """
        theta = asarray(theta)
        if check:
            self.check(phi, e, theta)
            check_positive("particle diameter d", d, "m")
            check_positive("material density rho_s", rho_s, "kg/m^3")
        return to_dimensional(self.reduced(phi, e, check=False, shear=shear, hcs=hcs), asarray(phi), theta, d, rho_s)

    def chi(self, phi: Any, shear: Any = None) -> Any:
        """The model's radial distribution function χ(φ), or χ(φ, s) at shear measure s if its RDF depends on it."""
        phi = asarray(phi)
        if shear is None or not getattr(self.rdf, "shear_dependent", False):
            return self.rdf.chi(phi)
        return self.rdf.chi(phi) + self.rdf.shear_chi(phi, shear)

    def replace(self, **changes: Any) -> Model:
        """A copy with fields replaced, e.g. ``model.replace(rdf=Torquato())``."""
        return dataclasses.replace(self, **changes)

    def with_options(self, **options: Any) -> Model:
        """A copy with options changed, routed to the part that owns them.

        ``zeta11``, ``sonine``, ``omega``, ``alpha`` go to the theory; ``phi_f``, ``phi_c``,
        ``beta``, ``a``, ``junction``, ``junction_width`` to the RDF and (where it has them) the
        viscosity law; ``dissipation`` (``"none"`` or ``"jenkins-berzi-2010"``) picks the
        dissipation correction, whose ``c`` is then an option too; ``friction`` (``"none"`` or
        ``"coulomb"``) picks the friction part, whose options (``mu``, ``restitution``, ``stress``, ...,
        :class:`~ktgf.closures.friction.model_slot.Friction`) are then options too.  ``mu`` goes to every
        part that has it (the friction part and a frictional RDF's jamming fraction).
        """
        if "friction" in options:
            key = options.pop("friction")
            if key not in FRICTIONS:
                raise InputError(f"option friction = {key!r} is not valid; choose one of {', '.join(FRICTIONS)}")
            if key != self.friction.key:
                return dataclasses.replace(self, friction=FRICTIONS[key]()).with_options(**options)
        if "dissipation" in options:  # a part chosen by name, e.g. dissipation="jenkins-berzi-2010"
            key = options.pop("dissipation")
            if key not in DISSIPATIONS:
                raise InputError(f"option dissipation = {key!r} is not valid; choose one of {', '.join(DISSIPATIONS)}")
            return dataclasses.replace(self, dissipation=DISSIPATIONS[key]()).with_options(**options)
        parts = {"theory": self.theory, "rdf": self.rdf, "viscosity": self.viscosity, "dissipation": self.dissipation,
                 "friction": self.friction}
        new = {}
        used: set[str] = set()
        for part_name, part in parts.items():
            names = {f.name for f in dataclasses.fields(part)}
            mine = {k: v for k, v in options.items() if k in names}
            used |= set(mine)
            new[part_name] = dataclasses.replace(part, **mine) if mine else part
        unknown = set(options) - used
        if unknown:
            raise InputError(f"model {self.name!r} has no option(s) {sorted(unknown)}; valid: {sorted(self.options())}")
        return dataclasses.replace(self, **new)

    def options(self) -> dict[str, Any]:
        """Every option of the model, flattened (for metadata and display)."""
        return {
            **self.theory.options(),
            **{k: v for k, v in self.rdf.params().items() if not callable(v)},
            **self.viscosity.options(),
            **self.dissipation.options(),
            **self.friction.options(),
        }

    def metadata(self) -> dict[str, str]:
        """Attributes for netCDF files: name, parts, references and options as strings."""
        import json

        return {
            "model": self.name,
            "model_label": self.label or self.name,
            "theory": self.theory.key,
            "theory_reference": self.theory.reference,
            "rdf": self.rdf.describe(),
            "viscosity_law": self.viscosity.key,
            "dissipation": self.dissipation.key,
            "friction": self.friction.key,
            "model_options": json.dumps(
                {
                    "theory": self.theory.options(),
                    "rdf": {k: v for k, v in self.rdf.params().items() if not callable(v)},
                    "viscosity": self.viscosity.options(),
                    "dissipation": self.dissipation.options(),
                    "friction": self.friction.options(),
                }
            ),
        }


_REGISTRY: dict[str, Model] = {}
_ALIASES: dict[str, str] = {}


def _normalise(name: str) -> str:
    return name.strip().lower().replace("_", "-").replace(".", "-").replace(" ", "-").strip("-")


def register_model(model: Model, *aliases: str, overwrite: bool = False) -> Model:
    """Add a model to the registry (and so to the CLI, the report and the tests)."""
    key = _normalise(model.name)
    if key in _REGISTRY and not overwrite:
        raise InputError(f"a model named {model.name!r} is already registered")
    _REGISTRY[key] = model
    for a in aliases:
        _ALIASES[_normalise(a)] = key
    return model


def get_model(name: str | Model, **options: Any) -> Model:
    """Look a model up by name (case and punctuation insensitive), optionally with options.

    >>> get_model("RET", zeta11="ghd").theory.zeta11
    'ghd'
    """
    if isinstance(name, Model):
        model = name
    else:
        key = _normalise(name)
        key = _ALIASES.get(key, key)
        if key not in _REGISTRY:
            raise UnknownModelError(f"unknown model {name!r}; registered models: {', '.join(_REGISTRY)}")
        model = _REGISTRY[key]
    return model.with_options(**options) if options else model


def list_models() -> list[Model]:
    """All registered models, in registration order."""
    return list(_REGISTRY.values())


PAPER_MODELS: tuple[str, ...] = ("enskog", "ret", "visc-div", "proposed")

register_model(
    Model(
        "enskog",
        Lun1984(),
        CarnahanStarling(),
        label="Enskog",
        description="Lun et al. (1984) kinetic theory, the classic KTGF benchmark",
    ),
    "lun", "lun1984", "lun-1984",
)
register_model(
    Model(
        "ret",
        GarzoDufty1999(),
        CarnahanStarling(),
        label="RET",
        description="Garzó & Dufty (1999) revised Enskog theory with density-gradient heat flux and ζ_U",
    ),
    "garzo-dufty", "gd99", "garzo-dufty-1999",
)
register_model(
    Model(
        "visc-div",
        Lun1984(),
        Torquato(),
        ViscosityDivergenceLaw(),
        label="Visc.div.",
        description="Lun et al. (1984) with Torquato χ and the Bocquet et al. (2001) faster viscosity divergence",
    ),
    "viscdiv", "visc-div", "bocquet",
)
register_model(
    Model(
        "proposed",
        GarzoDufty1999(),
        ViscosityDivergence(),
        label="Proposed",
        description="RET with the radial distribution function derived from the viscosity divergence",
    ),
)
def _family_rdf(mu: float) -> FrictionalPowerLaw:
    """The χ of the registered family at friction μ (``dense`` is μ = 0)."""
    return FrictionalPowerLaw(mu=mu, a=DENSE_PARAMETERS["a"], exponent=DENSE_PARAMETERS["exponent"],
                              shear_amplitude=DENSE_PARAMETERS["shear_amplitude"], **FRICTIONAL_PARAMETERS)


register_model(
    Model(
        "dense",
        GarzoDufty1999(),
        _family_rdf(0.0),
        dissipation=CorrelationLength(c=DENSE_PARAMETERS["c"]),
        label="Dense",
        description=(
            "Recommended for dense flows: RET, Carnahan-Starling + Chialvo-Sundaresan jamming term diverging at "
            "phi_J(0) = 0.634 whose amplitude grows with the reduced shear rate, EKT correlation length; a, b, c, A "
            "fitted to DEM uniform shear, cooling p/(nT) and Torquato's static chi (docs/dense.md); 'frictional' at mu = 0"
        ),
    ),
)
register_model(
    Model(
        "frictional",
        GarzoDufty1999(),
        _family_rdf(0.5),
        dissipation=CorrelationLength(c=DENSE_PARAMETERS["c"]),
        friction=Friction(mu=0.5, **FAMILY_FRICTION),
        label="Frictional",
        description=(
            "Recommended for frictional particles (default mu = 0.5; option mu): 'dense' with Walton's collision "
            "rule (beta0 = 1) and its tangential impulses' collisional stress, the divergence at the contact-number "
            "phi_J(mu) and a friction-grown jamming amplitude; mu_Z and k fitted to frictional DEM uniform shear "
            "(docs/friction.md); mu = 0 is 'dense'"
        ),
    ),
)
