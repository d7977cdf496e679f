"""Enskog kinetic theory of Lun, Savage, Jeffrey & Chepurniy (1984) in reduced form.

Lun et al., J. Fluid Mech. 140, 223 (1984), as restated in ``docs/model.md`` §4,
divided by the reference scales of §1 (η0, κ0, ν0).  With η_L = (1 + e)/2:

    p*   = 1 + 4η_L φχ
    λ_b* = (256/(5π)) η_L φ²χ
    η*   = (1 + (8/5)η_L φχ)(1 + (8/5)η_L(3η_L − 2)φχ)/(η_L(2 − η_L)χ) + (768/(25π)) η_L φ²χ
    κ*   = 8/(η_L(41 − 33η_L)χ) · [(1 + (12/5)η_L φχ)(1 + (12/5)η_L²(4η_L − 3)φχ)
                                   + (64/(25π))(41 − 33η_L)(η_L φχ)²]          (K0/κ0 = 8/(η_L(41 − 33η_L)))
    ζ0*  = (5/12)(1 − e²)χ                                                      (from γ = (3/2)ρθζ0)
    ζ_U  = 0

These equal the RET values with c* = 0 and ζ0* dropped from the kinetic denominators.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from .coefficients import Reduced
from .garzo_dufty1999 import stability_derivatives
from .options import choice_option, real_option

OMEGA_VARIANTS: tuple[str, ...] = ("none", "lun")


def reduced_coefficients(
    phi: Any, e: Any, chi: Any, dchi: Any, *, omega: str = "none", alpha: float = 1.0
) -> Reduced:
    """Reduced Lun (1984) coefficients (p*, η*, λ_b*, κ*, μ*, ζ0*, ζ_U, g, C) — model.md §4.

    Parameters
    ----------
    phi, e, chi, dchi : array_like
        Solid fraction, restitution, χ(φ) and χ'(φ).
    omega : {"none", "lun"}
        "none" (default): no density-gradient heat flux, the typical KTGF form the paper
        benchmarks.  "lun": Lun's own term ω_L (model.md §4), which in reduced form is
        μ* = φω_L/(θκ0) = 19.2 φ (η_L − 1)(2η_L − 1)/(41 − 33η_L)(1 + (12/5)η_L φχ)(2χ + φχ')/χ.
    alpha : float
        Empirical factor (2 + α)/3 on the kinetic–collisional part of η, as in MFiX (α = 1.6
        there).  The default α = 1 gives the original theory.
    """
    eta_l = 0.5 * (1.0 + e)
    ephi = phi * chi
    p = 1.0 + 4.0 * eta_l * ephi
    lambda_b = (256.0 / (5.0 * math.pi)) * eta_l * phi * ephi
    eta_kc = (1.0 + 1.6 * eta_l * ephi) * (1.0 + 1.6 * eta_l * (3.0 * eta_l - 2.0) * ephi) / (eta_l * (2.0 - eta_l) * chi)
    eta = ((2.0 + alpha) / 3.0) * eta_kc + (768.0 / (25.0 * math.pi)) * eta_l * phi * ephi
    b = 41.0 - 33.0 * eta_l
    kappa = (8.0 / (eta_l * b * chi)) * (
        (1.0 + 2.4 * eta_l * ephi) * (1.0 + 2.4 * eta_l**2 * (4.0 * eta_l - 3.0) * ephi)
        + (64.0 / (25.0 * math.pi)) * b * (eta_l * ephi) ** 2
    )
    zeta0 = (5.0 / 12.0) * (1.0 - e**2) * chi
    if omega == "lun":
        mu = 19.2 * phi * (eta_l - 1.0) * (2.0 * eta_l - 1.0) / b * (1.0 + 2.4 * eta_l * ephi) * (2.0 * chi + phi * dchi) / chi
    else:
        mu = 0.0 * ephi
    g, big_c = stability_derivatives(phi, e, chi, dchi)
    return Reduced(p=p, eta=eta, lambda_b=lambda_b, kappa=kappa, mu=mu, zeta0=zeta0, zeta_u=0.0 * ephi, g=g, C=big_c)


@dataclass(frozen=True)
class Lun1984:
    """The Lun et al. (1984) closure set with its options (see :func:`reduced_coefficients`)."""

    omega: str = "none"
    alpha: float = 1.0
    key: ClassVar[str] = "lun-1984"
    label: ClassVar[str] = "Enskog (Lun et al. 1984)"
    reference: ClassVar[str] = "Lun, Savage, Jeffrey & Chepurniy, J. Fluid Mech. 140, 223 (1984)"

    def __post_init__(self) -> None:
        owner = f"theory {self.key}"
        choice_option("omega", self.omega, OMEGA_VARIANTS, owner=owner)
        # (2 + α)/3 multiplies the kinetic-collisional viscosity: it must stay positive
        real_option("alpha", self.alpha, owner=owner, low=-2.0, high=10.0,
                    why="(2 + alpha)/3 in (0, 4]: eta > 0, MFiX uses 1.6")

    def reduced(self, phi: Any, e: Any, chi: Any, dchi: Any) -> Reduced:
        """Reduced coefficients at (φ, e) given χ, χ' (model.md §4)."""
        return reduced_coefficients(phi, e, chi, dchi, omega=self.omega, alpha=self.alpha)

    def options(self) -> dict[str, Any]:
        return {"omega": self.omega, "alpha": self.alpha}
