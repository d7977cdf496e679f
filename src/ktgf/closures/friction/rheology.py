"""Dense rheology: the μ(I) friction law with dilatancy φ(I), and the dense-inertial temperature.

Inertial number I = γ̇ d/√(p/ρ_s) (d diameter, p pressure, ρ_s material density).

* :class:`MuIRheology` — Jop, Forterre & Pouliquen, Nature 441, 727 (2006), the friction law of
  their constitutive model: μ(I) = μ_s + (μ_2 − μ_s)/(I0/I + 1), with their glass-bead values
  μ_s = tan 20.9° = 0.382, μ_2 = tan 32.76° = 0.644, I0 = 0.279 (equation number not checked).  The same three numbers are used by the
  Basilisk μ(I) examples (``mus=0.383, dmu=0.26, I0=0.279``), an independent check of the transcription.
* :class:`LinearDilatancy` — φ(I) = φ_max − Δφ I (Forterre & Pouliquen, Annu. Rev. Fluid Mech. 40, 1
  (2008); GDR MiDi, Eur. Phys. J. E 14, 341 (2004)), φ_max ≈ 0.6 and φ decreasing to ≈ 0.5 over the
  dense-flow range.  We could not read a printed Δφ; the default Δφ = 0.2 (φ = 0.5 at I = 0.5) is our
  reading of that description, a named option, not a fitted number.
* :class:`DenseInertialTemperature` — Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013):
  θ/(γ̇d)² = α1/√(φ_c − φ) with α1 = 0.06 (their Eq. 27 and Table 2 as cited by the CFDEM-PRINCETON
  implementation), the dense-limit temperature that replaces the kinetic one when larger.

Chialvo, Sun & Sundaresan, Phys. Rev. E 85, 021305 (2012) blend quasi-static, inertial and
kinetic asymptotes with μ-dependent fitted constants; their printed table could not be read here,
so that model is not implemented (see ``docs/friction.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from ..._array import namespace
from ._part import FrictionPart, check_range


def inertial_number(shear_rate: Any, d: Any, p: Any, rho_s: Any) -> Any:
    """I = γ̇ d/√(p/ρ_s)."""
    xp = namespace(shear_rate, p)
    return shear_rate * d / xp.sqrt(p / rho_s)


@dataclass(frozen=True)
class MuIRheology(FrictionPart):
    """μ(I) = μ_s + (μ_2 − μ_s)/(I0/I + 1) (Jop, Forterre & Pouliquen 2006; defaults their glass beads)."""

    mu_s: float = math.tan(math.radians(20.9))
    mu_2: float = math.tan(math.radians(32.76))
    I0: float = 0.279
    key: ClassVar[str] = "mu-i"
    label: ClassVar[str] = "μ(I) rheology"
    reference: ClassVar[str] = "Jop, Forterre & Pouliquen, Nature 441, 727 (2006)"

    def __post_init__(self) -> None:
        check_range("static friction coefficient mu_s", self.mu_s, low=0.0)
        check_range("limiting friction coefficient mu_2", self.mu_2, low=self.mu_s, why="mu_2 >= mu_s")
        check_range("inertial-number scale I0", self.I0, low=0.0, low_open=True)

    def friction(self, inertial: Any) -> Any:
        """μ(I) = τ/p (μ_s at I = 0, μ_2 as I → ∞); written as I/(I0 + I) so that I = 0 is regular."""
        return self.mu_s + (self.mu_2 - self.mu_s) * inertial / (self.I0 + inertial)

    def dfriction(self, inertial: Any) -> Any:
        """dμ/dI = (μ_2 − μ_s) I0/(I0 + I)²."""
        return (self.mu_2 - self.mu_s) * self.I0 / (self.I0 + inertial) ** 2

    def inertial_number_at(self, friction: Any) -> Any:
        """The inverse: I = I0 (μ − μ_s)/(μ_2 − μ); valid for μ_s ≤ μ < μ_2."""
        return self.I0 * (friction - self.mu_s) / (self.mu_2 - friction)


@dataclass(frozen=True)
class LinearDilatancy(FrictionPart):
    """φ(I) = φ_max − Δφ I (Forterre & Pouliquen 2008); defaults φ_max = 0.6, Δφ = 0.2 (see module notes)."""

    phi_max: float = 0.6
    delta_phi: float = 0.2
    key: ClassVar[str] = "linear-dilatancy"
    label: ClassVar[str] = "linear dilatancy φ(I)"
    reference: ClassVar[str] = "Forterre & Pouliquen, Annu. Rev. Fluid Mech. 40, 1 (2008)"

    def __post_init__(self) -> None:
        check_range("dilatancy packing limit phi_max", self.phi_max, low=0.0, high=1.0, low_open=True, high_open=True)
        check_range("dilatancy slope delta_phi", self.delta_phi, low=0.0, low_open=True)

    def solid_fraction(self, inertial: Any) -> Any:
        """φ(I)."""
        return self.phi_max - self.delta_phi * inertial

    def inertial_number(self, phi: Any) -> Any:
        """I(φ) = (φ_max − φ)/Δφ (≥ 0 for φ ≤ φ_max)."""
        return (self.phi_max - phi) / self.delta_phi

    def check(self, phi: Any) -> None:
        """Raise :class:`~ktgf.errors.InputError` unless 0 ≤ φ < φ_max (I > 0)."""
        check_range("solid fraction phi", phi, low=0.0, high=self.phi_max, high_open=True,
                    why="the dilatancy law needs I > 0")


@dataclass(frozen=True)
class DenseInertialTemperature(FrictionPart):
    """θ/(γ̇d)² = α1/√(φ_c − φ) (Chialvo & Sundaresan 2013, Eq. 27; α1 = 0.06 from their Table 2)."""

    alpha1: float = 0.06
    key: ClassVar[str] = "chialvo-sundaresan-dense-temperature"
    label: ClassVar[str] = "dense-inertial temperature"
    reference: ClassVar[str] = "Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013)"

    def __post_init__(self) -> None:
        check_range("dense temperature coefficient alpha1", self.alpha1, low=0.0)

    def temperature_ratio(self, phi: Any, phi_c: Any) -> Any:
        """θ/(γ̇d)² in the dense inertial regime (φ < φ_c)."""
        xp = namespace(phi)
        return self.alpha1 / xp.sqrt(phi_c - phi)
