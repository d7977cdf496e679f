"""Jenkins & Zhang (2002): closed-form effective restitution of nearly elastic, frictional spheres.

Jenkins & Zhang, "Kinetic theory for identical, frictional, nearly elastic spheres", Phys. Fluids 14, 1228
(2002), reduce Walton's collision rule (Coulomb friction μ, sticking tangential restitution β0) to an
effective normal restitution e_eff = e − f(μ) that enters the collisional dissipation only (the role of
Eq. 1.1 of ``docs/friction.md``).  The paper's text could not be read here; the form below is the one
coded in SedFoam (github.com/SedFoam/sedfoam, commit 079bc886, ``solver/kineticTheoryModels/
kineticTheoryModel/kineticTheoryModel.C``, block "Frictional dissipation (Jenkins & Zhang (2002))", with
"Tangential restitution coefficient assumed to be 0", i.e. β0 = 0, for solid spheres):

    μ0 = (7/2) μ (1 + e),    c = 1 − (2/π) arctan μ0,
    a1 = (μ/μ0) [π μ0 c + 2 μ0²/(1 + μ0²) (1 − 2μ/μ0)],
    a2 = (5/2)(μ/μ0) [(π/2) μ0 c + (μ0² − μ0⁴)/(1 + μ0²)²],
    b1 = μ²/(1 + μ0²),   b2 = (1/2)(μ/μ0) [(π/2) μ0 c + μ0²/(1 + μ0²)],
    f = (a1 − a2 b1/b2)/2,   e_eff = e − f.

(7/2 = 1 + 1/q with q = 4I/(m d²) = 2/5.)  Limits of these expressions (tested): f = 0 at μ = 0;
f → (π/2) μ and b1/b2 → (4/π) μ as μ → 0; f → 2(1 − 1/k)/k and b1/b2 → 1/k as μ → ∞, k = (7/2)(1 + e)
(12/49 and 1/7 at e = 1).  The ratio b1/b2 is the
rotational-to-translational temperature ratio of the steady state at small μ: ktgf's numerical Maxwellian
average of Walton's rule (:class:`~ktgf.closures.friction.collisions.WaltonRestitution`, our derivation,
Monte-Carlo checked) gives the same (π/2)μ and (4/π)μ to O(μ) and O(1 − e) (tested) — two independent
routes to the same nearly elastic, weakly frictional limit.  Away from it they part: as μ → ∞ every
contact sticks and the exact Maxwellian average is that of rough spheres with β = 0 (η = 1/7):
1 − e_eff² = 4[η(1 − η) − η³/(q − η)] = 0.444 at e = 1 and T_rot/T = 2/9, while the closed form has
f = 2η(1 − η) = 12/49 (2f = 0.490: the first term alone, without the energy that rotation returns) and
b1/b2 = 1/7; and the closed form is a nearly elastic theory (at μ = 0.01 the excess dissipation differs by
6 % at e = 0.9 and 23 % at e = 0.7).  Pure NumPy/JAX (differentiable in e and μ, unlike the quadrature of
:class:`~ktgf.closures.friction.collisions.WaltonRestitution`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from ..._array import namespace
from ._part import FrictionPart, check_friction_coefficient, check_range


@dataclass(frozen=True)
class JenkinsZhangRestitution(FrictionPart):
    """e_eff = e − f(e, μ) of Jenkins & Zhang (2002) as coded in SedFoam (module docstring); β0 = 0, solid spheres."""

    key: ClassVar[str] = "jenkins-zhang-2002"
    label: ClassVar[str] = "Jenkins–Zhang e_eff"
    reference: ClassVar[str] = ("Jenkins & Zhang, Phys. Fluids 14, 1228 (2002), as coded in SedFoam "
                                "(kineticTheoryModel.C, commit 079bc886)")

    def _terms(self, e: Any, mu: Any) -> tuple[Any, Any, Any]:
        """(a1, a2, b1/b2), written with μ/μ0 = 1/k, k = (7/2)(1 + e), so that μ = 0 needs no division:
        b1/b2 = 2μ/((1 + μ0²)(π/2)c + μ0)."""
        xp = namespace(e, mu)
        k = 3.5 * (1.0 + e)
        mu0 = k * mu
        c = 1.0 - (2.0 / math.pi) * xp.arctan(mu0)
        s = mu0 * mu0
        a1 = (math.pi * mu0 * c + 2.0 * s / (1.0 + s) * (1.0 - 2.0 / k)) / k
        a2 = 2.5 * (0.5 * math.pi * mu0 * c + (s - s * s) / (1.0 + s) ** 2) / k
        ratio = 2.0 * mu / ((1.0 + s) * 0.5 * math.pi * c + mu0)
        return a1, a2, ratio

    def friction_loss(self, e: Any, mu: Any) -> Any:
        """f = (a1 − a2 b1/b2)/2 (0 at μ = 0, slope π/2 there)."""
        a1, a2, ratio = self._terms(e, mu)
        return 0.5 * (a1 - a2 * ratio)

    def effective_restitution(self, e: Any, mu: Any) -> Any:
        """e_eff = e − f."""
        return e - self.friction_loss(e, mu)

    def inelasticity(self, e: Any, mu: Any) -> Any:
        """1 − e_eff², the factor of the collisional dissipation."""
        return 1.0 - self.effective_restitution(e, mu) ** 2

    def rotational_ratio(self, e: Any, mu: Any) -> Any:
        """b1/b2: T_rot/T of the steady state to leading order in μ and 1 − e (module docstring); 0 at μ = 0."""
        return self._terms(e, mu)[2]

    def check(self, e: Any, mu: Any) -> None:
        """Raise :class:`~ktgf.errors.InputError` for μ < 0 or an e_eff outside (−1, 1]."""
        check_friction_coefficient(mu)
        check_range("effective restitution e_eff", self.effective_restitution(e, mu), low=-1.0, high=1.0,
                    low_open=True, why="from e and mu")
