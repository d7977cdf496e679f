"""Corrections of the collisional dissipation (cooling rate ζ0): none, or extended kinetic theory.

Extended kinetic theory (EKT) — Jenkins, Granular Matter 10, 47 (2007); Jenkins & Berzi,
Granular Matter 12, 151 (2010); used for frictionless spheres by Vescovi, Berzi, Richard &
Brodu, Phys. Fluids 26, 053305 (2014) and Berzi & Vescovi, Phys. Fluids 27, 013302 (2015).
In dense shear, velocity correlations between colliding particles reduce the energy lost per
collision; EKT expresses this by dividing the dissipation rate by a correlation length L (in
units of d) that grows with the shear rate:

    ζ0 → ζ0 · d/L,     L/d = max(1, Λ(φ, e) · d γ̇/√θ),
    Λ = (c/2) √(2J/(15(1 − e))) G^(1/3),     G = φχ,
    J = (1 + e)/2 + (π/32) [5 + 2(1 + e)(3e − 1)G][5 + 4(1 + e)G] / ([24 − 6(1 − e)² − 5(1 − e²)] G²)

with c an order-one constant that those papers fit to particle data.  The formula is taken
from Jenkins & Berzi (2010) as we recall it; its equation number, the prefactor of Λ and the value
of c used there are not verified against the printed paper (searched, docs/dense.md §2.4) — treat
c as a parameter to fit.  J is verified by identity: it is the Garzó & Dufty (1999) shear
viscosity with the Sonine correction c* = 0 in units of (8/(5√π)) ρ_s d φ G √T (tested to 1e-12).
The papers also use J in their viscosity; here only L is taken, so the correction can be composed
with any theory.

Where it applies: the factor needs the local shear measure s = d γ̇/√θ.  With ``shear=None``
(homogeneous cooling, the HCS stability analysis, the 3D solver, the Couette solver) s = 0 and
L = d: the standard theory, exactly.  The uniform-shear closed forms
(:mod:`ktgf.shear.steady`) solve the energy balance with L consistently.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from .._array import namespace
from .options import real_option


@dataclass(frozen=True)
class NoDissipationCorrection:
    """The theory's own cooling rate, unchanged (L = d)."""

    key: ClassVar[str] = "none"
    label: ClassVar[str] = "theory's own"

    def coefficient(self, phi: Any, e: Any, chi: Any) -> Any:
        """Λ in L/d = max(1, Λ s): 0, so L = d always."""
        return 0.0 * phi

    def factor(self, phi: Any, e: Any, chi: Any, shear: Any = None) -> Any:
        """Multiplier d/L of ζ0 (1 everywhere)."""
        return 1.0

    def options(self) -> dict[str, Any]:
        return {}


def ekt_j(e: Any, G: Any) -> Any:
    """J(e, G) of extended kinetic theory (Jenkins & Berzi 2010), G = φχ.

    Equal to the Garzó–Dufty (1999) shear viscosity without the Sonine correction divided by
    (8/(5√π)) ρ_s d φ G √T (the Enskog value at e = 1; ``tests/closures/test_dense_models.py``).
    """
    num = (5.0 + 2.0 * (1.0 + e) * (3.0 * e - 1.0) * G) * (5.0 + 4.0 * (1.0 + e) * G)
    den = (24.0 - 6.0 * (1.0 - e) ** 2 - 5.0 * (1.0 - e**2)) * G**2
    return 0.5 * (1.0 + e) + (math.pi / 32.0) * num / den


@dataclass(frozen=True)
class CorrelationLength:
    """EKT correlation length: ζ0 multiplied by d/L, L/d = max(1, Λ(φ, e) dγ̇/√θ) (module docstring).

    Parameters
    ----------
    c : float
        The order-one constant of Λ = (c/2) √(2J/(15(1 − e))) G^(1/3) (> 0; default 1).
    """

    c: float = 1.0
    key: ClassVar[str] = "jenkins-berzi-2010"
    label: ClassVar[str] = "EKT correlation length (Jenkins & Berzi 2010)"

    def __post_init__(self) -> None:
        real_option("c", self.c, owner=f"dissipation correction {self.key}", low=0.0, why="correlation-length constant")

    def coefficient(self, phi: Any, e: Any, chi: Any) -> Any:
        """Λ(φ, e) such that L/d = max(1, Λ dγ̇/√θ); +inf at e = 1 (no dissipation to correct)."""
        xp = namespace(phi, e, chi)
        G = phi * chi
        one_e = 1.0 - e
        safe = xp.where(one_e > 0, one_e, 1.0)
        lam = 0.5 * self.c * xp.sqrt(2.0 * ekt_j(e, G) / (15.0 * safe)) * G ** (1.0 / 3.0)
        return xp.where(one_e > 0, lam, xp.inf)

    def factor(self, phi: Any, e: Any, chi: Any, shear: Any = None) -> Any:
        """d/L at shear measure s = dγ̇/√θ (``None`` or 0: no shear, factor 1)."""
        if shear is None:
            return 1.0
        xp = namespace(phi, e, chi, shear)
        lam = self.coefficient(phi, e, chi)
        ls = xp.where(shear > 0, lam * xp.where(shear > 0, shear, 0.0), 0.0)
        ls = xp.where(xp.isfinite(ls), ls, 1.0)  # e = 1: nothing is dissipated, the factor is moot
        return 1.0 / xp.maximum(1.0, ls)

    def options(self) -> dict[str, Any]:
        return {"c": self.c}


#: Dissipation corrections by key (``Model.with_options(dissipation=KEY)``).
DISSIPATIONS: dict[str, type] = {cls.key: cls for cls in (NoDissipationCorrection, CorrelationLength)}
