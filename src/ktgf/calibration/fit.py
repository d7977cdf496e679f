"""The least-squares driver: fit chosen parameters of a model to data files (scipy ``least_squares``).

The cost is ½ Σ r_i² over every observation of every file (residuals of
:mod:`ktgf.calibration.residuals`), minimised by the trust-region reflective method within
the parameters' bounds with the exact Jacobians of that module.

Uncertainties (from the Jacobian J of the weighted residuals at the optimum): covariance
C = (JᵀJ)⁻¹, multiplied by the residual variance s² = Σr²/(m − n) (``errors="scaled"``, the
default when there are more observations m than parameters n) or not (``errors="stated"``:
the data's stated standard errors taken at face value; only meaningful with ``weights="sigma"``).
With model errors far above the DEM's statistical errors, as here, "scaled" is the honest one.

A fit that stops early (solver failure, non-finite residuals, evaluation limit) does not raise:
its result has ``success = False``, the reason in ``message`` and the best point evaluated.

Identifiability (:func:`identifiability`, in every result): observations per fitted parameter,
the correlation matrix, and warnings naming a pair correlated beyond :data:`CORRELATION_WARNING`
or the parameters of a direction the Jacobian does not see (rank deficiency). Fewer observations
than parameters is refused before any evaluation.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import numpy as np

from ..closures.models import Model
from ..errors import ConvergenceError, InputError
from ..data import CouetteData, UniformShearData
from .residuals import DEFAULT_SPECULARITY, WALL_PARAMETERS, make_terms, model_at

#: Bounds of the common options (φ_c, φ_f, β, a, RDF exponent); other float options default to (0, ∞)
#: when positive.  ``bounds=`` of :func:`calibrate` overrides any of them.
DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "phi_c": (0.5, 0.74), "phi_f": (0.2, 0.62), "beta": (0.05, 6.0), "a": (0.0, 20.0), "exponent": (0.01, 6.0),
    **WALL_PARAMETERS,
}
ERRORS = ("scaled", "stated")
#: |correlation| above which a pair of fitted parameters is reported as not separately determined.
CORRELATION_WARNING = 0.95
#: Singular values of the column-normalised Jacobian below this fraction of the largest count as zero.
RANK_TOLERANCE = 1e-10


def fittable_parameters(model: Model, *, couette: bool = False) -> dict[str, float]:
    """Every parameter that can be fitted: the model's float options, and the walls' for Couette data."""
    out = {k: float(v) for k, v in model.options().items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
    if couette:
        out.update({"specularity": math.nan, "wall_restitution": math.nan})
    return out


@dataclass(frozen=True)
class Parameter:
    """A fitted parameter: start value and bounds."""

    name: str
    start: float
    lower: float
    upper: float


@dataclass(frozen=True)
class Identifiability:
    """What the data determine: observations per parameter, numerical rank and warnings (one sentence each)."""

    observations: int
    parameters: int
    rank: int
    warnings: tuple[str, ...]

    @property
    def points_per_parameter(self) -> float:
        return self.observations / self.parameters if self.parameters else math.nan


def identifiability(J: np.ndarray, names: Sequence[str], correlation: np.ndarray | None = None) -> Identifiability:
    """Rank of the Jacobian ``J`` (columns scaled to unit length, so units do not matter) and the warnings.

    A parameter whose column is zero does not act on the data; the others of a null direction of the
    scaled Jacobian (components above 0.1 of the unit null vector) are named together; a pair with
    |correlation| > :data:`CORRELATION_WARNING` is named with its correlation.
    """
    J = np.asarray(J, dtype=float)
    m, n = J.shape
    warnings: list[str] = []
    if not np.all(np.isfinite(J)):
        return Identifiability(m, n, 0, ("the Jacobian at the optimum is not finite: identifiability unknown",))
    norms = np.linalg.norm(J, axis=0)
    dead = [names[j] for j in range(n) if norms[j] == 0.0]
    if dead:
        warnings.append(f"the data do not depend on {', '.join(dead)} at the optimum (zero column of the Jacobian)")
    live = [j for j in range(n) if norms[j] > 0.0]
    rank = 0
    if live:
        Js = J[:, live] / norms[live]
        _, s, Vt = np.linalg.svd(Js, full_matrices=True)
        s = np.concatenate([s, np.zeros(len(live) - s.size)])
        rank = int(np.sum(s > s[0] * RANK_TOLERANCE)) if s[0] > 0 else 0
        for v in Vt[rank:]:
            involved = [names[live[k]] for k in np.flatnonzero(np.abs(v) > 0.1)]
            warnings.append(f"the Jacobian is rank-deficient: the data determine only a combination of {', '.join(involved)} "
                            f"(rank {rank + len(dead)} short of {n}; fix all but one of them)" if len(involved) > 1 else
                            f"the Jacobian is rank-deficient in {involved[0]}")
    if correlation is not None and rank == len(live):
        for i in range(n):
            for j in range(i + 1, n):
                c = float(correlation[i, j])
                if math.isfinite(c) and abs(c) > CORRELATION_WARNING:
                    warnings.append(f"parameters {names[i]} and {names[j]} are {c:+.4f} correlated (|corr| > {CORRELATION_WARNING:g}): "
                                    "the data determine mainly one combination of them")
    return Identifiability(m, n, rank, tuple(warnings))


@dataclass
class FitResult:
    """Outcome of :func:`calibrate` (also when it failed: then the best point evaluated)."""

    base: str
    model: Model
    parameters: list[Parameter]
    values: np.ndarray
    stderr: np.ndarray
    correlation: np.ndarray
    errors: str
    cost: float
    residuals: np.ndarray
    labels: list[str]
    observed: np.ndarray
    predicted: np.ndarray
    weights: str
    success: bool
    message: str
    evaluations: int
    seconds: float
    files: list[str]
    walls: dict[str, float] = field(default_factory=dict)
    at_bound: list[str] = field(default_factory=list)
    #: Covariance of the fitted values (scaled as ``errors`` says): the prediction bands use it.
    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    identifiability: Identifiability | None = None

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parameters]

    def value_dict(self) -> dict[str, float]:
        return {n: float(v) for n, v in zip(self.names, self.values)}


def _parameters(model: Model, names: Sequence[str], datasets: Sequence[Any], start: dict[str, float],
                bounds: dict[str, tuple[float, float]], fixed_walls: dict[str, float]) -> list[Parameter]:
    couette = any(isinstance(d, CouetteData) for d in datasets)
    valid = fittable_parameters(model, couette=couette)
    if not names:
        raise InputError("--fit names no parameter; valid: " + ", ".join(valid))
    if len(set(names)) != len(names):
        raise InputError(f"--fit lists a parameter twice: {', '.join(names)}")
    for n in list(start) + list(bounds):
        if n not in valid:
            raise InputError(f"parameter {n!r} is not a parameter of model {model.name!r}" + ("" if couette else " with this data")
                             + f"; valid: {', '.join(valid)}")
    opts = model.options()
    max_phi = max([float(np.max(d.phi)) for d in datasets if isinstance(d, UniformShearData)]
                  + [d.case.mean_phi for d in datasets if isinstance(d, CouetteData)])
    couette_e = [d.case.e for d in datasets if isinstance(d, CouetteData)]
    wall_defaults = {"specularity": DEFAULT_SPECULARITY, "wall_restitution": couette_e[0] if couette_e else math.nan}
    params = []
    for n in names:
        if n not in valid:
            extra = "" if couette or n not in WALL_PARAMETERS else " (wall parameters need Couette data)"
            raise InputError(f"--fit: {n!r} is not a parameter of model {model.name!r}{extra}; valid: {', '.join(valid)}")
        default_start = fixed_walls.get(n, opts.get(n, wall_defaults.get(n)))
        x0 = float(start.get(n, default_start))
        default = DEFAULT_BOUNDS.get(n, (0.0, math.inf) if x0 > 0 else (-math.inf, math.inf))
        lo, hi = bounds.get(n, default)
        if n == "phi_c":  # the packing limit must stay above every solid fraction of the data
            lo = max(lo, max_phi + 1e-3)
            if "phi_f" in opts and "phi_f" not in names:
                lo = max(lo, float(opts["phi_f"]) + 1e-3)
        if n == "phi_f" and "phi_c" in opts and "phi_c" not in names:
            hi = min(hi, float(opts["phi_c"]) - 1e-3)
        if not lo < hi:
            raise InputError(f"parameter {n}: empty range {lo:g} < {n} < {hi:g}")
        if not lo <= x0 <= hi:
            raise InputError(f"parameter {n} = {x0:g} is out of range: valid {lo:g} <= {n} <= {hi:g}")
        params.append(Parameter(n, x0, lo, hi))
    return params


class _Stop(Exception):
    pass


def calibrate(model: Model, datasets: Sequence[Any], names: Sequence[str], *, start: dict[str, float] | None = None,
              bounds: dict[str, tuple[float, float]] | None = None, weights: str = "sigma", errors: str | None = None,
              walls: dict[str, float] | None = None, n_cells: int = 200, max_evaluations: int = 100,
              keep: np.ndarray | None = None) -> FitResult:
    """Fit parameters ``names`` of ``model`` to ``datasets`` (from :func:`ktgf.data.read_data`).

    Parameters
    ----------
    model : Model
        Any registered (or file-loaded) model; its other options stay as they are.
    datasets : sequence
        :class:`~.data.UniformShearData` and/or :class:`~.data.CouetteData`.
    names : sequence of str
        Parameters to fit: float options of the model (``phi_c``, ``beta``, …) and, with Couette
        data, ``specularity`` and ``wall_restitution``.
    start, bounds : dict, optional
        Start values (default: the model's current values; walls: ``walls`` or φ' = 0.1, e_w = e)
        and (low, high) bounds (default :data:`DEFAULT_BOUNDS`).
    weights : {"sigma", "relative"}
        Residuals divided by the stated standard errors, or relative to the data.
    errors : {"scaled", "stated"}, optional
        How the standard errors are scaled (module notes); default "scaled" if m > n.
    walls : dict, optional
        Fixed wall parameters (``specularity``, ``wall_restitution``) of the Couette cells.
    keep : bool array, optional
        Which observations (in the order of all files' labels) enter the cost; the others are left
        out and a file with none kept is not evaluated (leave-one-out refits,
        :mod:`ktgf.calibration.crossval`: the files stay the same, so compiled Jacobians are reused).
    """
    t0 = time.perf_counter()
    start, bounds, walls = dict(start or {}), dict(bounds or {}), dict(walls or {})
    if not datasets:
        raise InputError("no data file given (--data)")
    for k, v in walls.items():
        if k not in WALL_PARAMETERS:
            raise InputError(f"wall parameter {k!r} is unknown; valid: {', '.join(WALL_PARAMETERS)}")
        lo, hi = WALL_PARAMETERS[k]
        if not lo <= v <= hi:
            raise InputError(f"wall parameter {k} = {v:g} is out of range: valid {lo:g} <= {k} <= {hi:g}")
    params = _parameters(model, list(names), datasets, start, bounds, walls)
    names = [p.name for p in params]
    fixed = {k: v for k, v in walls.items() if k not in names}
    terms = make_terms(model, datasets, names, weights, n_cells=n_cells, fixed=fixed)
    if keep is not None:
        keep = np.asarray(keep, dtype=bool)
        sizes = [len(t.labels) for t in terms]
        if keep.shape != (sum(sizes),):
            raise InputError(f"keep has {keep.size} entries for {sum(sizes)} observations")
        parts = np.split(keep, np.cumsum(sizes)[:-1])
        terms = [_Kept(t, k) if not k.all() else t for t, k in zip(terms, parts) if k.any()]
    labels = [lab for t in terms for lab in t.labels]
    m, n = len(labels), len(params)
    if m < n:
        raise InputError(f"a fit of {n} parameters ({', '.join(names)}) to {m} data point(s): needs at least {n} data points")
    if errors is None:
        errors = "scaled" if m > n else "stated"
    if errors not in ERRORS:
        raise InputError(f"errors {errors!r} is not valid; choose one of {', '.join(ERRORS)}")
    if errors == "scaled" and m <= n:
        raise InputError(f"errors 'scaled' needs more observations ({m}) than parameters ({n}); use 'stated'")

    best: dict[str, Any] = {"cost": math.inf, "x": np.array([p.start for p in params]), "r": None}
    count = [0]

    def as_values(x: np.ndarray) -> dict[str, float]:
        return {p.name: float(v) for p, v in zip(params, x)}

    def fun(x: np.ndarray) -> np.ndarray:
        count[0] += 1
        try:
            with np.errstate(all="ignore"):
                r = np.concatenate([t.residuals(as_values(x)) for t in terms])
        except (ConvergenceError, InputError) as exc:
            raise _Stop(str(exc)) from None
        if not np.all(np.isfinite(r)):
            raise _Stop("non-finite residuals at " + ", ".join(f"{k}={v:.6g}" for k, v in as_values(x).items()))
        cost = 0.5 * float(r @ r)
        if cost < best["cost"]:
            best.update(cost=cost, x=np.array(x, dtype=float), r=r)
        return r

    def jac(x: np.ndarray) -> np.ndarray:
        try:
            return np.concatenate([t.jacobian(as_values(x)) for t in terms])
        except (ConvergenceError, InputError) as exc:
            raise _Stop(str(exc)) from None

    from scipy.optimize import least_squares

    success, message, active = False, "", np.zeros(n, dtype=int)
    try:
        res = least_squares(fun, best["x"], jac=jac, bounds=([p.lower for p in params], [p.upper for p in params]),
                            method="trf", x_scale="jac", max_nfev=max_evaluations)
        success = bool(res.status > 0)
        message = res.message if success else f"stopped: {res.message}"
        x, active = res.x, res.active_mask
        r, J = res.fun, res.jac
    except _Stop as exc:
        message = f"fit failed: {exc}; keeping the best point evaluated"
        x = best["x"]
        r = best["r"]
        J = None
        if r is None:
            raise ConvergenceError(f"fit failed at the start point: {exc}") from None
    if J is None:
        try:
            J = jac(x)
        except _Stop:
            J = np.full((m, n), np.nan)
    cov = _covariance(J)
    with np.errstate(all="ignore"):
        sd = np.sqrt(np.diag(cov))
        corr = cov / np.outer(sd, sd)  # scale-free: the same for stated and scaled errors
    if errors == "scaled":
        cov = cov * float(r @ r) / (m - n)
    se = np.sqrt(np.diag(cov))
    ident = identifiability(J, names, corr)
    wide = [f"{p.name} (standard error {s_:.3g}, range {p.lower:g} to {p.upper:g})" for p, s_ in zip(params, se)
            if math.isfinite(p.upper - p.lower) and math.isfinite(s_) and s_ > p.upper - p.lower]
    if wide:  # a direction shared by three or more parameters escapes the pairwise test; its errors show it
        ident = replace(ident, warnings=ident.warnings + ("the data do not determine " + "; ".join(wide)
                                                          + ": the standard error exceeds the whole range",))
    if not np.all(np.isfinite(se)):
        message += "; the data do not determine every fitted parameter (J^T J is singular: infinite standard errors)"
    notes = sorted({t.method_note for t in terms if getattr(t, "method_note", "")})
    if notes:
        message += "; " + "; ".join(notes)
    values = as_values(x)
    obs = np.concatenate([t.obs for t in terms])
    try:
        pred = np.concatenate([t.predict(values) for t in terms])
    except ConvergenceError:  # the best point was solved once; a failure here leaves the predictions unknown
        pred = obs * np.nan
    fitted_model = model_at(model, values)
    used_walls = {}
    for t in terms:
        if isinstance(t.data, CouetteData):
            used_walls = {k: float({**t.fixed, **values}[k]) for k in WALL_PARAMETERS}
    return FitResult(
        base=model.name, model=fitted_model, parameters=params, values=np.asarray(x, dtype=float), stderr=se,
        correlation=corr, errors=errors, cost=0.5 * float(r @ r), residuals=np.asarray(r), labels=labels, observed=obs,
        predicted=pred, weights=weights, success=success, message=message, evaluations=count[0],
        seconds=time.perf_counter() - t0, files=[str(d.path) for d in datasets], walls=used_walls,
        at_bound=[p.name for p, a in zip(params, active) if a != 0], covariance=cov, identifiability=ident,
    )


class _Kept:
    """A residual term restricted to some of its observations (same interface)."""

    def __init__(self, term: Any, keep: np.ndarray) -> None:
        self.term, self.keep = term, keep
        self.data = term.data
        self.obs = term.obs[keep]
        self.labels = [lab for lab, k in zip(term.labels, keep) if k]
        self.method_note = getattr(term, "method_note", "")
        self.fixed = getattr(term, "fixed", {})

    def predict(self, values: dict[str, float]) -> np.ndarray:
        return self.term.predict(values)[self.keep]

    def residuals(self, values: dict[str, float]) -> np.ndarray:
        return self.term.residuals(values)[self.keep]

    def jacobian(self, values: dict[str, float]) -> np.ndarray:
        J = self.term.jacobian(values)[self.keep]
        self.method_note = getattr(self.term, "method_note", "")
        return J


def _covariance(J: np.ndarray) -> np.ndarray:
    """(JᵀJ)⁻¹ via the SVD (pseudo-inverse: an unidentifiable direction gets infinite variance)."""
    if not np.all(np.isfinite(J)):
        return np.full((J.shape[1],) * 2, np.nan)
    _, s, Vt = np.linalg.svd(J, full_matrices=False)
    tiny = s <= s[0] * 1e-12 if s.size else s
    inv = np.where(tiny, np.inf, 1.0 / np.where(tiny, 1.0, s) ** 2)
    with np.errstate(invalid="ignore"):
        return (Vt.T * inv) @ Vt
