"""The fits behind the registered models' fitted constants (the constants themselves live in ``closures/``).

* ``dense``: β of the viscosity-divergence RDF (:data:`ktgf.closures.dense.DENSE_BETA`) by
  :func:`fit_rdf_option` on the frictionless DEM uniform shear (``docs/dense.md``);
* ``frictional``: the EKT correlation-length constant c (:data:`ktgf.closures.friction.calibrated.FRICTIONAL_C`)
  by :func:`fit_correlation_constant` on one row of the frictional DEM uniform shear (``docs/friction.md`` §6).

Tests refit both from the shipped data and compare with the constants.  :data:`REGISTERED_FITS` says which
data files and states each fit used (``ktgf validate`` marks those rows *fitted*): change it with the fits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from ..closures.friction.calibrated import FIT_ROW
from ..closures.models import get_model
from ..closures.rdf import ViscosityDivergence
from ..shear.steady import steady_shear


@dataclass(frozen=True)
class FitSource:
    """States of one data file a model was fitted to: ``states`` are (μ, φ, e) tuples, or None for every state."""

    file: str
    states: tuple[tuple[float, float, float], ...] | None = None
    sha256: str = ""


#: What the registered fitted models were fitted to (their docstrings and docs/dense.md, docs/friction.md):
#: ``dense`` — β on both rows of dem_uniform_shear.csv (φ 0.3, 0.5; e 0.9); ``frictional`` — the EKT
#: constant c on T of the row μ = 0.5, φ = 0.5 of dem_uniform_shear_friction.csv.  The other registered
#: models have published parameters only: every row is a prediction.  Update this with the models.
REGISTERED_FITS: dict[str, tuple[FitSource, ...]] = {
    "dense": (FitSource("dem_uniform_shear.csv"),),
    "frictional": (FitSource("dem_uniform_shear_friction.csv", ((0.5, 0.5, 0.7),)),),
}


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
    def residual(x: np.ndarray) -> np.ndarray:
        return relative_errors(base.replace(rdf=ViscosityDivergence(**{option: float(x[0])})), rows)

    sol = least_squares(residual, [start], bounds=([bounds[0]], [bounds[1]]), xtol=1e-12)
    return float(sol.x[0]), sol


def fit_correlation_constant(rows: list[dict[str, float]], base: Any = None) -> float:
    """c such that the model's uniform-shear T equals the DEM's at :data:`FIT_ROW` (Brent's method on [0.3, 2])."""
    from scipy.optimize import brentq

    row = next(r for r in rows if (r["mu"], r["phi"]) == FIT_ROW)
    base = base or get_model("frictional")

    def miss(c: float) -> float:
        m = base.with_options(mu=row["mu"], dissipation="jenkins-berzi-2010", c=c)
        return float(steady_shear(m, row["phi"], row["e"]).T) / row["T"] - 1.0

    return float(brentq(miss, 0.3, 2.0, xtol=1e-12))
