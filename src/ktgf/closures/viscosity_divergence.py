"""Viscosity laws applied on top of a theory: none, or the Bocquet et al. divergence.

Bocquet, Losert, Schalk, Lubensky & Gollub, Phys. Rev. E 65, 011307 (2001); used as a
closure by Abrahamsson et al. (2014).  Reconstructed in ``docs/model.md`` §5:

    η_vd = η(φ, θ) · ((φ_c − φ_f)/(φ_c − φ))^(β − 1)   for φ > φ_f,   η otherwise

so that, with an RDF diverging as (φ_c − φ)^(−1), η diverges as (φ_c − φ)^(−β).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from .._array import namespace


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

    Defaults φ_f = 0.49, φ_c = 0.64, β = 1.75.  In a dense layer at uniform stress this
    gives √θ ∝ γ̇^(1/(2β − 1)) and a velocity decay 2β − 1 times faster than that of √θ.
    """

    phi_f: float = 0.49
    phi_c: float = 0.64
    beta: float = 1.75
    key: ClassVar[str] = "bocquet-2001"
    label: ClassVar[str] = "Bocquet et al. (2001) divergence"

    def factor(self, phi: Any) -> Any:
        """Multiplier of η* at φ (1 for φ ≤ φ_f)."""
        xp = namespace(phi)
        ratio = (self.phi_c - self.phi_f) / (self.phi_c - xp.where(phi <= self.phi_f, self.phi_f, phi))
        return ratio ** (self.beta - 1.0)

    def options(self) -> dict[str, Any]:
        return {"phi_f": self.phi_f, "phi_c": self.phi_c, "beta": self.beta}
