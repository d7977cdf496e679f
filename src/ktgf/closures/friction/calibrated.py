"""The fitted numbers of the ``frictional`` model beyond those of ``dense`` (one family for all μ).

``frictional`` = ``dense`` (RET × the sheared χ of :class:`~ktgf.closures.jamming.FrictionalPowerLaw` × EKT
length, with a, b, c, A of :data:`ktgf.closures.dense.DENSE_PARAMETERS`) × Walton's collision rule with β0 = 1
(:mod:`ktgf.closures.friction.model_slot`), at friction μ (default 0.5).  Friction enters in four
places: the collisional dissipation (Walton, no fitted number), the collisional stress of the tangential
impulses and the part of its work that is dissipated (closed forms of Walton's rule, no fitted number;
docs/friction.md §7.1), the jamming fraction φ_J(μ) of the contact-number law (scale μ_Z) and the
amplitude a(μ) = a (1 + k μ/(μ + μ_Z)) of the jamming term (its sheared part grows by the same factor).

μ_Z and k are fitted (:func:`ktgf.calibration.registry_fits.fit_frictional`, log-ratios of T, p/(nT),
τ/p) on the frictional DEM uniform shear at μ = 0.5, e = 0.7, φ 0.3–0.57
(``dem_uniform_shear_friction.csv`` + ``_extra``: 7 states, 21 points, 10.5 per parameter), a, b, c, A
held at step 1 (:func:`~ktgf.calibration.registry_fits.fit_sheared_structure`).  At μ = 0 both drop out
exactly: ``frictional`` with μ = 0 is ``dense`` (tested).
"""

from __future__ import annotations

#: The friction part of the registered family at μ > 0 (``frictional``; ``dense`` is μ = 0): Walton's rule with β0 = 1
#: and the tangential impulses' collisional stress (docs/friction.md §6.0, §7.1); μ is the model's.
FAMILY_FRICTION: dict[str, object] = {"restitution": "walton", "beta0": 1.0, "tangential_stress": "maxwellian"}
#: μ_Z (mu_scale) and k (amplitude_growth), from :func:`ktgf.calibration.registry_fits.fit_frictional` (docs/friction.md §6).
FRICTIONAL_PARAMETERS: dict[str, float] = {"mu_scale": 0.5633, "amplitude_growth": 1.7836}
