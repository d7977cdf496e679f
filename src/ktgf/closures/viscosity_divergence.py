"""Viscosity laws applied on top of a theory: none, or the Bocquet et al. divergence.

Bocquet, Losert, Schalk, Lubensky & Gollub, Phys. Rev. E 65, 011307 (2001); used as a
closure by Abrahamsson et al. (2014).  Reconstructed in ``docs/model.md`` §5:

    η_vd = η(φ, θ) · ((φ_c − φ_f)/(φ_c − φ))^(β − 1)   for φ > φ_f,   η otherwise

so that, with an RDF diverging as (φ_c − φ)^(−1), η diverges as (φ_c − φ)^(−β).  The factor
has the same slope jump at φ_f as the piecewise RDFs (0 below, (β − 1)/(φ_c − φ_f) above); the
default ``junction="c1"`` bridges it (C², quintic Hermite) over [φ_f, φ_f + w] exactly as they do
(:mod:`ktgf.closures.junction`), ``junction="c0"`` keeps the plain switch of model.md §5.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from .._array import namespace, power
from .junction import DEFAULT_WIDTH, JUNCTIONS, hermite
from .options import CLOSE_PACKING, choice_option, real_option


@dataclass(frozen=True)
class NoViscosityCorrection:
    """The theory's own shear viscosity, unchanged."""

    key: ClassVar[str] = "none"
    label: ClassVar[str] = "theory's own"

    def factor(self, phi: Any) -> Any:
        """Multiplier of η* (1 everywhere)."""
        return 1.0

    def options(self) -> dict[str, Any]:
        return {}


@dataclass(frozen=True)
class ViscosityDivergenceLaw:
    """η multiplied by ((φ_c − φ_f)/(φ_c − φ))^(β − 1) above φ_f (model.md §5).

    Defaults φ_f = 0.49, φ_c = 0.64, β = 1.75, smooth (C²) junction over [φ_f, φ_f + 0.01].  In a dense
    layer at uniform stress this gives √θ ∝ γ̇^(1/(2β − 1)) and a velocity decay 2β − 1 times
    faster than that of √θ.
    """

    phi_f: float = 0.49
    phi_c: float = 0.64
    beta: float = 1.75
    junction: str = "c1"
    junction_width: float = DEFAULT_WIDTH
    key: ClassVar[str] = "bocquet-2001"
    label: ClassVar[str] = "Bocquet et al. (2001) divergence"

    def __post_init__(self) -> None:
        owner = f"viscosity law {self.key}"
        real_option("phi_f", self.phi_f, owner=owner, low=0.0, high=1.0, high_open=True)
        real_option("phi_c", self.phi_c, owner=owner, low=self.phi_f, high=CLOSE_PACKING,
                    why="phi_f < phi_c <= close packing pi/sqrt(18)")
        real_option("beta", self.beta, owner=owner, low=0.0, high=10.0, why="divergence exponent, at most 10")
        choice_option("junction", self.junction, JUNCTIONS, owner=owner)
        real_option("junction_width", self.junction_width, owner=owner, low=0.0, high=self.phi_c - self.phi_f,
                    high_open=True, why="0 < width < phi_c - phi_f")

    def _dense(self, phi: Any) -> Any:
        return power((self.phi_c - self.phi_f) / (self.phi_c - phi), self.beta - 1.0)

    def factor(self, phi: Any) -> Any:
        """Multiplier of η* at φ (1 for φ ≤ φ_f)."""
        xp = namespace(phi)
        dense = self._dense(xp.where(phi <= self.phi_f, self.phi_f, phi))
        if self.junction == "c0":
            return dense
        b = self.phi_f + self.junction_width
        fb = self._dense(b)
        sb = (self.beta - 1.0) * fb / (self.phi_c - b)
        bridge, _ = hermite(phi, self.phi_f, b, (1.0, 0.0, 0.0), (fb, sb, self.beta * sb / (self.phi_c - b)))
        return xp.where(phi <= self.phi_f, 1.0, xp.where(phi < b, bridge, dense))

    def options(self) -> dict[str, Any]:
        return {"phi_f": self.phi_f, "phi_c": self.phi_c, "beta": self.beta, "junction": self.junction,
                "junction_width": self.junction_width}
