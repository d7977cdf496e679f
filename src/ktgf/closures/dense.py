"""The fitted numbers of the recommended dense model ``dense`` (the frictionless member of one family for all μ).

Composition (``docs/dense.md``): Garzó & Dufty (1999) RET (model.md §3) × the sheared χ(φ, s) of
:class:`~ktgf.closures.jamming.FrictionalPowerLaw` (Eq. 3 there) — Carnahan–Starling plus the
Chialvo–Sundaresan (2013) jamming term a φ²/(φ_J − φ)^b, diverging at the published frictionless jamming
fraction φ_J(0) = 6/(6 + 2√3) = 0.634 of the contact-number law (not fitted), whose amplitude grows by
A γ̇/ν0 under shear — × the extended-kinetic-theory correlation length ``jenkins-berzi-2010``
(:mod:`ktgf.closures.dissipation`) with constant c.

a, b, c and A are fitted together (:func:`ktgf.calibration.registry_fits.fit_sheared_structure`: log-ratios
of T, p/(nT) and τ/p) on the frictionless DEM uniform shear at e = 0.9, φ 0.3–0.6
(``dem_uniform_shear.csv`` + ``dem_uniform_shear_extra.csv``: 7 states, 21 points), on p/(nT) of the
homogeneous cooling states (``dem_hcs_cooling.csv``, 10 points: χ without shear) and on Torquato's (1995,
Eq. 13) metastable contact value at φ 0.55, 0.575, 0.6 (3 points: χ without shear near jamming);
34 points, 8.5 per parameter.  The μ = 0, e = 0.7 row of the frictional file and the Couette file are
predictions, not fitted.  Why the sheared part, and why the static points: ``docs/dense_physics.md`` §8
(without A the dense states need χ 30–85 % above the static hard-sphere value; without the static points
a goes to 0 and the shear of a dense frictional-wall Couette cell gathers in a wall band as thin as the grid).
"""

from __future__ import annotations

#: a, b and the sheared part A of χ and c of the EKT length, from
#: :func:`ktgf.calibration.registry_fits.fit_sheared_structure` (docs/dense.md §3).
DENSE_PARAMETERS: dict[str, float] = {"a": 0.02955, "exponent": 2.0502, "c": 0.8854, "shear_amplitude": 0.3364}
