"""The fits behind the registered ``dense`` and ``frictional`` models (the constants live in ``closures/``).

One family for all μ (``docs/dense.md``, ``docs/friction.md``): RET × :class:`~ktgf.closures.jamming.
FrictionalPowerLaw` χ (diverging at the contact-number φ_J(μ)) × the EKT correlation length × Walton's
collision rule (β0 = 1) for μ > 0.  The parameters are chosen in two steps, on homogeneous flows only:

1. :func:`fit_sheared_structure` — a, b and the sheared part A of χ and c of the EKT length on the
   frictionless uniform shear (``dem_uniform_shear.csv`` + ``dem_uniform_shear_extra.csv``, e = 0.9,
   φ 0.3–0.6), on p/(nT) of the homogeneous cooling states (``dem_hcs_cooling.csv``) and on Torquato's
   static contact value near jamming (:func:`static_contact_states`); :func:`fit_frictionless` is the same
   step without the sheared part, the cooling and the static points (the registered fit before 2026-12);
2. :func:`fit_frictional` — the friction scale μ_Z of φ_J(μ) and the amplitude growth k on the
   frictional uniform shear at μ > 0 (``dem_uniform_shear_friction.csv`` + ``_extra``), the
   frictionless parameters held.

Residuals are the log-ratios model/DEM of T, p/(nT) and τ/p at every state.  :func:`leave_one_out`
refits without each state in turn and predicts it (the error a user should quote).  The μ = 0, e = 0.7
row of the frictional file and the Couette file are predictions, never fitted.  Tests refit from the
shipped data and compare with the registered constants.  :data:`REGISTERED_FITS` says which data files
and states each fit used (``ktgf validate`` marks those rows *fitted*): change it with the fits.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from ..closures.dissipation import CorrelationLength
from ..closures.friction.calibrated import FAMILY_FRICTION
from ..closures.friction.model_slot import Friction
from ..closures.garzo_dufty1999 import GarzoDufty1999
from ..closures.jamming import CoordinationJamming, FrictionalPowerLaw
from ..closures.models import Model
from ..closures.rdf import Torquato
from ..data import (
    FRICTION_SHEAR,
    FRICTION_SHEAR_EXTRA,
    HCS_COOLING,
    UNIFORM_SHEAR,
    UNIFORM_SHEAR_EXTRA,
    read_cooling,
    read_friction_shear,
    shipped,
    uniform_shear_records,
)
from ..errors import InputError
from ..shear.steady import steady_shear


@dataclass(frozen=True)
class FitSource:
    """States of one data file a model was fitted to.

    ``states`` are (μ, φ, e) tuples, or None for every state; ``quantities`` the columns that entered the fit,
    or None for every one (e.g. only p/(nT) of the cooling file: its cooling rates are predictions).
    """

    file: str
    states: tuple[tuple[float, float, float], ...] | None = None
    sha256: str = ""
    quantities: tuple[str, ...] | None = None


#: The μ = 0.5 rows (μ, φ, e) of the base and extra frictional files (the base file's μ = 0, e = 0.7 row is a
#: prediction); ``tests/calibration/test_calibration_validate.py`` checks them against the files.
_MU_HALF_BASE = ((0.5, 0.4, 0.7), (0.5, 0.5, 0.7))
_MU_HALF_EXTRA = ((0.5, 0.3, 0.7), (0.5, 0.45, 0.7), (0.5, 0.52, 0.7), (0.5, 0.55, 0.7), (0.5, 0.57, 0.7))
#: The cooling file's part of step 1: p/(nT) of every state (χ without shear); its cooling rates stay predictions.
_COOLING = FitSource(HCS_COOLING, quantities=("p_over_nT",))
#: What the registered fitted models were fitted to (docs/dense.md §3, docs/friction.md §6.0): ``dense`` — a, b, c, A
#: on every state of the frictionless uniform shear (base + extra) and p/(nT) of every cooling state (and Torquato's
#: static χ, a published formula, not a file); ``frictional`` — those, and μ_Z, k on every μ = 0.5 state of the
#: frictional uniform shear (base + extra).  The other registered models have published parameters only: every
#: row is a prediction.  Update this with the fits.
REGISTERED_FITS: dict[str, tuple[FitSource, ...]] = {
    "dense": (FitSource(UNIFORM_SHEAR), FitSource(UNIFORM_SHEAR_EXTRA), _COOLING),
    "frictional": (FitSource(UNIFORM_SHEAR), FitSource(UNIFORM_SHEAR_EXTRA), _COOLING,
                   FitSource(FRICTION_SHEAR, _MU_HALF_BASE), FitSource(FRICTION_SHEAR_EXTRA, _MU_HALF_EXTRA)),
}


def fitted_restitutions(name: str, mu: float) -> tuple[float, ...] | None:
    """The restitutions at which the registered model ``name`` was fitted for friction μ (``None``: no fit on record).

    From :data:`REGISTERED_FITS`: frictionless states fix the μ = 0 part, frictional ones (μ > 0) the rest, so
    ``frictional`` at μ > 0 answers with the e of its frictional states only (``ktgf shear`` says when a requested
    e lies outside them: ``docs/friction.md`` §6.2 measures what that costs).
    """
    sources = REGISTERED_FITS.get(name)
    if not sources:
        return None
    found: set[float] = set()
    for src in sources:
        if src.quantities is not None and "T" not in src.quantities:  # no sheared state (the cooling file's p/(nT))
            continue
        if src.states is not None:
            found |= {e for m, _, e in src.states if (m > 0.0) == (mu > 0.0)}
        elif mu == 0.0:  # a whole frictionless file
            found |= {float(r["e"]) for r in uniform_shear_records(shipped(src.file))}
    return tuple(sorted(found)) or None


#: Observables compared at every state (log-ratio residuals).
OBSERVABLES: tuple[str, ...] = ("T", "p_over_nT", "tau_over_p")
#: Frictionless parameters (step 1) with their starts and bounds.
FRICTIONLESS_PARAMETERS = {"a": (0.3, 0.0, 5.0), "exponent": (1.5, 0.5, 4.0), "c": (1.0, 0.05, 5.0)}
#: Step 1 with the sheared χ (Eq. (3) of FrictionalPowerLaw): start, lower, upper of a, b, c and A.
SHEARED_PARAMETERS = {**FRICTIONLESS_PARAMETERS, "a": (0.05, 0.0, 5.0), "exponent": (2.0, 0.5, 4.0),
                      "shear_amplitude": (0.3, 0.0, 20.0)}
#: Frictional parameters (step 2): μ_Z's lower bound is raised to keep every fitted state below φ_J(μ).
FRICTIONAL_PARAMETERS = {"mu_scale": (0.6, 0.01, 50.0), "amplitude_growth": (3.0, 0.0, 100.0)}


def frictionless_states(paths: tuple[Any, ...] | None = None) -> dict[str, np.ndarray]:
    """The frictionless uniform-shear states (base + extra file), with τ/p from the DEM's own columns.

    τ/p = η* (5/16)√(T/π) / (p* (6φ/π) T) in the files' units (d = m = 1).
    """
    paths = paths or (shipped(UNIFORM_SHEAR), shipped(UNIFORM_SHEAR_EXTRA))
    rows = np.concatenate([uniform_shear_records(p) for p in paths])
    rows = rows[np.argsort(rows["phi"], kind="stable")]
    tau = rows["eta_over_eta0"] * (5.0 / 16.0) * np.sqrt(rows["T"] / math.pi)
    p = rows["p_over_nT"] * (6.0 * rows["phi"] / math.pi) * rows["T"]
    return {"mu": np.zeros(rows.size), "phi": rows["phi"].astype(float), "e": rows["e"].astype(float),
            "T": rows["T"].astype(float), "p_over_nT": rows["p_over_nT"].astype(float), "tau_over_p": tau / p}


def frictional_states(paths: tuple[Any, ...] | None = None, *, frictional_only: bool = True) -> dict[str, np.ndarray]:
    """The frictional uniform-shear states (base + extra file); μ > 0 only unless ``frictional_only=False``."""
    paths = paths or (shipped(FRICTION_SHEAR), shipped(FRICTION_SHEAR_EXTRA))
    recs = [r for p in paths for r in read_friction_shear(p) if r["mu"] > 0.0 or not frictional_only]
    recs.sort(key=lambda r: (r["mu"], r["e"], r["phi"]))
    out = {k: np.array([r[k] for r in recs], dtype=float) for k in ("mu", "phi", "e", "T", "tau_over_p", "Trot_over_T")}
    out["p_over_nT"] = np.array([r["p_star"] / (r["phi"] * r["T"]) for r in recs])
    return out


def subset(states: dict[str, np.ndarray], keep: Any) -> dict[str, np.ndarray]:
    """The states selected by a boolean mask or index array."""
    return {k: v[keep] for k, v in states.items()}


def family_model(name: str = "family", *, mu: float = 0.0, a: float, exponent: float, c: float, mu_scale: float = 0.1,
                 amplitude_growth: float = 0.0, shear_amplitude: float = 0.0) -> Model:
    """The one family at friction μ: RET × FrictionalPowerLaw χ (sheared part A = ``shear_amplitude``) × EKT length (c)
    × Walton (β0 = 1) with the tangential impulses' collisional stress if μ > 0."""
    rdf = FrictionalPowerLaw(mu=mu, a=a, exponent=exponent, mu_scale=mu_scale, amplitude_growth=amplitude_growth,
                             shear_amplitude=shear_amplitude)
    model = Model(name, GarzoDufty1999(), rdf, dissipation=CorrelationLength(c=c))
    return model.replace(friction=Friction(**FAMILY_FRICTION, mu=mu)) if mu > 0.0 else model


def predict(params: dict[str, float], states: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """T, p/(nT), τ/p of the family with ``params`` at every state (grouped by (μ, e))."""
    out = {k: np.empty(states["phi"].size) for k in OBSERVABLES}
    for mu, e in sorted(set(zip(states["mu"].tolist(), states["e"].tolist()))):
        idx = np.flatnonzero((states["mu"] == mu) & (states["e"] == e))
        s = steady_shear(family_model(mu=mu, **params), states["phi"][idx], e)
        for k in OBSERVABLES:
            out[k][idx] = np.broadcast_to(getattr(s, k), idx.shape)
    return out


def log_errors(params: dict[str, float], states: dict[str, np.ndarray]) -> np.ndarray:
    """ln(model/DEM) of T, p/(nT), τ/p, shape (3, n_states)."""
    pred = predict(params, states)
    return np.array([np.log(pred[k] / states[k]) for k in OBSERVABLES])


@dataclass(frozen=True)
class Fit:
    """A least-squares fit: values, standard errors, correlation, residuals (log-ratios, shape (3, n))."""

    names: tuple[str, ...]
    values: dict[str, float]
    stderr: dict[str, float]
    correlation: np.ndarray
    residuals: np.ndarray
    n_points: int
    success: bool

    @property
    def points_per_parameter(self) -> float:
        return self.n_points / len(self.names)


def _least_squares(residual: Callable[[np.ndarray], np.ndarray], names: tuple[str, ...], start: list[float],
                   lower: list[float], upper: list[float]) -> tuple[Any, np.ndarray, np.ndarray]:
    sol = least_squares(residual, start, bounds=(lower, upper), x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    J = sol.jac
    dof = max(sol.fun.size - len(names), 1)
    cov = np.linalg.pinv(J.T @ J) * (2.0 * sol.cost / dof)
    sd = np.sqrt(np.diag(cov))
    return sol, cov, sd


def _free(table: dict[str, tuple[float, float, float]], hold: dict[str, float]) -> tuple[tuple[str, ...], list, list, list]:
    names = tuple(k for k in table if k not in hold)
    start, lower, upper = (list(v) for v in zip(*(table[k] for k in names)))
    return names, start, lower, upper


def fit_frictionless(states: dict[str, np.ndarray] | None = None, *, hold: dict[str, float] | None = None) -> Fit:
    """Step 1: a, b (χ) and c (EKT) on frictionless uniform shear (default: the shipped e = 0.9 set).

    ``hold`` keeps some of them at given values (e.g. ``{"exponent": 1.5}``, Chialvo & Sundaresan's).
    """
    states = frictionless_states() if states is None else states
    hold = dict(hold or {})
    names, start, lower, upper = _free(FRICTIONLESS_PARAMETERS, hold)

    def params(x: np.ndarray) -> dict[str, float]:
        return {**hold, **dict(zip(names, x))}

    sol, cov, sd = _least_squares(lambda x: log_errors(params(x), states).ravel(), names, start, lower, upper)
    return _result(names, sol, cov, sd, states, params)


def cooling_states(path: Any = None) -> dict[str, np.ndarray]:
    """φ, e and p/(nT) of the homogeneous cooling states (default: the shipped ``dem_hcs_cooling.csv``)."""
    columns = read_cooling(path or shipped(HCS_COOLING))
    return {k: np.asarray(columns[k], dtype=float) for k in ("phi", "e", "p_over_nT")}


def cooling_log_errors(params: dict[str, float], cooling: dict[str, np.ndarray]) -> np.ndarray:
    """ln(model/DEM) of p/(nT) in the cooling states: the frictionless family's p* there, χ without shear."""
    model = family_model(a=params["a"], exponent=params["exponent"], c=params["c"])
    return np.log(np.asarray(model.reduced(cooling["phi"], cooling["e"], hcs=True).p) / cooling["p_over_nT"])


#: Where the static contact value near jamming is taken (:func:`static_contact_states`): the metastable branch
#: above freezing, up to the densest frictionless shear state (0.6), below both divergences (0.634 here, 0.64 in
#: Torquato's fit), where the two forms part.
STATIC_PHI: tuple[float, ...] = (0.55, 0.575, 0.6)


def static_contact_states(phi: tuple[float, ...] = STATIC_PHI) -> dict[str, np.ndarray]:
    """φ and the contact value χ of hard spheres without shear on the metastable branch near jamming.

    From Torquato, Phys. Rev. E 51, 3170 (1995), Eq. (13) (:class:`~ktgf.closures.rdf.Torquato`, φ_f 0.49,
    φ_c 0.64): his fit to the metastable (non-crystallising) hard-sphere fluid's pressure above freezing.  The
    shared files hold no static state there (the cooling states stop at φ 0.4), so without these points the
    unsheared part of the sheared χ is not fixed near jamming (``docs/dense_physics.md`` §8).
    """
    phis = np.asarray(phi, dtype=float)
    return {"phi": phis, "chi": np.asarray(Torquato().chi(phis), dtype=float)}


def static_log_errors(params: dict[str, float], static: dict[str, np.ndarray]) -> np.ndarray:
    """ln(model/static) of the contact value without shear at the states of :func:`static_contact_states`."""
    rdf = FrictionalPowerLaw(a=params["a"], exponent=params["exponent"])
    return np.log(np.asarray(rdf.chi(static["phi"])) / static["chi"])


def fit_sheared_structure(states: dict[str, np.ndarray] | None = None, cooling: dict[str, np.ndarray] | None = None, *,
                          static: dict[str, np.ndarray] | None = None, hold: dict[str, float] | None = None) -> Fit:
    """Step 1 with the sheared χ: a, b, c and A on the frictionless uniform shear, the cooling states' p/(nT) and
    the static contact value near jamming.

    The cooling states (no shear, φ ≤ 0.4) and the static states (:func:`static_contact_states`, φ 0.55–0.6; give
    an empty dict to leave them out) fix χ without shear; the shear states at e = 0.9 its sheared part
    (``docs/dense_physics.md`` §8).  ``Fit.residuals`` are those of the shear states; ``n_points`` counts all.
    """
    states = frictionless_states() if states is None else states
    cooling = cooling_states() if cooling is None else cooling
    static = static_contact_states() if static is None else static
    hold = dict(hold or {})
    names, start, lower, upper = _free(SHEARED_PARAMETERS, hold)

    def params(x: np.ndarray) -> dict[str, float]:
        return {**hold, **dict(zip(names, x))}

    def residual(x: np.ndarray) -> np.ndarray:
        parts = [log_errors(params(x), states).ravel(), cooling_log_errors(params(x), cooling)]
        if static:
            parts.append(static_log_errors(params(x), static))
        return np.concatenate(parts)

    sol, cov, sd = _least_squares(residual, names, start, lower, upper)
    return _result(names, sol, cov, sd, states, params)


def _lowest_mu_scale(states: dict[str, np.ndarray]) -> float:
    """The μ_Z below which φ_J(μ) would fall under a fitted state's φ (the data say those states flow)."""
    law = CoordinationJamming()
    worst = 0.0
    for mu in np.unique(states["mu"]):
        phi = float(states["phi"][states["mu"] == mu].max())
        z = 2.0 * math.sqrt(3.0) * phi / (1.0 - phi)  # Z at φ, law's inverse
        share = (law.z_frictionless - z) / (law.z_frictionless - law.z_infinite)  # s(μ) that puts φ_J at φ
        if share <= 0.0:
            return math.inf
        worst = max(worst, float(mu) * (1.0 - share) / share)
    return worst


def fit_frictional(frictionless: dict[str, float], states: dict[str, np.ndarray] | None = None, *,
                   hold: dict[str, float] | None = None) -> Fit:
    """Step 2: μ_Z and k (Eq. 2 of :class:`~ktgf.closures.jamming.FrictionalPowerLaw`) at μ > 0, step 1 held.

    ``hold`` keeps one of them at a given value (e.g. ``{"amplitude_growth": 0.0}``: φ_J(μ) alone).
    """
    states = frictional_states() if states is None else states
    hold = dict(hold or {})
    names, start, lower, upper = _free(FRICTIONAL_PARAMETERS, hold)
    if "mu_scale" in names:
        lower[0] = max(lower[0], _lowest_mu_scale(states) * (1.0 + 1e-6) + 1e-9)
        start[0] = min(max(start[0], lower[0] * 1.5), upper[0])
    base = {**{k: frictionless[k] for k in SHEARED_PARAMETERS if k in frictionless}, **hold}

    def params(x: np.ndarray) -> dict[str, float]:
        return {**base, **dict(zip(names, x))}

    sol, cov, sd = _least_squares(lambda x: log_errors(params(x), states).ravel(), names, start, lower, upper)
    return _result(names, sol, cov, sd, states, params)


def _result(names: tuple[str, ...], sol: Any, cov: np.ndarray, sd: np.ndarray, states: dict[str, np.ndarray],
            params: Callable[[np.ndarray], dict[str, float]]) -> Fit:
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    return Fit(names, {n: float(v) for n, v in zip(names, sol.x)}, {n: float(s) for n, s in zip(names, sd)}, corr,
               log_errors(params(sol.x), states), int(sol.fun.size), bool(sol.success))


def leave_one_out(fit: Callable[[dict[str, np.ndarray]], dict[str, float]],
                  states: dict[str, np.ndarray]) -> np.ndarray:
    """Relative errors (model/DEM − 1) of T, p/(nT), τ/p at each state, predicted by a fit without it.

    ``fit(states)`` returns the full parameter dict of the family.  Shape (3, n_states); a state the
    refit cannot predict (above its φ_J(μ)) is NaN.
    """
    n = states["phi"].size
    out = np.full((len(OBSERVABLES), n), np.nan)
    for i in range(n):
        params = fit(subset(states, np.arange(n) != i))
        try:
            out[:, i] = np.expm1(log_errors(params, subset(states, [i]))[:, 0])
        except InputError:  # refused: the left-out φ lies above the refit's φ_J(μ); stays NaN
            continue
    return out


def registered_parameters() -> dict[str, float]:
    """The registered family's parameters (from :mod:`ktgf.closures.dense` and ``closures/friction/calibrated``)."""
    from ..closures.dense import DENSE_PARAMETERS
    from ..closures.friction.calibrated import FRICTIONAL_PARAMETERS as FRICTIONAL

    return {**DENSE_PARAMETERS, **FRICTIONAL}
