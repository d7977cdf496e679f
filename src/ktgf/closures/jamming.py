"""The jamming packing fraction φ_J(μ) of frictional spheres: a registry of laws, and moving parts to it.

Frictional spheres jam below random close packing.  The abstract of Silbert, Soft Matter 6, 2918
(2010) (arXiv:1108.0012) puts it this way: φ_c^μ falls "from the random close packing point for
zero friction, to a value coincident with random loose packing as the friction coefficient is
increased over several orders of magnitude", while the contact number at jamming z_c^μ "varies
from approximately six to four".  Every part that diverges (an RDF, a viscosity law, a frictional
stress) must diverge at the *same* φ_J(μ); this module is where that number comes from.

Laws (:data:`JAMMING_LAWS`, :func:`get_jamming_law`); each has ``phi_c(mu)`` and ``dphi_c(mu)``
(pure, NumPy and JAX), ``key``, ``label``, ``reference`` and ``params()``:

``interpolation``
    :class:`~ktgf.closures.friction.jamming.JammingFraction`, φ_rlp + (φ_rcp − φ_rlp)/(1 + μ/μ_J)
    with the end points 0.64 and 0.550 (``docs/friction.md`` §2).
``coordination``
    :class:`CoordinationJamming`: φ_J = Z_J/(Z_J + 2√3), the mean-field volume of jammed packings of
    Song, Wang & Makse, Nature 453, 629 (2008), at the contact number Z_J(μ) that moves from the
    isostatic frictionless value 2D = 6 to the isostatic frictional value D + 1 = 4 (Maxwell counting
    in D = 3 dimensions; Silbert's "approximately six to four"):

        Z_J(μ) = Z_∞ + (Z_0 − Z_∞)/(1 + μ/μ_Z),     φ_J(μ) = Z_J/(Z_J + 2√3)                  (1)

    Its end points follow from the two integers alone: φ_J(0) = 6/(6 + 2√3) = 0.63397 and
    φ_J(∞) = 4/(4 + 2√3) = 0.53590, printed as "4/(4 + 2√3) or 53.6% and 6/(6 + 2√3) or 63.4%,
    defining RLP and RCP" in the abstract of "Jamming II: Edwards' statistical mechanics of random
    packings of hard spheres" (Makse group, arXiv; its abstract as stored at arxivlens.com, read for
    this module; the Nature paper itself was not read).  Only μ_Z is a number to be chosen or calibrated (default 0.1, our choice, as μ_J
    of the interpolation: not a literature fit).
``tabulated``
    :class:`TabulatedJamming`: linear interpolation through (μ_i, φ_i) pairs that the user takes from
    a table of DEM jamming points (constant beyond the last point).  No default table is shipped: we
    could not read a printed one in this project (``docs/dense_physics.md`` §1).

:func:`at_jamming` moves the divergence point ``phi_c`` of any part that has one (every RDF family
but Carnahan–Starling, the Bocquet viscosity law) to φ_J(μ) of a law; :func:`check_below_jamming`
refuses a state at or above φ_J(μ) with one line naming it; :func:`mu_scale_for` gives the μ scale
of the two one-parameter laws that puts φ_J(μ) at a given value (to take a printed or calibrated
point).

:class:`FrictionalPowerLaw` is the RDF of the registered ``dense`` and ``frictional`` models: the
Chialvo–Sundaresan form diverging at the contact-number φ_J(μ).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

import numpy as np

from .._array import namespace, power
from ..errors import InputError
from .coefficients import SHEAR_PER_ASTAR
from .friction._part import FrictionPart, check_friction_coefficient, check_range
from .friction.jamming import JammingFraction, with_jamming_fraction
from .rdf import RadialDistribution, jamming_power_chi, jamming_power_dchi

#: 2√3, the constant of the mean-field volume function φ = Z/(Z + 2√3) (Song, Wang & Makse 2008).
TWO_SQRT3 = 2.0 * math.sqrt(3.0)


class JammingLaw(Protocol):
    """What a jamming law provides: φ_J(μ) and its derivative (pure functions of μ)."""

    key: ClassVar[str]
    label: ClassVar[str]
    reference: ClassVar[str]

    def phi_c(self, mu: Any) -> Any: ...

    def dphi_c(self, mu: Any) -> Any: ...

    def params(self) -> dict[str, Any]: ...

    def describe(self) -> str: ...


def packing_fraction_of_coordination(z: Any) -> Any:
    """φ(Z) = Z/(Z + 2√3): the mean-field volume fraction of a jammed packing of contact number Z.

    Song, Wang & Makse, "A phase diagram for jammed matter", Nature 453, 629 (2008); checked here through the
    abstract of "Jamming II" (module docstring), which prints 4/(4 + 2√3) = 53.6 % and 6/(6 + 2√3) = 63.4 %.
    """
    return z / (z + TWO_SQRT3)


def coordination_of_packing_fraction(phi: Any) -> Any:
    """The inverse, Z(φ) = 2√3 φ/(1 − φ)."""
    return TWO_SQRT3 * phi / (1.0 - phi)


@dataclass(frozen=True)
class CoordinationJamming(FrictionPart):
    """φ_J(μ) = Z_J/(Z_J + 2√3), Z_J(μ) = Z_∞ + (Z_0 − Z_∞)/(1 + μ/μ_Z) (Eq. 1 of this module).

    Parameters
    ----------
    z_frictionless : float
        Z_0, contact number at jamming for μ = 0: 2D = 6 (isostatic, Maxwell counting in 3D).
    z_infinite : float
        Z_∞, the limit μ → ∞: D + 1 = 4 (isostatic with tangential forces).
    mu_scale : float
        μ_Z, the friction at which Z_J is halfway (default 0.1: our choice, to be calibrated).
    """

    z_frictionless: float = 6.0
    z_infinite: float = 4.0
    mu_scale: float = 0.1
    key: ClassVar[str] = "coordination"
    label: ClassVar[str] = "φ_J from the contact number at jamming"
    reference: ClassVar[str] = ("Song, Wang & Makse, Nature 453, 629 (2008) (φ = Z/(Z + 2√3)); "
                                "Silbert, Soft Matter 6, 2918 (2010) (Z_J from six to four)")

    def __post_init__(self) -> None:
        check_range("contact number at jamming z_frictionless", self.z_frictionless, low=0.0, low_open=True)
        check_range("contact number at jamming z_infinite", self.z_infinite, low=0.0, high=self.z_frictionless,
                    low_open=True,
                    why="friction cannot raise the contact number at jamming: z_infinite <= z_frictionless")
        check_range("contact-number friction scale mu_scale", self.mu_scale, low=0.0, low_open=True)

    def coordination(self, mu: Any) -> Any:
        """Z_J(μ)."""
        return self.z_infinite + (self.z_frictionless - self.z_infinite) / (1.0 + mu / self.mu_scale)

    def dcoordination(self, mu: Any) -> Any:
        """dZ_J/dμ."""
        return -(self.z_frictionless - self.z_infinite) / (self.mu_scale * (1.0 + mu / self.mu_scale) ** 2)

    def phi_c(self, mu: Any) -> Any:
        """φ_J(μ)."""
        return packing_fraction_of_coordination(self.coordination(mu))

    def dphi_c(self, mu: Any) -> Any:
        """dφ_J/dμ = 2√3/(Z_J + 2√3)² · dZ_J/dμ."""
        z = self.coordination(mu)
        return TWO_SQRT3 / (z + TWO_SQRT3) ** 2 * self.dcoordination(mu)


@dataclass(frozen=True)
class TabulatedJamming(FrictionPart):
    """φ_J(μ) by linear interpolation through a table (μ_i, φ_i); constant outside [μ_0, μ_n].

    ``mu`` must start at 0 and increase strictly; ``phi`` must not increase (friction does not raise
    the jamming fraction) and lie in (0, π/√18].  Give the table's source when you use it.
    """

    mu: tuple[float, ...] = ()
    phi: tuple[float, ...] = ()
    key: ClassVar[str] = "tabulated"
    label: ClassVar[str] = "φ_J(μ) from a table"
    reference: ClassVar[str] = "user table (e.g. DEM jamming points)"

    def __post_init__(self) -> None:
        from .options import CLOSE_PACKING

        mu, phi = np.asarray(self.mu, dtype=float), np.asarray(self.phi, dtype=float)
        if mu.ndim != 1 or mu.size < 2 or mu.shape != phi.shape:
            raise InputError(f"tabulated jamming law needs two equal-length lists mu and phi of at least 2 values "
                             f"(got {mu.size} and {phi.size})")
        check_range("first friction coefficient of the table mu[0]", mu[0], low=0.0, high=0.0,
                    why="the table must start at mu = 0, the frictionless jamming point")
        if np.any(np.diff(mu) <= 0.0):
            raise InputError(f"tabulated jamming law: mu = {list(mu)} must increase strictly")
        check_range("tabulated jamming fraction phi", phi, low=0.0, high=CLOSE_PACKING, low_open=True,
                    why="0 < phi <= close packing pi/sqrt(18)")
        if np.any(np.diff(phi) > 0.0):
            raise InputError(f"tabulated jamming law: phi = {list(phi)} must not increase with mu")
        # tuples keep the part hashable (a static argument of jax.jit)
        object.__setattr__(self, "mu", tuple(float(m) for m in mu))
        object.__setattr__(self, "phi", tuple(float(p) for p in phi))

    def phi_c(self, mu: Any) -> Any:
        """φ_J(μ), piecewise linear."""
        xp = namespace(mu)
        return xp.interp(mu, xp.asarray(self.mu), xp.asarray(self.phi))

    def dphi_c(self, mu: Any) -> Any:
        """dφ_J/dμ: the slope of the segment that holds μ (0 outside the table; the right one at a node)."""
        xp = namespace(mu)
        m, p = xp.asarray(self.mu), xp.asarray(self.phi)
        slopes = xp.concatenate([(p[1:] - p[:-1]) / (m[1:] - m[:-1]), xp.zeros(1)])
        i = xp.clip(xp.searchsorted(m, mu, side="right") - 1, 0, len(self.mu) - 1)
        return xp.where(mu < m[0], 0.0, slopes[i])


#: Jamming laws by key (``get_jamming_law(KEY, **options)``).
JAMMING_LAWS: dict[str, type] = {
    "interpolation": JammingFraction,
    CoordinationJamming.key: CoordinationJamming,
    TabulatedJamming.key: TabulatedJamming,
}


def get_jamming_law(name: str, **params: Any) -> Any:
    """Build a registered jamming law by key (``"interpolation"``, ``"coordination"``, ``"tabulated"``)."""
    key = str(name).lower().replace("_", "-")
    if key not in JAMMING_LAWS:
        raise InputError(f"unknown jamming law {name!r}; choose one of {', '.join(JAMMING_LAWS)}")
    return JAMMING_LAWS[key](**params)


def _describe(part: Any) -> str:
    if hasattr(part, "describe"):
        return part.describe()
    fields = ", ".join(f"{f.name}={getattr(part, f.name)}" for f in dataclasses.fields(part))
    return f"{getattr(part, 'key', type(part).__name__)}({fields})"


def at_jamming(part: Any, mu: float, law: Any = None) -> Any:
    """A copy of ``part`` whose divergence point ``phi_c`` is φ_J(μ) of ``law`` (default: interpolation).

    ``part`` is any frozen dataclass with a ``phi_c`` field: every RDF family but Carnahan–Starling,
    and the Bocquet viscosity law (:class:`~ktgf.closures.viscosity_divergence.ViscosityDivergenceLaw`),
    so that the RDF and the viscosity divergence of a model diverge at the same point.  One-line
    :class:`~ktgf.errors.InputError` for μ < 0, a part without ``phi_c`` and a freezing point φ_f at or
    above φ_J(μ).
    """
    return with_jamming_fraction(part, mu, law)


def check_below_jamming(phi: Any, mu: float, law: Any = None) -> None:
    """Raise a one-line :class:`~ktgf.errors.InputError` naming φ_J(μ) if any φ is at or above it."""
    law = JammingFraction() if law is None else law
    check_friction_coefficient(mu)
    phi_j = float(law.phi_c(mu))
    check_range("solid fraction phi", phi, low=0.0, high=phi_j, high_open=True,
                why=f"below the jamming fraction phi_J(mu={mu:g}) = {phi_j:.4g} of {_describe(law)}")


def mu_scale_for(law: Any, mu: float, phi_j: float) -> float:
    """The μ scale (μ_J or μ_Z) that makes the one-parameter law ``law`` give φ_J(μ) = ``phi_j``.

    Both laws are a + b/(1 + μ/s) in a variable (φ for the interpolation, Z for the contact-number
    law), so s = μ/(b/(x − a) − 1) with x the target's value of that variable.  ``phi_j`` must lie
    strictly between the law's limits at μ = ∞ and μ = 0, and μ > 0.
    """
    check_range("friction coefficient mu", mu, low=0.0, low_open=True)
    if isinstance(law, CoordinationJamming):
        a, b = law.z_infinite, law.z_frictionless - law.z_infinite
        lo, hi = law.phi_c(math.inf), law.phi_c(0.0)
        x = float(coordination_of_packing_fraction(phi_j)) if lo < phi_j < hi else float("nan")
    elif isinstance(law, JammingFraction):
        a, b = law.phi_rlp, law.phi_rcp - law.phi_rlp
        lo, hi, x = law.phi_rlp, law.phi_rcp, float(phi_j)
    else:
        raise InputError("mu_scale_for needs a one-parameter jamming law (interpolation, coordination), "
                         f"got {_describe(law)}")
    check_range("target jamming fraction phi_j", phi_j, low=float(lo), high=float(hi), low_open=True, high_open=True,
                why=f"between the limits of {_describe(law)}")
    return float(mu / (b / (x - a) - 1.0))


@dataclass(frozen=True)
class FrictionalPowerLaw(RadialDistribution):
    """χ = χ_CS + a(μ) φ²/(φ_J(μ) − φ)^b: the Chialvo–Sundaresan form diverging at the contact-number φ_J(μ).

    The form of Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013) (their a = 0.58, b = 1.5 for
    frictionless spheres; :class:`~ktgf.closures.rdf.JammingPowerLaw`), with the divergence at φ_J(μ) of
    :class:`CoordinationJamming` (φ_J(0) = 6/(6 + 2√3) = 0.634, φ_J(∞) = 4/(4 + 2√3) = 0.536) and an
    amplitude that grows with friction on the same scale μ_Z as the contact number:

        a(μ) = a (1 + k s(μ)),     s(μ) = μ/(μ + μ_Z) = (Z_0 − Z_J(μ))/(Z_0 − Z_∞)                   (2)

    s goes from 0 (frictionless) to 1 (μ → ∞), so at μ = 0 the amplitude is a and φ_J is φ_J(0) exactly
    (one family for all μ: the registered ``dense`` is this RDF at μ = 0).  a, b, μ_Z and k are
    calibration parameters of the registered models (``docs/dense.md``, ``docs/friction.md``); the form of
    a(μ) between μ = 0 and the one frictional μ of the shared data (0.5) is our choice, not a fit.

    Under shear the amplitude gains a part proportional to the reduced shear rate a* = γ̇/ν0 = s/(k0 φ)
    (s = dγ̇/√θ, k0 = 96/(5√π); ``docs/dense_physics.md`` §8):

        χ(φ, s) = χ(φ) + A a* (1 + k s(μ)) φ²/(φ_J(μ) − φ)^b                                          (3)

    A (``shear_amplitude``, default 0: no shear dependence) is our calibration parameter: the mean shear
    brings neighbours into contact at a rate ∝ γ̇ besides the thermal rate ∝ √θ/d, which raises the
    collision frequency, i.e. the effective contact value, by a part ∝ γ̇d/√θ.  With A > 0 the sheared
    χ holds only where a shear measure is given (:meth:`shear_chi`; ``Model.reduced(shear=...)``):
    the homogeneous cooling state keeps χ(φ).

    Parameters
    ----------
    mu : float
        Particle friction coefficient (≥ 0).
    a, exponent : float
        Amplitude at μ = 0 and divergence exponent b (defaults: Chialvo & Sundaresan's 0.58 and 1.5).
    mu_scale : float
        μ_Z of the contact-number law (default 0.1).
    amplitude_growth : float
        k of Eq. (2) (≥ 0; default 0: the amplitude does not depend on μ).
    shear_amplitude : float
        A of Eq. (3) (≥ 0; default 0: χ does not depend on the shear).
    """

    mu: float = 0.0
    a: float = 0.58
    exponent: float = 1.5
    mu_scale: float = 0.1
    amplitude_growth: float = 0.0
    shear_amplitude: float = 0.0
    key: ClassVar[str] = "frictional-power-law"
    label: ClassVar[str] = "CS + power law at φ_J(μ)"
    reference: ClassVar[str] = ("Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013) (form); φ_J(μ): "
                                "ktgf.closures.jamming.CoordinationJamming")

    def __post_init__(self) -> None:
        from .options import real_option

        check_friction_coefficient(self.mu)
        owner = f"RDF {self.key}"
        real_option("a", self.a, owner=owner, low=0.0, low_open=False, why="amplitude")
        real_option("exponent", self.exponent, owner=owner, low=0.0, high=10.0, low_open=True,
                    why="divergence exponent, at most 10")
        real_option("amplitude_growth", self.amplitude_growth, owner=owner, low=0.0, low_open=False, why="k of a(mu) = a (1 + k s(mu))")
        real_option("shear_amplitude", self.shear_amplitude, owner=owner, low=0.0, low_open=False,
                    why="A of the sheared amplitude A a* (1 + k s(mu))")
        _ = self.jamming_law  # validates mu_scale

    @property
    def jamming_law(self) -> CoordinationJamming:
        """The model's one φ_J(μ) (every divergence of the model uses it)."""
        return CoordinationJamming(mu_scale=self.mu_scale)

    @property
    def friction_share(self) -> Any:
        """s(μ) = μ/(μ + μ_Z) of Eq. (2): 0 frictionless, 1 as μ → ∞."""
        return self.mu / (self.mu + self.mu_scale)

    @property
    def amplitude(self) -> Any:
        """a(μ) of Eq. (2) (a itself at μ = 0)."""
        return self.a * (1.0 + self.amplitude_growth * self.friction_share)

    @property
    def phi_c(self) -> Any:
        """φ_J(μ) of :attr:`jamming_law`, where χ diverges (written out so that fitted options may be JAX values)."""
        law = CoordinationJamming
        z = law.z_infinite + (law.z_frictionless - law.z_infinite) / (1.0 + self.mu / self.mu_scale)
        return packing_fraction_of_coordination(z)

    @property
    def phi_max(self) -> float:
        return float(self.phi_c)

    def chi(self, phi: Any) -> Any:
        return jamming_power_chi(phi, self.amplitude, self.phi_c, self.exponent)

    def dchi(self, phi: Any) -> Any:
        return jamming_power_dchi(phi, self.amplitude, self.phi_c, self.exponent)

    @property
    def shear_dependent(self) -> bool:
        """Whether χ depends on the shear measure (A > 0; a JAX-valued A counts as shear dependent)."""
        return not (isinstance(self.shear_amplitude, (int, float)) and self.shear_amplitude == 0.0)

    def _shear_scale(self, shear: Any) -> Any:
        # A (1 + k s(μ)) a* φ = A (1 + k s(μ)) s/k0: the sheared amplitude of Eq. (3) times φ
        return self.shear_amplitude * (1.0 + self.amplitude_growth * self.friction_share) * shear / SHEAR_PER_ASTAR

    def shear_chi(self, phi: Any, shear: Any) -> Any:
        """The sheared part of Eq. (3), A a* (1 + k s(μ)) φ²/(φ_J − φ)^b, at shear measure s = dγ̇/√θ."""
        return self._shear_scale(shear) * phi / power(self.phi_c - phi, self.exponent)

    def shear_dchi(self, phi: Any, shear: Any) -> Any:
        """∂/∂φ of :meth:`shear_chi` at fixed s."""
        gap = self.phi_c - phi
        return self._shear_scale(shear) * (1.0 / power(gap, self.exponent)
                                           + self.exponent * phi / power(gap, self.exponent + 1.0))
