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

#: c of ``frictional``: :func:`ktgf.calibration.registry_fits.fit_correlation_constant` on ``dem_uniform_shear_friction.csv`` (docs/friction.md §6).
FRICTIONAL_C = 0.7921
#: (μ, φ) of the DEM row whose T fixes c.
FIT_ROW = (0.5, 0.5)
