"""The frictional jamming fraction φ_c(μ) and radial distribution functions that diverge there.

Frictional spheres jam (and their sheared pair correlation at contact diverges) below random close
packing: φ_c falls from φ_rcp ≈ 0.64 at μ = 0 towards random loose packing φ_rlp ≈ 0.55 as μ
grows over several decades (Silbert, Soft Matter 6, 2918 (2010), arXiv:1108.0012, abstract; Chialvo, Sun &
Sundaresan, Phys. Rev. E 85, 021305 (2012)).  We could not read those papers' tables, so φ_c(μ)
is a smooth interpolation between the two documented end points, with its μ scale a named option:

    φ_c(μ) = φ_rlp + (φ_rcp − φ_rlp)/(1 + μ/μ_J)                                           (1)

Defaults: φ_rcp = 0.64 (model.md §2, the frictionless packing limit of every ktgf RDF),
φ_rlp = 0.550 (Jerkins, Schröter, Swinney, Senden, Saadatfar & Aste, "Onset of mechanical stability
in random packings of frictional spheres", arXiv:0710.5160, Phys. Rev. Lett. 101, 018301 (2008):
φ_RLP = 0.550 ± 0.001 for rough spheres in the limit of zero pressure, from its abstract), μ_J = 0.1 (our choice: φ_c(0.1) = 0.595,
φ_c(0.5) = 0.565, φ_c(1) = 0.558 — within the 0.55–0.59 band the references describe at μ ≈ 0.5;
not fitted to the shared DEM file).

:class:`FrictionalChialvoSundaresan` is the RDF of Chialvo & Sundaresan (2013) with φ_c = φ_c(μ),
which is what that paper prescribes (its φ_c is the friction-dependent jamming point).
:func:`with_jamming_fraction` does the same for any other RDF family that has a ``phi_c`` field.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar

from ..rdf import ChialvoSundaresan, RadialDistribution
from ._part import FrictionPart, check_friction_coefficient, check_range


def _check_jamming(phi_rcp: Any, phi_rlp: Any, mu_scale: Any) -> None:
    check_range("random close packing phi_rcp", phi_rcp, low=0.0, high=1.0, low_open=True, high_open=True)
    check_range("random loose packing phi_rlp", phi_rlp, low=0.0, high=phi_rcp, low_open=True,
                why="must not exceed phi_rcp")
    check_range("jamming friction scale mu_J", mu_scale, low=0.0, low_open=True)


def jamming_fraction(mu: Any, phi_rcp: Any = 0.64, phi_rlp: Any = 0.55, mu_scale: Any = 0.1) -> Any:
    """φ_c(μ) of Eq. (1): φ_rcp at μ = 0, decreasing monotonically to φ_rlp as μ → ∞."""
    return phi_rlp + (phi_rcp - phi_rlp) / (1.0 + mu / mu_scale)


def d_jamming_fraction_dmu(mu: Any, phi_rcp: Any = 0.64, phi_rlp: Any = 0.55, mu_scale: Any = 0.1) -> Any:
    """dφ_c/dμ = −(φ_rcp − φ_rlp)/(μ_J (1 + μ/μ_J)²)."""
    return -(phi_rcp - phi_rlp) / (mu_scale * (1.0 + mu / mu_scale) ** 2)


@dataclass(frozen=True)
class JammingFraction(FrictionPart):
    """φ_c(μ) = φ_rlp + (φ_rcp − φ_rlp)/(1 + μ/μ_J), Eq. (1) of this module; defaults 0.64, 0.55, 0.1."""

    phi_rcp: float = 0.64
    phi_rlp: float = 0.55
    mu_scale: float = 0.1
    key: ClassVar[str] = "jamming-interpolation"
    label: ClassVar[str] = "φ_c(μ) interpolation"
    reference: ClassVar[str] = "end points: model.md §2 (0.64); Jerkins et al., arXiv:0710.5160 (2008) (0.550)"

    def __post_init__(self) -> None:
        _check_jamming(self.phi_rcp, self.phi_rlp, self.mu_scale)

    def phi_c(self, mu: Any) -> Any:
        """φ_c(μ)."""
        return jamming_fraction(mu, self.phi_rcp, self.phi_rlp, self.mu_scale)

    def dphi_c(self, mu: Any) -> Any:
        """dφ_c/dμ."""
        return d_jamming_fraction_dmu(mu, self.phi_rcp, self.phi_rlp, self.mu_scale)


def with_jamming_fraction(part: Any, mu: float, jamming: Any = None) -> Any:
    """A copy of ``part`` whose divergence point ``phi_c`` is moved to φ_c(μ) of ``jamming`` (any law with
    ``phi_c(mu)``; default :class:`JammingFraction`).

    Works for every frozen part with a ``phi_c`` field: the RDF families (Torquato, Lun–Savage, Ma–Ahmadi,
    Chialvo–Sundaresan, viscosity divergence) and the Bocquet viscosity law, so that the RDF and the
    viscosity divergence of a model diverge at the same point.  Raises :class:`~ktgf.errors.InputError` for
    μ < 0, for a part without ``phi_c`` (Carnahan–Starling diverges only at φ = 1) and when the part's
    freezing point φ_f would lie at or above φ_c(μ).
    """
    from ...errors import InputError

    check_friction_coefficient(mu)
    jamming = jamming or JammingFraction()
    names = {f.name for f in dataclasses.fields(part)} if dataclasses.is_dataclass(part) else set()
    if "phi_c" not in names:
        what = part.describe() if hasattr(part, "describe") else type(part).__name__
        raise InputError(f"{what} has no divergence point phi_c to move to the jamming fraction")
    phi_c = float(jamming.phi_c(mu))
    if "phi_f" in names:
        check_range("freezing point phi_f", part.phi_f, high=phi_c, high_open=True,
                    why=f"must lie below the jamming fraction phi_J(mu={mu:g}) = {phi_c:.4g}")
    return dataclasses.replace(part, phi_c=phi_c)


@dataclass(frozen=True)
class FrictionalChialvoSundaresan(RadialDistribution):
    """Chialvo & Sundaresan (2013) χ with its divergence at the frictional jamming fraction φ_c(μ).

    χ = (1 − φ/2)/(1 − φ)³ + a φ²/(φ_c(μ) − φ)^1.5,   φ_c(μ) from :class:`JammingFraction`.

    Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013) (a = 0.58; their Eq. 31 as cited by the
    CFDEM-PRINCETON implementation), with φ_c their friction-dependent jamming point.  At μ = 0 it
    is exactly ktgf's ``chialvo-sundaresan`` RDF (φ_c = φ_rcp = 0.64).  Options: ``mu``, ``a``,
    ``phi_rcp``, ``phi_rlp``, ``mu_scale``.
    """

    mu: float = 0.0
    a: float = 0.58
    phi_rcp: float = 0.64
    phi_rlp: float = 0.55
    mu_scale: float = 0.1
    key: ClassVar[str] = "frictional-chialvo-sundaresan"
    label: ClassVar[str] = "Chialvo–Sundaresan, frictional φ_c(μ)"
    reference: ClassVar[str] = "Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013); φ_c(μ): docs/friction.md"

    def __post_init__(self) -> None:
        check_friction_coefficient(self.mu)
        check_range("Chialvo-Sundaresan coefficient a", self.a, low=0.0)
        _check_jamming(self.phi_rcp, self.phi_rlp, self.mu_scale)

    @property
    def phi_c(self) -> Any:
        """The jamming fraction φ_c(μ) at this RDF's μ."""
        return jamming_fraction(self.mu, self.phi_rcp, self.phi_rlp, self.mu_scale)

    @property
    def phi_max(self) -> float:
        return float(self.phi_c)

    def _frictionless(self) -> ChialvoSundaresan:
        return ChialvoSundaresan(a=self.a, phi_c=self.phi_c)

    def chi(self, phi: Any) -> Any:
        return self._frictionless().chi(phi)

    def dchi(self, phi: Any) -> Any:
        return self._frictionless().dchi(phi)
