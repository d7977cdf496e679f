"""The fits behind the registered models' fitted constants (the constants themselves live in ``closures/``).

* ``dense``: β of the viscosity-divergence RDF (:data:`ktgf.closures.dense.DENSE_BETA`) by
  :func:`fit_rdf_option` on the frictionless DEM uniform shear (``docs/dense.md``);
* ``frictional``: the EKT correlation-length constant c (:data:`ktgf.closures.friction.calibrated.FRICTIONAL_C`)
  by :func:`fit_correlation_constant` on one row of the frictional DEM uniform shear (``docs/friction.md`` §6).

Tests refit both from the shipped data and compare with the constants.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.optimize import least_squares

from ..closures.friction.calibrated import FIT_ROW
from ..closures.models import get_model
from ..closures.rdf import ViscosityDivergence
from ..shear.steady import steady_shear


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
