"""The recommended dense model ``dense``: RET with the viscosity-divergence RDF, divergence exponent fitted.

Composition (``docs/dense.md``): Garzó & Dufty (1999) RET (model.md §3) × the viscosity-divergence
RDF of model.md §2 (φ_f = 0.49, φ_c = 0.64 as published, smooth junction) with its exponent β
fitted to the frictionless DEM uniform shear at e = 0.9 (``shared/data/dem_uniform_shear.csv``,
φ = 0.3 and 0.5): least squares on the relative errors of η/η0 and p/(nT) of the Navier–Stokes
closed forms (:mod:`ktgf.couette.uniform_shear`).  The e = 0.7 frictionless row of
``dem_uniform_shear_friction.csv`` and the Couette file are predictions, not fitted.

Only one parameter is fitted: the two φ of the file fix χ(0.5) and nothing else, so fitting φ_f
instead of β gives the same uniform-shear residuals (both are in ``docs/dense.md``); the two
differ where the Couette core goes beyond φ = 0.5, and there the β fit predicts the DEM wall
stresses (the one use of the Couette file: choosing which single parameter to fit).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .rdf import ViscosityDivergence

#: β of ``dense``, from :func:`fit_rdf_option` on ``dem_uniform_shear.csv`` (docs/dense.md).
DENSE_BETA = 4.052


def relative_errors(model: Any, rows: np.ndarray) -> np.ndarray:
    """[η*/η*_DEM − 1, p*/p*_DEM − 1] for every DEM row (Navier–Stokes uniform shear)."""
    r = model.reduced(rows["phi"], rows["e"])
    eta = np.broadcast_to(np.asarray(r.eta, dtype=float), rows.shape)
    p = np.broadcast_to(np.asarray(r.p, dtype=float), rows.shape)
    return np.concatenate([eta / rows["eta_over_eta0"] - 1.0, p / rows["p_over_nT"] - 1.0])


def fit_rdf_option(base: Any, rows: np.ndarray, option: str = "beta", *, start: float = 1.75,
                   bounds: tuple[float, float] = (1.0, 8.0)) -> tuple[float, Any]:
    """Least-squares value of one option of the viscosity-divergence RDF with ``base``'s theory on DEM ``rows``.

    Returns (value, scipy result); the RDF's other options keep their published values.
    """
    from scipy.optimize import least_squares

    def residual(x: np.ndarray) -> np.ndarray:
        return relative_errors(base.replace(rdf=ViscosityDivergence(**{option: float(x[0])})), rows)

    sol = least_squares(residual, [start], bounds=([bounds[0]], [bounds[1]]), xtol=1e-12)
    return float(sol.x[0]), sol
