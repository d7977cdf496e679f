"""The recommended dense model ``dense``: RET with the viscosity-divergence RDF, divergence exponent fitted.

Composition (``docs/dense.md``): Garzó & Dufty (1999) RET (model.md §3) × the viscosity-divergence
RDF of model.md §2 (φ_f = 0.49, φ_c = 0.64 as published, smooth junction) with its exponent β
fitted to the frictionless DEM uniform shear at e = 0.9 (``shared/data/dem_uniform_shear.csv``,
φ = 0.3 and 0.5): least squares on the relative errors of η/η0 and p/(nT) of the Navier–Stokes
closed forms (:mod:`ktgf.shear.steady`).  The e = 0.7 frictionless row of
``dem_uniform_shear_friction.csv`` and the Couette file are predictions, not fitted.

Only one parameter is fitted: the two φ of the file fix χ(0.5) and nothing else, so fitting φ_f
instead of β gives the same uniform-shear residuals (both are in ``docs/dense.md``); the two
differ where the Couette core goes beyond φ = 0.5, and there the β fit predicts the DEM wall
stresses (the one use of the Couette file: choosing which single parameter to fit).
"""

from __future__ import annotations

#: β of ``dense``, from :func:`ktgf.calibration.registry_fits.fit_rdf_option` on ``dem_uniform_shear.csv`` (docs/dense.md).
DENSE_BETA = 4.052
