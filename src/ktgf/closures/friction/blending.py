"""Smooth switches between the kinetic and the frictional stress: MFiX's ``TANH_BLEND`` and ``SIGM_BLEND``.

MFiX (``physprop`` module, ``blend_function``; initialised in ``set_constprop``) blends the
plastic and the kinetic stress across the packed-bed void fraction ε* = EP_STAR:
stress = (1 − w) σ_kinetic + w σ_frictional, written here with the solid fraction φ = 1 − ε_g and
φ* = 1 − ε* (MFiX's EP_STAR has no default; it is a required input there, and here).

* tanh (MFiX: blend_start = 0.99 ε*, blend_end = 1.01 ε*, so a width W = 0.02 ε* in φ):

      w(φ) = [1 + tanh(2π (φ − φ_mid)/W)]/2   for |φ − φ_mid| < W/2,  0 below,  1 above,

  φ_mid = φ* exactly.  MFiX truncates outside the band, where the tanh has reached
  (1 ± tanh π)/2 = 0.0019 / 0.9981, so w jumps by 0.19 % at both ends; ``truncate=False``
  gives the untruncated (smooth) tanh.
* sigmoid (MFiX: blend_start = 0.97 ε*, blend_end = 1.01 ε*, W = 0.04 ε*): the kinetic weight
  1 − w = s/(1 + 0.01^((ε_g − ε*)/W)) for ε_g below blend_end and 1 above, with s a scale.
  MFiX sets s = 1/((b + 1)/2), b = 1/(1 + 0.01^((blend_end − ε*)/W)) = 0.760 — that averaging
  leaves the kinetic weight at 0.863 just below blend_end and 1 just above (a 14 % jump).  Here
  s = 1/b, which makes the blend continuous; the difference is documented, not hidden.

A blend of zero width is rejected (it would be a step, which is what the blends exist to avoid).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from ..._array import namespace
from ._part import FrictionPart, check_range


def _check_star(phi_star: float, rel_width: float, name: str) -> None:
    check_range("packed-bed solid fraction phi_star", phi_star, low=0.0, high=1.0, low_open=True, high_open=True)
    check_range(name, rel_width, low=0.0, low_open=True, why="a blend of zero width is a step")


@dataclass(frozen=True)
class TanhBlend(FrictionPart):
    """MFiX ``TANH_BLEND``: frictional weight w(φ) = [1 + tanh(2π(φ − φ*)/W)]/2, W = 0.02 (1 − φ*).

    ``relative_width`` is W/(1 − φ*) (MFiX: 1.01 − 0.99 = 0.02); ``truncate`` reproduces MFiX's
    cut to 0 and 1 outside |φ − φ*| < W/2.
    """

    phi_star: float
    relative_width: float = 0.02
    truncate: bool = True
    key: ClassVar[str] = "tanh"
    label: ClassVar[str] = "tanh blend (MFiX TANH_BLEND)"
    reference: ClassVar[str] = "MFiX physprop.f blend_function (TANH_BLEND)"

    def __post_init__(self) -> None:
        _check_star(self.phi_star, self.relative_width, "tanh blend relative width")

    @property
    def width(self) -> float:
        """W in φ."""
        return self.relative_width * (1.0 - self.phi_star)

    def weight(self, phi: Any) -> Any:
        """w(φ) ∈ [0, 1], the weight of the frictional stress."""
        xp = namespace(phi)
        x = (phi - self.phi_star) / self.width
        w = 0.5 * (1.0 + xp.tanh(2.0 * math.pi * x))
        if self.truncate:
            w = xp.where(x >= 0.5, 1.0, xp.where(x <= -0.5, 0.0, w))
        return w

    def dweight(self, phi: Any) -> Any:
        """dw/dφ = (π/W) sech²(2π(φ − φ*)/W) (0 outside the band when truncated)."""
        xp = namespace(phi)
        x = (phi - self.phi_star) / self.width
        dw = (math.pi / self.width) / xp.cosh(2.0 * math.pi * x) ** 2
        if self.truncate:
            dw = xp.where(xp.abs(x) >= 0.5, 0.0, dw)
        return dw


@dataclass(frozen=True)
class SigmoidBlend(FrictionPart):
    """MFiX ``SIGM_BLEND`` (made continuous): kinetic weight s/(1 + 100^((φ − φ*)/W)) below the band end.

    In φ the band runs from φ* − 0.01(1 − φ*) (MFiX blend_end, ε_g = 1.01 ε*) upwards, W = 0.04 (1 − φ*).
    ``relative_width`` = W/(1 − φ*) (MFiX 0.04), ``relative_end`` = (ε_end − ε*)/ε* (MFiX 0.01).
    """

    phi_star: float
    relative_width: float = 0.04
    relative_end: float = 0.01
    key: ClassVar[str] = "sigmoid"
    label: ClassVar[str] = "sigmoid blend (MFiX SIGM_BLEND, continuous)"
    reference: ClassVar[str] = "MFiX physprop.f blend_function (SIGM_BLEND)"

    def __post_init__(self) -> None:
        _check_star(self.phi_star, self.relative_width, "sigmoid blend relative width")
        check_range("sigmoid blend end offset relative_end", self.relative_end, low=0.0, high=self.relative_width,
                    high_open=True)

    @property
    def width(self) -> float:
        return self.relative_width * (1.0 - self.phi_star)

    @property
    def phi_end(self) -> float:
        """Solid fraction below which the blend is pure kinetic (w = 0): MFiX's blend_end."""
        return self.phi_star - self.relative_end * (1.0 - self.phi_star)

    @property
    def scale(self) -> float:
        """s = 1/b, b the raw sigmoid at the band end (MFiX uses 1/((b + 1)/2))."""
        return 1.0 + 0.01 ** (self.relative_end / self.relative_width)

    def _kinetic(self, phi: Any) -> Any:
        xp = namespace(phi)
        return self.scale / (1.0 + xp.exp(math.log(100.0) * (phi - self.phi_star) / self.width))

    def weight(self, phi: Any) -> Any:
        """w(φ) = 1 − kinetic weight; 0 for φ ≤ φ_end, → 1 as φ grows."""
        xp = namespace(phi)
        return xp.where(phi <= self.phi_end, 0.0, 1.0 - self._kinetic(phi))

    def dweight(self, phi: Any) -> Any:
        """dw/dφ = s (ln 100/W) E/(1 + E)², E = 100^((φ − φ*)/W), for φ > φ_end."""
        xp = namespace(phi)
        big = xp.exp(math.log(100.0) * (phi - self.phi_star) / self.width)
        dw = self.scale * (math.log(100.0) / self.width) * big / (1.0 + big) ** 2
        return xp.where(phi <= self.phi_end, 0.0, dw)


BLENDS: dict[str, type[FrictionPart]] = {cls.key: cls for cls in (TanhBlend, SigmoidBlend)}
