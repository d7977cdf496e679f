"""The recommended dense model ``dense``: RET with the viscosity-divergence RDF, freezing point fitted.

Composition (``docs/dense.md``): Garzó & Dufty (1999) RET (model.md §3) × the viscosity-divergence
RDF of model.md §2 (φ_c = 0.64, β = 1.75 as published, smooth junction) with its junction point
φ_f fitted to the frictionless DEM uniform shear at e = 0.9 (``shared/data/dem_uniform_shear.csv``,
φ = 0.3 and 0.5): least squares on the relative errors of η/η0 and p/(nT) of the Navier–Stokes
closed forms (:mod:`ktgf.couette.uniform_shear`).  The e = 0.7 frictionless row of
``dem_uniform_shear_friction.csv`` and the Couette file are predictions, not fitted.

Only one parameter is fitted: the two φ of the file determine the dense rise of χ between
0.3 and 0.5 and nothing else (two-parameter fits of φ_c and β, or of the jamming power law,
run to their bounds — see ``docs/dense.md``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .rdf import ViscosityDivergence

#: φ_f of ``dense``, from :func:`fit_freezing_point` on ``dem_uniform_shear.csv`` (docs/dense.md).
DENSE_PHI_F = 0.4617


def relative_errors(model: Any, rows: np.ndarray) -> np.ndarray:
    """[η*/η*_DEM − 1, p*/p*_DEM − 1] for every DEM row (Navier–Stokes uniform shear)."""
    r = model.reduced(rows["phi"], rows["e"])
    eta = np.broadcast_to(np.asarray(r.eta, dtype=float), rows.shape)
    p = np.broadcast_to(np.asarray(r.p, dtype=float), rows.shape)
    return np.concatenate([eta / rows["eta_over_eta0"] - 1.0, p / rows["p_over_nT"] - 1.0])


def fit_freezing_point(base: Any, rows: np.ndarray, *, bounds: tuple[float, float] = (0.3, 0.6)) -> tuple[float, Any]:
    """Least-squares φ_f of ``base``'s theory with the viscosity-divergence RDF on DEM ``rows``.

    Returns (φ_f, scipy result).  φ_c = 0.64 and β = 1.75 stay at their published values.
    """
    from scipy.optimize import least_squares

    def residual(x: np.ndarray) -> np.ndarray:
        return relative_errors(base.replace(rdf=ViscosityDivergence(phi_f=float(x[0]))), rows)

    sol = least_squares(residual, [0.49], bounds=([bounds[0]], [bounds[1]]), xtol=1e-12)
    return float(sol.x[0]), sol
