"""Revised Enskog theory (RET) for inelastic hard spheres — Garzó & Dufty (1999).

Garzó & Dufty, Phys. Rev. E 59, 5895 (1999), 3D, first Sonine approximation, as restated in
``docs/model.md`` §3 (equation labels below refer to that section).  All functions
are pure and vectorised over ``phi``, ``e`` and the RDF values; they run on NumPy and JAX
arrays.

Glossary: ``phi`` φ, ``e`` restitution, ``chi`` χ(φ), ``dchi`` χ'(φ), ``cs`` c* (fourth
cumulant of the HCS distribution, a2 = c*/2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

from .coefficients import Reduced
from .options import bool_option, choice_option

Zeta11Variant = Literal["gd99", "ghd", "none"]
ZETA11_VARIANTS: tuple[str, ...] = ("gd99", "ghd", "none")


def c_star(e: Any) -> Any:
    """HCS fourth cumulant c*(e) = 32(1 − e)(1 − 2e²)/(81 − 17e + 30e²(1 − e)).

    van Noije & Ernst, Granular Matter 1, 57 (1998); Garzó & Dufty (1999) Eq. (25); model.md §3.
    Vanishes at e = 1 and is −0.029 at e = 0.9.
    """
    return 32.0 * (1.0 - e) * (1.0 - 2.0 * e**2) / (81.0 - 17.0 * e + 30.0 * e**2 * (1.0 - e))


def zeta11_gd99(phi: Any, e: Any, chi: Any, cs: Any, p: Any, zeta0: Any) -> Any:
    """First-order cooling-rate coefficient ζ11 in the Garzó–Dufty (1999) form (model.md §3).

    ζ11 = (5/32)(1 − e²)(1 + 3c*/64) χ c_D with c_D, ν_γ*, λ_D as given there.
    """
    nu_gamma = ((1.0 + e) / 48.0) * chi * (
        128.0 - 96.0 * e + 15.0 * e**2 - 15.0 * e**3 + (cs / 64.0) * (15.0 * e**3 - 15.0 * e**2 + 498.0 * e - 434.0)
    )
    lambda_d = (3.0 / 8.0) * (
        (1.0 - e) * (5.0 * e**2 + 4.0 * e - 1.0) + (cs / 12.0) * (159.0 * e + 3.0 * e**2 - 19.0 - 15.0 * e**3)
    ) * (1.0 + e)
    c_d = ((4.0 / 15.0) * lambda_d * phi * chi + (p - 1.0) * (2.0 / 3.0 - e) * cs) / (
        0.5 * zeta0 + nu_gamma + (5.0 * cs / 64.0) * (1.0 + 3.0 * cs / 64.0) * chi * (1.0 - e**2)
    )
    return (5.0 / 32.0) * (1.0 - e**2) * (1.0 + 3.0 * cs / 64.0) * chi * c_d


def zeta11_ghd(phi: Any, e: Any, chi: Any) -> Any:
    """ζ11 = 3(1 − e²)²(5e − 1) φχ/(121 − 57e + 30e² − 30e³) (model.md §3, "ghd" variant)."""
    return 3.0 * (1.0 - e**2) ** 2 * (5.0 * e - 1.0) * phi * chi / (121.0 - 57.0 * e + 30.0 * e**2 - 30.0 * e**3)


def stability_derivatives(phi: Any, e: Any, chi: Any, dchi: Any) -> tuple[Any, Any]:
    """g = 1 + φχ'/χ and C = 1 + 2(1 + e)φ(2χ + φχ') (model.md §3, used in μ* and in §8).

    g = ∂ln ζ0/∂ln n at fixed θ holds for every closure here whose ζ0* ∝ χ; C = ∂(φp*)/∂φ
    for p* = 1 + 2(1 + e)φχ.
    """
    return 1.0 + phi * dchi / chi, 1.0 + 2.0 * (1.0 + e) * phi * (2.0 * chi + phi * dchi)


def reduced_coefficients(
    phi: Any, e: Any, chi: Any, dchi: Any, *, zeta11: str = "gd99", sonine: bool = True
) -> Reduced:
    """All RET reduced coefficients (p*, η*, λ_b*, κ*, μ*, ζ0*, ζ_U, g, C) — model.md §3.

    Parameters
    ----------
    phi, e : array_like
        Solid fraction φ and restitution coefficient e (broadcast together).
    chi, dchi : array_like
        χ(φ) and χ'(φ) of the chosen radial distribution function.
    zeta11 : {"gd99", "ghd", "none"}
        Which published form of the small first-order cooling coefficient ζ11 to use.
    sonine : bool
        Include the Sonine correction c*(e) (True, the theory) or set c* = 0.

    Notes
    -----
    μ* uses the logarithmic derivative χ'/χ, as Garzó & Dufty (1999) write it (model.md §3 note i).
    """
    cs = c_star(e) if sonine else 0.0 * e
    ephi = phi * chi
    one_e = 1.0 + e
    p = 1.0 + 2.0 * one_e * ephi
    zeta0 = (5.0 / 12.0) * chi * (1.0 - e**2) * (1.0 + 3.0 * cs / 32.0)
    nu_eta = chi * (1.0 - (1.0 - e) ** 2 / 4.0) * (1.0 - cs / 64.0)
    eta_k = (1.0 - 0.4 * one_e * (1.0 - 3.0 * e) * ephi) / (nu_eta - 0.5 * zeta0)
    lambda_b = (128.0 / (5.0 * math.pi)) * phi * ephi * one_e * (1.0 - cs / 32.0)
    eta = eta_k * (1.0 + 0.8 * ephi * one_e) + 0.6 * lambda_b
    nu_kappa = (chi / 3.0) * one_e * (1.0 + (33.0 / 16.0) * (1.0 - e) + (19.0 - 3.0 * e) * cs / 1024.0)
    kappa_k = (2.0 / 3.0) * (
        1.0 + 0.5 * (1.0 + p) * cs + 0.6 * ephi * one_e**2 * (2.0 * e - 1.0 + (0.5 * one_e - 5.0 / (3.0 * one_e)) * cs)
    ) / (nu_kappa - 2.0 * zeta0)
    kappa = kappa_k * (1.0 + 1.2 * ephi * one_e) + (256.0 / (25.0 * math.pi)) * phi * ephi * one_e * (1.0 + 7.0 * cs / 32.0)
    g, big_c = stability_derivatives(phi, e, chi, dchi)
    mu_k = 2.0 * (
        g * zeta0 * kappa_k
        + (big_c / 3.0) * cs
        - 0.8 * ephi * (1.0 + 0.5 * phi * dchi / chi) * one_e * (e * (1.0 - e) + 0.25 * (4.0 / 3.0 + e * (1.0 - e)) * cs)
    ) / (2.0 * nu_kappa - 3.0 * zeta0)
    mu = mu_k * (1.0 + 1.2 * ephi * one_e)
    zeta10 = -2.0 * (1.0 - e**2) * ephi
    if zeta11 == "gd99":
        z11 = zeta11_gd99(phi, e, chi, cs, p, zeta0)
    elif zeta11 == "ghd":
        z11 = zeta11_ghd(phi, e, chi)
    else:
        z11 = 0.0 * zeta10
    return Reduced(p=p, eta=eta, lambda_b=lambda_b, kappa=kappa, mu=mu, zeta0=zeta0, zeta_u=zeta10 + z11, g=g, C=big_c)


@dataclass(frozen=True)
class GarzoDufty1999:
    """The RET closure set with its options (see :func:`reduced_coefficients`)."""

    zeta11: str = "gd99"
    sonine: bool = True
    key: ClassVar[str] = "garzo-dufty-1999"
    label: ClassVar[str] = "RET (Garzó & Dufty 1999)"
    reference: ClassVar[str] = "Garzó & Dufty, Phys. Rev. E 59, 5895 (1999)"

    def __post_init__(self) -> None:
        choice_option("zeta11", self.zeta11, ZETA11_VARIANTS, owner=f"theory {self.key}")
        # stored as a plain bool (np.bool_ is accepted), so the model stays hashable and printable
        object.__setattr__(self, "sonine", bool_option("sonine", self.sonine, owner=f"theory {self.key}"))

    def reduced(self, phi: Any, e: Any, chi: Any, dchi: Any) -> Reduced:
        """Reduced coefficients at (φ, e) given χ, χ' (model.md §3)."""
        return reduced_coefficients(phi, e, chi, dchi, zeta11=self.zeta11, sonine=self.sonine)

    def options(self) -> dict[str, Any]:
        return {"zeta11": self.zeta11, "sonine": self.sonine}
