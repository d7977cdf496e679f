"""The one fitted number of the ``frictional`` model: the correlation-length constant c of extended kinetic theory.

``frictional`` = RET × Chialvo–Sundaresan χ diverging at φ_c(μ) × Walton's collision rule (β0 = 1) ×
the EKT dissipation correction ``jenkins-berzi-2010`` (:mod:`ktgf.closures.dissipation`) whose constant c
is solved exactly from the granular temperature T = θ/(γ̇d)² of ONE row of the shared frictional DEM file
``dem_uniform_shear_friction.csv``: μ = 0.5, φ = 0.5 (:data:`FIT_ROW`).  Everything else is predicted:
p* and τ/p of that row, the row μ = 0.5, φ = 0.4 and the frictionless row (``docs/friction.md`` §6).

Why this parameter: without it the no-fit composition's T falls from φ = 0.4 to 0.5 while the DEM's rises
(0.169 → 0.184); the correlation length, which reduces the dissipation where dγ̇/√θ is large in dense flow,
is the one part of the registry that acts in that direction.  At the fitted c it is inactive at φ = 0.4
(L = d there) and at the frictionless row, so those are unchanged by the fit.
"""

from __future__ import annotations

from typing import Any

#: c of ``frictional``: :func:`fit_correlation_constant` on ``dem_uniform_shear_friction.csv`` (docs/friction.md §6).
FRICTIONAL_C = 0.7921
#: (μ, φ) of the DEM row whose T fixes c.
FIT_ROW = (0.5, 0.5)


def fit_correlation_constant(rows: list[dict[str, float]], base: Any = None) -> float:
    """c such that the model's uniform-shear T equals the DEM's at :data:`FIT_ROW` (Brent's method on [0.3, 2])."""
    from scipy.optimize import brentq

    from ..friction_shear import model_uniform_shear
    from ..models import get_model

    row = next(r for r in rows if (r["mu"], r["phi"]) == FIT_ROW)
    base = base or get_model("frictional")

    def miss(c: float) -> float:
        m = base.with_options(mu=row["mu"], dissipation="jenkins-berzi-2010", c=c)
        return float(model_uniform_shear(m, [row["phi"]], row["e"]).T[0]) / row["T"] - 1.0

    return float(brentq(miss, 0.3, 2.0, xtol=1e-12))
