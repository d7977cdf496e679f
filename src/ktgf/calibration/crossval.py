"""Leave-one-state-out cross-validation of a calibration: the error a user should quote.

A *state* is one row (φ, e) of a uniform-shear file or one Couette file.  For each state the fit
is repeated without that state's observations, starting from the full fit's optimum, and the
refitted model predicts the state left out.  Its relative error model/data − 1 per quantity is a
prediction error: no parameter saw that state.  The mean of their absolute values over every state
and quantity (:attr:`CrossValidation.mean_abs_error`) is the number to quote; the full fit's own
(in-sample) errors are kept beside it for comparison.

The refits drop observations (``keep`` of :func:`~ktgf.calibration.fit.calibrate`) rather than
rows of the files, so the compiled JAX Jacobian of each uniform-shear file is reused by every refit.
A parameter that only the left-out state determines (a wall parameter when its Couette file is left
out) keeps the full fit's value in that refit; the refit's identifiability warning is kept in
:attr:`CrossValidation.notes`, since that state's error is then not a clean prediction.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from ..data import CouetteData
from ..errors import InputError
from .fit import FitResult, calibrate
from .residuals import COUETTE_OBSERVABLES, make_terms


@dataclass(frozen=True)
class State:
    """One state of the data: its label, file, the indices of its observations and their quantities."""

    label: str
    file: str
    index: tuple[int, ...]
    quantities: tuple[str, ...]


def states_of(datasets: Sequence[Any]) -> list[State]:
    """Every state of ``datasets``, with the positions of its observations in the fit's residual vector."""
    out, offset = [], 0
    for d in datasets:
        name = d.path.name
        if isinstance(d, CouetteData):
            k = len(COUETTE_OBSERVABLES)
            out.append(State(f"{name} (mean phi={d.case.mean_phi:g} e={d.case.e:g})", name, tuple(range(offset, offset + k)),
                             COUETTE_OBSERVABLES))
            offset += k
            continue
        n, quantities = len(d.phi), tuple(d.values)
        for i in range(n):
            out.append(State(f"{name} phi={d.phi[i]:g} e={d.e[i]:g}", name,
                             tuple(offset + q * n + i for q in range(len(quantities))), quantities))
        offset += n * len(quantities)
    return out


@dataclass
class CrossValidation:
    """Result of :func:`cross_validate`.

    ``rows``: one per (left-out state, quantity) — state, file, quantity, data, its standard error,
    the left-out prediction and its relative error ``error``, the full fit's prediction and its
    error ``in_sample_error``, and the refit's parameter values.
    """

    full: FitResult
    rows: list[dict[str, Any]]
    refits: list[dict[str, Any]]
    seconds: float
    notes: list[str] = field(default_factory=list)

    @property
    def mean_abs_error(self) -> float:
        """Mean |model/data − 1| of the left-out predictions over every state and quantity."""
        e = np.array([abs(r["error"]) for r in self.rows], dtype=float)
        return float(np.nanmean(e)) if e.size else math.nan

    @property
    def mean_abs_in_sample_error(self) -> float:
        e = np.array([abs(r["in_sample_error"]) for r in self.rows], dtype=float)
        return float(np.nanmean(e)) if e.size else math.nan

    def per_quantity(self) -> list[dict[str, Any]]:
        """Mean and max |error| per quantity, left out and in sample."""
        out = []
        for q in dict.fromkeys(r["quantity"] for r in self.rows):
            e = np.array([abs(r["error"]) for r in self.rows if r["quantity"] == q])
            i = np.array([abs(r["in_sample_error"]) for r in self.rows if r["quantity"] == q])
            out.append({"quantity": q, "states": int(e.size), "mean_abs_error": float(np.nanmean(e)),
                        "max_abs_error": float(np.nanmax(e)), "mean_abs_in_sample_error": float(np.nanmean(i))})
        return out

    def summary(self) -> dict[str, Any]:
        return {"model": self.full.base, "parameters": self.full.names, "full_fit": self.full.value_dict(),
                "states": len(self.refits), "mean_abs_error": self.mean_abs_error,
                "mean_abs_in_sample_error": self.mean_abs_in_sample_error, "seconds": self.seconds,
                "failed_refits": [r["state"] for r in self.refits if not r["success"]], "notes": self.notes}


def cross_validate(model: Any, datasets: Sequence[Any], names: Sequence[str], *, full: FitResult | None = None,
                   progress: Any = None, **fit_options: Any) -> CrossValidation:
    """Leave-one-state-out refits of ``names`` of ``model`` on ``datasets`` (options as :func:`calibrate`).

    ``full`` is the fit on every state (done here if not given); each refit starts from its optimum.
    ``progress(i, n)`` is called after each refit.
    """
    t0 = time.perf_counter()
    if full is None:
        full = calibrate(model, datasets, names, **fit_options)
    names = full.names
    states = states_of(datasets)
    if len(states) < 2:
        raise InputError(f"cross-validation needs at least 2 states (rows of uniform-shear files, Couette files); the data hold {len(states)}")
    m = sum(len(s.index) for s in states)
    walls = {**fit_options.pop("walls", {}), **full.walls}
    fixed = {k: v for k, v in walls.items() if k not in names}
    opts = {k: v for k, v in fit_options.items() if k not in ("start", "errors")}
    # predictions of the left-out states come from terms of all files, built once
    terms = make_terms(model, datasets, names, fit_options.get("weights", "sigma"), n_cells=fit_options.get("n_cells", 200),
                       fixed=fixed)
    where = []  # (term, position inside the term) of every observation
    for t in terms:
        where += [(t, j) for j in range(len(t.labels))]
    obs = np.concatenate([t.obs for t in terms])
    sigma = np.concatenate([t.sigma for t in terms])
    rows, refits = [], []
    notes = [] if full.success else [f"the full fit did not converge: {full.message}"]
    for k, s in enumerate(states):
        keep = np.ones(m, dtype=bool)
        keep[list(s.index)] = False
        if keep.sum() < len(names):
            raise InputError(f"cross-validation: leaving out {s.label} leaves {int(keep.sum())} data point(s) "
                             f"for {len(names)} parameter(s)")
        fit = calibrate(model, datasets, names, start=full.value_dict(), errors="stated", keep=keep,
                        walls={k2: v for k2, v in walls.items() if k2 not in names}, **opts)
        values = fit.value_dict()
        # a parameter only the left-out state determined keeps the full fit's value: that error is not a clean prediction
        # (only the structural warnings: correlations and standard errors of each refit differ a little from the full fit's)
        notes += [f"refit without {s.label}: {w}" for w in fit.identifiability.warnings
                  if ("do not depend" in w or "rank-deficient" in w) and w not in full.identifiability.warnings]
        refits.append({"state": s.label, **values, "success": fit.success, "evaluations": fit.evaluations,
                       "message": "" if fit.success else fit.message})
        term = where[s.index[0]][0]
        pred = term.predict(values)
        for q, i in zip(s.quantities, s.index):
            p = float(pred[where[i][1]])
            rows.append({"state": s.label, "file": s.file, "quantity": q, "data": float(obs[i]), "sigma": float(sigma[i]),
                         "model": p, "error": p / obs[i] - 1.0, "model_in_sample": float(full.predicted[i]),
                         "in_sample_error": float(full.predicted[i] / obs[i] - 1.0), "refit_converged": fit.success,
                         **{f"refit_{n}": v for n, v in values.items()}})
        if progress is not None:
            progress(k + 1, len(states))
    return CrossValidation(full, rows, refits, time.perf_counter() - t0, notes)


__all__ = ["CrossValidation", "State", "cross_validate", "states_of"]
