"""The fitted numbers of the recommended dense model ``dense`` (the frictionless member of one family for all μ).

Composition (``docs/dense.md``): Garzó & Dufty (1999) RET (model.md §3) × the χ of
:class:`~ktgf.closures.jamming.FrictionalPowerLaw` — Carnahan–Starling plus the Chialvo–Sundaresan
(2013) jamming term a φ²/(φ_J − φ)^b, diverging at the published frictionless jamming fraction
φ_J(0) = 6/(6 + 2√3) = 0.634 of the contact-number law (not fitted) — × the extended-kinetic-theory
correlation length ``jenkins-berzi-2010`` (:mod:`ktgf.closures.dissipation`) with constant c.

a, b and c are fitted together (:func:`ktgf.calibration.registry_fits.fit_frictionless`: log-ratios of
T, p/(nT) and τ/p) on the frictionless DEM uniform shear at e = 0.9, φ 0.3–0.6
(``dem_uniform_shear.csv`` + ``dem_uniform_shear_extra.csv``: 7 states, 21 points, 7 per parameter).
The μ = 0, e = 0.7 row of the frictional file and the Couette file are predictions, not fitted.
Why b is fitted and not kept at Chialvo & Sundaresan's 1.5: at the published φ_J(0) = 0.634 the DEM's
own excess of χ over Carnahan–Starling rises with a local exponent of 1.9–2.2 between neighbouring
states; b = 1.5 fits only with φ_J(0) moved to 0.623, below the published frictionless value
(``docs/dense.md`` §2 has both fits and their cross-validated errors).
"""

from __future__ import annotations

#: a, b of χ and c of the EKT length, from :func:`ktgf.calibration.registry_fits.fit_frictionless` (docs/dense.md).
DENSE_PARAMETERS: dict[str, float] = {"a": 0.1238, "exponent": 1.9102, "c": 0.8861}
