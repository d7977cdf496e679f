"""Frictional (rate-independent) stress above a threshold solid fraction: pressure and viscosities.

The enduring-contact stress that MFiX and OpenFOAM users add to the kinetic-theory stress:

* :class:`JohnsonJacksonPressure` — Johnson & Jackson, J. Fluid Mech. 176, 67 (1987):
  p_f = Fr (φ − φ_min)^n / (φ_max − φ)^p for φ > φ_min, 0 below;
* :class:`SchaefferViscosity` — Schaeffer, J. Differ. Equations 66, 19 (1987): μ_f = p_f sin φ_fr/(2√I2D),
  so that in simple shear τ_f = p_f sin φ_fr;
* :class:`SrivastavaSundaresanViscosity` — Srivastava & Sundaresan, Powder Technol. 129, 72 (2003):
  the same with the strain rate augmented by the fluctuations, √(S:S + θ/d²), and the
  dilatancy correction of the frictional pressure.

Documented defaults (no code default exists in either program; these are their shipped values):

=================  ==========  =======================================================================
option             default     source
=================  ==========  =======================================================================
Fr                 0.05 Pa     OpenFOAM-7 tutorial ``twoPhaseEulerFoam/RAS/fluidisedBed``
                               (``JohnsonJacksonCoeffs {Fr 0.05;}``); MFiX ``constant_mod.f``
                               ``PARAMETER(Fr = 0.5d0 ...)`` in dyn/cm² = 0.05 Pa
n (``eta``)        2           same tutorial ``eta 2``; MFiX ``N_Pc = 2``
p                  5           same tutorial ``p 5``; MFiX ``D_Pc = 5``
φ_min              0.5         same tutorial ``alphaMinFriction 0.5``
φ_max              0.62        same tutorial ``alphaMax 0.62``
δ_min              0.05        same tutorial ``alphaDeltaMin 0.05``: OpenFOAM evaluates the
                               denominator as max(φ_max − φ, δ_min); 0 gives the original formula
φ_fr               28.5°       same tutorial ``phi 28.5``
n (compression)    1.03        MFiX ``N_Pf = 1.03`` (Srivastava & Sundaresan's compression value)
n (dilation)       √3/(2 sin φ_fr)   Srivastava & Sundaresan (2003)
=================  ==========  =======================================================================

Units: Fr and p_f in Pa (they are SI quantities, unlike the reduced kinetic-theory coefficients),
I2D = (1/2) S:S in 1/s² with S = D − (1/3)(tr D) I, θ/d² in 1/s².
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from ..._array import namespace
from ._part import FrictionPart, check_range


@dataclass(frozen=True)
class JohnsonJacksonPressure(FrictionPart):
    """Johnson & Jackson (1987) frictional pressure p_f = Fr (φ − φ_min)^n / max(φ_max − φ, δ_min)^p [Pa].

    Johnson & Jackson, J. Fluid Mech. 176, 67 (1987) (their frictional normal stress; exponents
    n = 2, p = 5 there).  Zero for φ ≤ φ_min.  With δ_min = 0 it diverges at φ_max; OpenFOAM's
    ``alphaDeltaMin`` (default here 0.05, see the module table) caps the denominator so that p_f
    stays finite past φ_max − δ_min (continuous, with a kink).  Defaults: module table.
    """

    Fr: float = 0.05
    n: float = 2.0
    p: float = 5.0
    phi_min: float = 0.5
    phi_max: float = 0.62
    delta_min: float = 0.05
    key: ClassVar[str] = "johnson-jackson"
    label: ClassVar[str] = "Johnson–Jackson frictional pressure"
    reference: ClassVar[str] = "Johnson & Jackson, J. Fluid Mech. 176, 67 (1987)"

    def __post_init__(self) -> None:
        check_range("frictional pressure coefficient Fr", self.Fr, low=0.0, why="Pa")
        check_range("frictional pressure exponent n", self.n, low=1.0, why="n >= 1 keeps p_f differentiable at phi_min")
        check_range("frictional pressure exponent p", self.p, low=0.0)
        check_range("packing limit phi_max", self.phi_max, low=0.0, high=1.0, low_open=True, high_open=True)
        check_range("friction threshold phi_min", self.phi_min, low=0.0, high=self.phi_max, high_open=True,
                    why=f"must lie below the packing limit phi_max = {self.phi_max:g}")
        check_range("denominator floor delta_min", self.delta_min, low=0.0, high=self.phi_max - self.phi_min,
                    high_open=True, why="0 <= delta_min < phi_max - phi_min")

    def _gap(self, phi: Any) -> Any:
        xp = namespace(phi)
        return xp.maximum(self.phi_max - phi, self.delta_min)

    def pressure(self, phi: Any) -> Any:
        """p_f(φ) [Pa]."""
        xp = namespace(phi)
        excess = xp.maximum(phi - self.phi_min, 0.0)
        return self.Fr * excess**self.n / self._gap(phi) ** self.p

    def dpressure(self, phi: Any) -> Any:
        """dp_f/dφ [Pa]: Fr [n (φ − φ_min)^(n−1) G + p (φ − φ_min)^n G'] / G^(p+1), G = φ_max − φ (capped)."""
        xp = namespace(phi)
        excess = xp.maximum(phi - self.phi_min, 0.0)
        gap = self._gap(phi)
        # d gap/dφ is −1 where φ_max − φ is used and 0 where the floor δ_min is.
        capped = (self.phi_max - phi) <= self.delta_min
        growth = xp.where(capped, 0.0, self.p * excess**self.n / gap)
        rise = xp.where(excess > 0.0, self.n * excess ** (self.n - 1.0), 0.0)
        return self.Fr * (rise + growth) / gap**self.p


@dataclass(frozen=True)
class _AngleOfInternalFriction(FrictionPart):
    """Base of the frictional viscosities: the angle of internal friction φ_fr (degrees)."""

    phi_fr_deg: float = 28.5

    def __post_init__(self) -> None:
        check_range("angle of internal friction phi_fr", self.phi_fr_deg, low=0.0, high=90.0, low_open=True,
                    high_open=True, why="degrees")

    @property
    def sin_phi(self) -> float:
        return math.sin(math.radians(self.phi_fr_deg))


@dataclass(frozen=True)
class SchaefferViscosity(_AngleOfInternalFriction):
    """Schaeffer (1987) frictional viscosity μ_f = p_f sin φ_fr / (2 √I2D) [Pa s].

    Schaeffer, J. Differ. Equations 66, 19 (1987); as implemented in MFiX ``calc_mu_s.f``
    (``MU_s = P_star*Sin2_Phi/sqrt(4 Sin2_Phi I2_devD_s)``) and OpenFOAM ``JohnsonJacksonSchaeffer``
    (``0.5*pf*sin(phi)/sqrt(I2D)``).  I2D = (1/2) S:S is the second invariant of the deviatoric
    strain rate.  In simple shear at rate γ̇, I2D = γ̇²/4 and the frictional shear stress is
    τ_f = p_f sin φ_fr, independent of γ̇ (rate independent, hence singular as γ̇ → 0: a solver
    must regularise I2D, see ``docs/friction.md``).  Default φ_fr = 28.5° (module table).
    """

    key: ClassVar[str] = "schaeffer"
    label: ClassVar[str] = "Schaeffer frictional viscosity"
    reference: ClassVar[str] = "Schaeffer, J. Differ. Equations 66, 19 (1987)"

    def viscosity(self, p_f: Any, i2d: Any) -> Any:
        """μ_f(p_f, I2D) [Pa s]."""
        xp = namespace(p_f, i2d)
        return p_f * self.sin_phi / (2.0 * xp.sqrt(i2d))

    def shear_stress_ratio(self) -> float:
        """τ_f/p_f in simple shear: sin φ_fr."""
        return self.sin_phi


@dataclass(frozen=True)
class SrivastavaSundaresanViscosity(_AngleOfInternalFriction):
    """Srivastava & Sundaresan (2003): frictional pressure and viscosity with the fluctuation term.

    Srivastava & Sundaresan, Powder Technol. 129, 72 (2003), in the form of MFiX ``calc_mu_s.f``
    (``SAVAGE = 2``: ZETA = √(θ/d² + S:S)):

        Z   = √(S:S + θ/d²)
        p_f = p_c (1 − ∇·u/(n √2 sin φ_fr Z))^(n−1)                (0 when the bracket is ≤ 0)
        μ_f = √2 p_f sin φ_fr (n − (n − 1)(p_f/p_c)^(1/(n−1))) / (2 Z)

    with p_c the critical-state pressure (e.g. :class:`JohnsonJacksonPressure`), n = √3/(2 sin φ_fr)
    in dilation (∇·u ≥ 0) and n = 1.03 in compression.  In simple shear (∇·u = 0, S:S = γ̇²/2) p_f = p_c
    and τ_f = μ_f γ̇ = p_c sin φ_fr γ̇/√(γ̇² + 2θ/d²): Schaeffer's p_c sin φ_fr when θ/(γ̇d)² → 0,
    smaller when the particles are agitated (the fluctuations regularise the γ̇ → 0 singularity).
    """

    n_compression: float = 1.03
    key: ClassVar[str] = "srivastava-sundaresan"
    label: ClassVar[str] = "Srivastava–Sundaresan frictional viscosity"
    reference: ClassVar[str] = "Srivastava & Sundaresan, Powder Technol. 129, 72 (2003)"

    def __post_init__(self) -> None:
        super().__post_init__()
        check_range("compression exponent n_compression", self.n_compression, low=1.0, low_open=True)

    @property
    def n_dilation(self) -> float:
        """n = √3/(2 sin φ_fr) for ∇·u ≥ 0 (1.814 at φ_fr = 28.5°)."""
        return math.sqrt(3.0) / (2.0 * self.sin_phi)

    def _n(self, div_u: Any) -> Any:
        return namespace(div_u).where(div_u >= 0.0, self.n_dilation, self.n_compression)

    def pressure_ratio(self, div_u: Any, ss: Any, theta_over_d2: Any) -> Any:
        """p_f/p_c = (1 − ∇·u/(n √2 sin φ_fr Z))^(n−1), 0 where the bracket is ≤ 0."""
        xp = namespace(div_u, ss, theta_over_d2)
        n = self._n(div_u)
        z = xp.sqrt(ss + theta_over_d2)
        bracket = 1.0 - div_u / (n * math.sqrt(2.0) * self.sin_phi * z)
        return xp.where(bracket > 0.0, xp.maximum(bracket, 0.0) ** (n - 1.0), 0.0)

    def viscosity(self, p_c: Any, div_u: Any, ss: Any, theta_over_d2: Any) -> Any:
        """μ_f [Pa s] from the critical pressure p_c, ∇·u, S:S [1/s²] and θ/d² [1/s²]."""
        xp = namespace(p_c, div_u, ss, theta_over_d2)
        n = self._n(div_u)
        ratio = self.pressure_ratio(div_u, ss, theta_over_d2)
        z = xp.sqrt(ss + theta_over_d2)
        return math.sqrt(2.0) * p_c * ratio * self.sin_phi * (n - (n - 1.0) * ratio ** (1.0 / (n - 1.0))) / (2.0 * z)

    def simple_shear_stress_ratio(self, temperature_ratio: Any) -> Any:
        """τ_f/p_c in simple shear at θ/(γ̇d)² = ``temperature_ratio``: sin φ_fr/√(1 + 2θ/(γ̇d)²)."""
        xp = namespace(temperature_ratio)
        return self.sin_phi / xp.sqrt(1.0 + 2.0 * temperature_ratio)
