"""Radial distribution functions at contact, χ = g0(φ), each with its analytic derivative.

Every RDF is a small frozen dataclass whose fields are its parameters; ``chi(phi)`` and
``dchi(phi)`` are pure, vectorised and work on NumPy and JAX arrays alike.  The valid
domain is ``0 ≤ φ < phi_max`` (the packing limit at which χ diverges); evaluation does
not check it (so it can run under ``jax.jit``) — :func:`ktgf.validation.check_state`
does, at the public boundary.

Glossary: ``phi`` solid volume fraction φ, ``phi_f`` freezing point φ_f,
``phi_c`` random-close-packing (divergence) point φ_c, ``beta`` divergence exponent β.
Formulas: ``docs/model.md`` §2.  The piecewise RDFs join their branches at φ_f with a
C¹ bridge by default (``junction="c1"``; ``junction="c0"`` is the plain switch of model.md §2;
see :mod:`ktgf.closures.junction`).  Options are validated when an RDF is made
(:mod:`ktgf.closures.options`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, Callable, ClassVar

import numpy as np

from .._array import namespace, power
from ..errors import InputError
from .junction import DEFAULT_WIDTH, JUNCTIONS, hermite
from .options import CLOSE_PACKING, choice_option, real_option


@dataclass(frozen=True)
class RadialDistribution:
    """Base class: a radial distribution function at contact χ(φ) with its derivative."""

    key: ClassVar[str] = ""
    label: ClassVar[str] = ""
    reference: ClassVar[str] = ""

    @property
    def phi_max(self) -> float:
        """Packing limit: χ diverges here and states must have φ below it."""
        raise NotImplementedError

    def chi(self, phi: Any) -> Any:
        """χ(φ), the pair correlation at contact."""
        raise NotImplementedError

    def dchi(self, phi: Any) -> Any:
        """χ'(φ) = dχ/dφ."""
        raise NotImplementedError

    def params(self) -> dict[str, Any]:
        """The parameters of this RDF (its dataclass fields)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def describe(self) -> str:
        """Short text: name and parameters, e.g. ``torquato(phi_f=0.49, phi_c=0.64)``."""
        p = ", ".join(f"{k}={v}" for k, v in self.params().items() if not callable(v))
        return f"{self.key}({p})"


def _check_exponent(name: str, value: Any, key: str) -> None:
    real_option(name, value, owner=f"RDF {key}", low=0.0, high=10.0, why="divergence exponent, at most 10")


def _cs_chi(phi: Any) -> Any:
    return (1.0 - 0.5 * phi) / (1.0 - phi) ** 3


def _cs_dchi(phi: Any) -> Any:
    return (2.5 - phi) / (1.0 - phi) ** 4


def _cs_d2chi(phi: Any) -> Any:
    return (9.0 - 3.0 * phi) / (1.0 - phi) ** 5


@dataclass(frozen=True)
class CarnahanStarling(RadialDistribution):
    """Carnahan–Starling: χ = (1 − φ/2)/(1 − φ)³, χ' = (5/2 − φ)/(1 − φ)⁴.

    Carnahan & Starling, J. Chem. Phys. 51, 635 (1969); the paper's Table 1 row T11.
    Diverges only at φ = 1, so it does not stop a dense region from passing random close packing.
    """

    key: ClassVar[str] = "carnahan-starling"
    label: ClassVar[str] = "Carnahan–Starling"
    reference: ClassVar[str] = "Carnahan & Starling, J. Chem. Phys. 51, 635 (1969)"

    @property
    def phi_max(self) -> float:
        return 1.0

    def chi(self, phi: Any) -> Any:
        return _cs_chi(phi)

    def dchi(self, phi: Any) -> Any:
        return _cs_dchi(phi)


@dataclass(frozen=True)
class _DivergesAtPhiC(RadialDistribution):
    """An RDF whose parameter ``phi_c`` (0 < φ_c ≤ π/√18) is its packing limit."""

    @property
    def phi_max(self) -> float:
        return self.phi_c  # type: ignore[attr-defined]

    def __post_init__(self) -> None:
        phi_c = self.phi_c  # type: ignore[attr-defined]
        real_option("phi_c", phi_c, owner=f"RDF {self.key}", low=0.0, high=CLOSE_PACKING,
                    why="0 < phi_c <= close packing pi/sqrt(18)")


@dataclass(frozen=True)
class _CarnahanStarlingBelowFreezing(RadialDistribution):
    """Carnahan–Starling up to the freezing point φ_f, a dense branch diverging at φ_c above it.

    ``junction="c1"`` (default): on [φ_f, φ_f + w] (w = ``junction_width``) the quintic Hermite
    bridge matching χ, χ' and χ'' of CS at φ_f and of the dense branch at φ_f + w, so χ, χ'
    (and χ'') are continuous.  ``junction="c0"``: the plain switch at φ_f of model.md §2 (χ' jumps there).
    """

    phi_f: float = 0.49
    phi_c: float = 0.64
    junction: str = "c1"
    junction_width: float = DEFAULT_WIDTH

    def __post_init__(self) -> None:
        owner = f"RDF {self.key}"
        real_option("phi_f", self.phi_f, owner=owner, low=0.0, high=1.0, high_open=True)
        real_option("phi_c", self.phi_c, owner=owner, low=self.phi_f, high=CLOSE_PACKING,
                    why="phi_f < phi_c <= close packing pi/sqrt(18)")
        choice_option("junction", self.junction, JUNCTIONS, owner=owner)
        real_option("junction_width", self.junction_width, owner=owner, low=0.0, high=self.phi_c - self.phi_f,
                    high_open=True, why="0 < width < phi_c - phi_f")

    def _check_bridge(self) -> None:
        """The smooth bridge must keep χ increasing; it can fail to when the dense branch starts
        flatter than CS at φ_f (not so for the published parameters: 66.4 or 37.9 against 29.7)."""
        if self.junction != "c1":
            return
        t = np.linspace(0.0, 1.0, 257)
        if np.any(self._bridge(self.phi_f + t * self.junction_width)[1] <= 0):
            raise InputError(
                f"junction c1 of RDF {self.key} (phi_f={self.phi_f:g}, phi_c={self.phi_c:g}, "
                f"width={self.junction_width:g}) is not monotone: the dense branch starts flatter than CS; "
                "use junction='c0' or a wider junction_width"
            )

    @property
    def phi_max(self) -> float:
        return self.phi_c

    def _dense(self, phi: Any) -> Any:
        raise NotImplementedError

    def _dense_slope(self, phi: Any) -> Any:
        raise NotImplementedError

    def _dense_curvature(self, phi: Any) -> Any:
        raise NotImplementedError

    def _bridge(self, phi: Any) -> tuple[Any, Any]:
        a, b = self.phi_f, self.phi_f + self.junction_width
        lo = (_cs_chi(a), _cs_dchi(a), _cs_d2chi(a))
        return hermite(phi, a, b, lo, (self._dense(b), self._dense_slope(b), self._dense_curvature(b)))

    def _join(self, phi: Any, low: Any, bridge: Any, high: Any) -> Any:
        xp = namespace(phi)
        if self.junction == "c0":
            return xp.where(phi <= self.phi_f, low, high)
        return xp.where(phi <= self.phi_f, low, xp.where(phi < self.phi_f + self.junction_width, bridge, high))

    def chi(self, phi: Any) -> Any:
        bridge = self._bridge(phi)[0] if self.junction == "c1" else None
        return self._join(phi, _cs_chi(phi), bridge, self._dense(phi))

    def dchi(self, phi: Any) -> Any:
        bridge = self._bridge(phi)[1] if self.junction == "c1" else None
        return self._join(phi, _cs_dchi(phi), bridge, self._dense_slope(phi))


@dataclass(frozen=True)
class Torquato(_CarnahanStarlingBelowFreezing):
    """Torquato (1995): CS for φ ≤ φ_f, χ_CS(φ_f)(φ_c − φ_f)/(φ_c − φ) above.

    Torquato, Phys. Rev. E 51, 3170 (1995), Eq. (13).  Defaults φ_f = 0.49, φ_c = 0.64, joined
    C² over [φ_f, φ_f + 0.01] (``junction="c0"``: the paper's plain switch).
    """

    key: ClassVar[str] = "torquato"
    label: ClassVar[str] = "Torquato"
    reference: ClassVar[str] = "Torquato, Phys. Rev. E 51, 3170 (1995)"

    def __post_init__(self) -> None:
        super().__post_init__()
        self._check_bridge()

    def _dense(self, phi: Any) -> Any:
        return _cs_chi(self.phi_f) * (self.phi_c - self.phi_f) / (self.phi_c - phi)

    def _dense_slope(self, phi: Any) -> Any:
        return _cs_chi(self.phi_f) * (self.phi_c - self.phi_f) / (self.phi_c - phi) ** 2

    def _dense_curvature(self, phi: Any) -> Any:
        return 2.0 * self._dense_slope(phi) / (self.phi_c - phi)


@dataclass(frozen=True)
class LunSavage(_DivergesAtPhiC):
    """Lun & Savage (1986): χ = (1 − φ/φ_c)^(−2.5 φ_c).

    Lun & Savage, Acta Mech. 63, 15 (1986).  Default φ_c = 0.64.
    """

    phi_c: float = 0.64
    key: ClassVar[str] = "lun-savage"
    label: ClassVar[str] = "Lun–Savage"
    reference: ClassVar[str] = "Lun & Savage, Acta Mech. 63, 15 (1986)"

    def chi(self, phi: Any) -> Any:
        return (1.0 - phi / self.phi_c) ** (-2.5 * self.phi_c)

    def dchi(self, phi: Any) -> Any:
        return 2.5 * (1.0 - phi / self.phi_c) ** (-2.5 * self.phi_c - 1.0)


@dataclass(frozen=True)
class MaAhmadi(_DivergesAtPhiC):
    """Ma & Ahmadi (1986): χ = (1 + 2.5φ + 4.5904φ² + 4.515439φ³)/(1 − (φ/φ_c)³)^0.678021.

    Ma & Ahmadi, J. Chem. Phys. 84, 3449 (1986).  Default φ_c = 0.64356.
    """

    phi_c: float = 0.64356
    exponent: float = 0.678021
    key: ClassVar[str] = "ma-ahmadi"
    label: ClassVar[str] = "Ma–Ahmadi"
    reference: ClassVar[str] = "Ma & Ahmadi, J. Chem. Phys. 84, 3449 (1986)"

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_exponent("exponent", self.exponent, self.key)

    def chi(self, phi: Any) -> Any:
        num = 1.0 + 2.5 * phi + 4.5904 * phi**2 + 4.515439 * phi**3
        return num / (1.0 - (phi / self.phi_c) ** 3) ** self.exponent

    def dchi(self, phi: Any) -> Any:
        num = 1.0 + 2.5 * phi + 4.5904 * phi**2 + 4.515439 * phi**3
        dnum = 2.5 + 9.1808 * phi + 13.546317 * phi**2
        den = 1.0 - (phi / self.phi_c) ** 3
        dden = -3.0 * phi**2 / self.phi_c**3
        a = self.exponent
        return dnum / den**a - a * num * dden / den ** (a + 1.0)


def jamming_power_chi(phi: Any, a: Any, phi_c: Any, b: Any) -> Any:
    """χ_CS + a φ²/(φ_c − φ)^b (pure: any of the arguments may be a JAX value)."""
    # (2 − φ)/(2(1 − φ)³) in Chialvo & Sundaresan is the Carnahan–Starling χ written differently.
    return _cs_chi(phi) + a * phi**2 / power(phi_c - phi, b)


def jamming_power_dchi(phi: Any, a: Any, phi_c: Any, b: Any) -> Any:
    """dχ/dφ of :func:`jamming_power_chi`."""
    gap = phi_c - phi
    return _cs_dchi(phi) + a * (2.0 * phi / power(gap, b) + b * phi**2 / power(gap, b + 1.0))


@dataclass(frozen=True)
class JammingPowerLaw(_DivergesAtPhiC):
    """Carnahan–Starling plus a jamming divergence of free exponent: χ = χ_CS + a φ²/(φ_c − φ)^b.

    The form of Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013), their fitted χ (there
    b = 1.5, a = 0.58, φ_c = 0.64, from DEM of sheared frictionless spheres; not verified against
    the printed paper — a public implementation cites it as Eq. (31) with the same a and b, a hint
    only; docs/dense.md §2.4),
    with the divergence exponent b made a parameter so that the dense rise can be fitted
    (``docs/dense.md``).  Smooth (C^∞) on 0 ≤ φ < φ_c; reduces to CS for a = 0 and is
    CS + O(φ²) for φ → 0.  Defaults a = 0.58, φ_c = 0.64, b = 1.5 (the published values).

        χ' = χ_CS' + a (2φ (φ_c − φ)^(−b) + b φ² (φ_c − φ)^(−b−1))
    """

    a: float = 0.58
    phi_c: float = 0.64
    exponent: float = 1.5
    key: ClassVar[str] = "jamming-power-law"
    label: ClassVar[str] = "CS + jamming power law"
    reference: ClassVar[str] = "Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013), exponent free"

    def __post_init__(self) -> None:
        super().__post_init__()
        real_option("a", self.a, owner=f"RDF {self.key}", low=0.0, low_open=False, why="amplitude")
        _check_exponent("exponent", self.exponent, self.key)

    def chi(self, phi: Any) -> Any:
        return jamming_power_chi(phi, self.a, self.phi_c, self.exponent)

    def dchi(self, phi: Any) -> Any:
        return jamming_power_dchi(phi, self.a, self.phi_c, self.exponent)


@dataclass(frozen=True)
class ChialvoSundaresan(JammingPowerLaw):
    """Chialvo & Sundaresan (2013): χ = (2 − φ)/(2(1 − φ)³) + a φ²/(φ_c − φ)^1.5.

    Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013).  Defaults a = 0.58, φ_c = 0.64;
    the :class:`JammingPowerLaw` with b = 1.5.
    """

    key: ClassVar[str] = "chialvo-sundaresan"
    label: ClassVar[str] = "Chialvo–Sundaresan"
    reference: ClassVar[str] = "Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013)"


@dataclass(frozen=True)
class ViscosityDivergence(_CarnahanStarlingBelowFreezing):
    """The paper's new RDF: CS for φ ≤ φ_f, χ_CS(φ_f) ((φ_c − φ_f)/(φ_c − φ))^β above.

    Reconstructed in ``model.md`` §2 from the Bocquet et al. (2001) viscosity divergence
    η ∝ (φ_c − φ)^(−β), β = 1.75 (from δV ∝ γ̇^0.4: β = (1/0.4 + 1)/2).  With it the dense
    RET viscosity (∝ φ²χ) follows the measured law.  Defaults φ_f = 0.49, φ_c = 0.64, β = 1.75.
    With ``junction="c0"`` χ is continuous at φ_f but χ' is not (29.7 below, 66.4 above with the
    defaults); the default ``junction="c1"`` bridges [φ_f, φ_f + 0.01] so that χ' is continuous.
    """

    beta: float = 1.75
    key: ClassVar[str] = "viscosity-divergence"
    label: ClassVar[str] = "Viscosity divergence"
    reference: ClassVar[str] = "model.md §2; Bocquet et al., Phys. Rev. E 65, 011307 (2001)"

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_exponent("beta", self.beta, self.key)
        self._check_bridge()

    def _dense(self, phi: Any) -> Any:
        return _cs_chi(self.phi_f) * power((self.phi_c - self.phi_f) / (self.phi_c - phi), self.beta)

    def _dense_slope(self, phi: Any) -> Any:
        return self.beta * self._dense(phi) / (self.phi_c - phi)

    def _dense_curvature(self, phi: Any) -> Any:
        return (self.beta + 1.0) * self._dense_slope(phi) / (self.phi_c - phi)


@dataclass(frozen=True, eq=False)
class CustomRDF(RadialDistribution):
    """A user-supplied RDF: a pair of functions ``chi(phi)``, ``dchi(phi)`` and its packing limit.

    Both functions must be vectorised; to use the RDF inside the JAX solver they must be
    written with operators (or ``ktgf._array.namespace``) rather than NumPy calls.
    """

    chi_fn: Callable[[Any], Any] = None  # type: ignore[assignment]
    dchi_fn: Callable[[Any], Any] = None  # type: ignore[assignment]
    packing_limit: float = 1.0
    name: str = "custom"
    key: ClassVar[str] = "custom"
    label: ClassVar[str] = "Custom"
    reference: ClassVar[str] = "user supplied"

    def __post_init__(self) -> None:
        if not callable(self.chi_fn) or not callable(self.dchi_fn):
            raise TypeError("CustomRDF needs two callables: chi_fn(phi) and dchi_fn(phi)")
        real_option("packing_limit", self.packing_limit, owner="a custom RDF", low=0.0, high=1.0)

    @property
    def phi_max(self) -> float:
        return self.packing_limit

    def chi(self, phi: Any) -> Any:
        return self.chi_fn(phi)

    def dchi(self, phi: Any) -> Any:
        return self.dchi_fn(phi)

    def describe(self) -> str:
        return f"custom({self.name}, phi_max={self.packing_limit})"


RDFS: dict[str, type[RadialDistribution]] = {
    cls.key: cls
    for cls in (
        CarnahanStarling, Torquato, LunSavage, MaAhmadi, ChialvoSundaresan, ViscosityDivergence, JammingPowerLaw,
    )
}


def get_rdf(name: str, **params: Any) -> RadialDistribution:
    """Build a registered RDF by key (``"carnahan-starling"``, ``"torquato"``, …) with parameters."""
    from ..errors import InputError

    key = name.lower().replace("_", "-")
    if key in ("cs",):
        key = "carnahan-starling"
    if key not in RDFS:
        raise InputError(f"unknown radial distribution function {name!r}; choose one of {sorted(RDFS)}")
    return RDFS[key](**params)
