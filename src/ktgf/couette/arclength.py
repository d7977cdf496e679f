"""Pseudo-arclength continuation (Keller 1977) of the discrete Couette balances in one parameter.

A family of problems R(X; λ) = 0 (λ a homotopy parameter, e.g. the mean solid fraction of a
stage of :func:`ktgf.couette.solver.homotopy_paths`) is followed along its solution curve
(X(s), λ(s)), parametrised by the arclength s in the norm

    ‖(δX, δλ)‖² = mean(δX²) + δλ²        (RMS over the unknowns u/V, ln θ, logit φ),

instead of by λ itself.  Natural-parameter continuation (fix λ, solve for X) cannot pass a
turning point (fold) of the curve, where dλ/ds changes sign and ∂R/∂X is singular; here each
step solves the bordered system

    [ ∂R/∂X      ∂R/∂λ ] [δX]      [ R                                  ]
    [ t_X/N      t_λ   ] [δλ] = −  [ t_X·(X − X_k)/N + t_λ(λ − λ_k) − Δs ]

(t the unit tangent at the last point (X_k, λ_k), N the number of unknowns), which stays
regular at a simple fold.  ∂R/∂X is the solver's sparse Jacobian; ∂R/∂λ a central difference
in λ.  The bordered matrix is factorised as a whole (SuperLU), not by block elimination,
which would fail exactly where it is needed (singular ∂R/∂X at the fold).

Step control: a step is accepted when the chord corrector (the bordered matrix factorised once,
at the predictor) converges within ``MAX_CORRECTOR`` iterations, each correction at most half the
previous one (or stagnating below ``ROUND_OFF_STEP``: round-off in near-jammed cores); Δs grows
×1.5 after fast corrections and is halved after a failed one; the predictor is limited so that
no ln θ or logit φ moves by more than ``MAX_PREDICTOR``.  Folds are detected where λ along the
accepted points reverses, and reported.  When the curve crosses the end value
λ₁, the point on the curve at λ = λ₁ is found with λ fixed (the last row becomes δλ = λ₁ − λ).

Failures raise :class:`ArclengthStall` with a diagnosis (step collapse, the curve turning back
past the start, too many steps) and the path followed so far.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .equations import N_VARS

#: Largest corrector iteration count for an accepted step.
MAX_CORRECTOR = 12
#: Largest change of any ln θ or logit φ along one predictor step.
MAX_PREDICTOR = 1.0
#: A corrector that stops contracting below this step length has reached round-off: accepted.
ROUND_OFF_STEP = 1e-7
#: Relative central-difference step in λ for ∂R/∂λ.
LAMBDA_STEP = 1e-6


@dataclass
class ArclengthPath:
    """Points accepted along the curve: λ, the unknowns, t_λ = dλ/ds, and the folds passed."""

    lam: list[float] = field(default_factory=list)
    X: list[np.ndarray] = field(default_factory=list)
    dlam_ds: list[float] = field(default_factory=list)
    folds: list[float] = field(default_factory=list)
    corrector_iterations: int = 0
    rejected_steps: int = 0

    def append(self, lam: float, X: np.ndarray, t_lam: float) -> None:
        # a fold is where λ along the accepted points stops rising and starts falling (or back);
        # before the second point the direction is the start tangent's
        if self.lam:
            before = self.lam[-1] - self.lam[-2] if len(self.lam) >= 2 else self.dlam_ds[0]
            if (lam - self.lam[-1]) * before < 0:
                self.folds.append(self.lam[-1])
        self.lam.append(float(lam))
        self.X.append(X.copy())
        self.dlam_ds.append(float(t_lam))


class ArclengthStall(RuntimeError):
    """The continuation could not reach the end value; ``path``, ``X`` and ``lam`` hold where it got."""

    def __init__(self, message: str, path: ArclengthPath, X: np.ndarray, lam: float) -> None:
        super().__init__(message)
        self.path, self.X, self.lam = path, X, lam


def _rms(v: np.ndarray) -> float:
    return float(np.sqrt(np.mean(v**2)))


def _log_change(dX: np.ndarray) -> float:
    return float(np.abs(dX.reshape(-1, N_VARS)[:, 1:]).max())


class _Family:
    """R(X; λ), ∂R/∂X and ∂R/∂λ of a one-parameter family of problems."""

    def __init__(self, problem_at: Callable[[float], Any]) -> None:
        self.problem_at = problem_at

    def residual(self, X: np.ndarray, lam: float) -> np.ndarray:
        return self.problem_at(lam).residual(X)

    def linearise(self, X: np.ndarray, lam: float) -> tuple[np.ndarray, Any, np.ndarray, float]:
        """R, ∂R/∂X (sparse), ∂R/∂λ and the relative residual at (X, λ)."""
        pr = self.problem_at(lam)
        t = pr.terms(X)
        R = pr.residual(X, t)
        rel = float(np.max(np.abs(R) / pr.residual_scales(t)))
        J = pr.jacobian(X, R)
        h = LAMBDA_STEP * (1.0 + abs(lam))
        R_lam = (self.residual(X, lam + h) - self.residual(X, lam - h)) / (2.0 * h)
        return R, J, R_lam, rel


def _bordered(J: Any, R_lam: np.ndarray, row_X: np.ndarray, row_lam: float) -> Any:
    """The (N+1)×(N+1) matrix [[J, ∂R/∂λ], [row_X, row_lam]] as CSC, ready for SuperLU."""
    col = sp.csc_matrix(R_lam.reshape(-1, 1))
    row = sp.csr_matrix(np.append(row_X, row_lam).reshape(1, -1))
    return sp.vstack([sp.hstack([J, col]), row]).tocsc()


def _correct(family: _Family, X: np.ndarray, lam: float, row_X: np.ndarray, row_lam: float,
             constraint: Callable[[np.ndarray, float], float], tol: float):
    """Chord-Newton on R = 0 and one scalar constraint; returns (X, λ, iterations, (J, ∂R/∂λ)) or None.

    The bordered matrix is factorised once, at the predictor; the iteration must contract
    (each correction at most half the previous one), else the predictor was too far and
    the step is rejected.
    """
    n = X.size
    with np.errstate(all="ignore"):
        R, J, R_lam, rel = family.linearise(X, lam)
    if not (np.all(np.isfinite(R)) and np.all(np.isfinite(R_lam))):
        return None
    try:
        lu = spla.splu(_bordered(J, R_lam, row_X, row_lam))
    except RuntimeError:  # exactly singular: not a simple fold
        return None
    prev = math.inf
    for it in range(1, MAX_CORRECTOR + 1):
        if it > 1:
            with np.errstate(all="ignore"):
                pr = family.problem_at(lam)
                t = pr.terms(X)
                R = pr.residual(X, t)
                rel = float(np.max(np.abs(R) / pr.residual_scales(t)))
            if not np.all(np.isfinite(R)):
                return None
        d = -lu.solve(np.append(R, constraint(X, lam)))
        dX, dlam = d[:n], float(d[n])
        step = math.hypot(_rms(dX), dlam)
        if not np.isfinite(step) or _log_change(dX) > 1.0:
            return None
        if step < tol and rel < 1e-6:
            return X + dX, lam + dlam, it, (J, R_lam)
        if step > 0.5 * prev:
            if prev < ROUND_OFF_STEP and rel < 1e-6:
                # stagnating at round-off (near-jammed cores: condition numbers ~1e13), not diverging
                return X, lam, it, (J, R_lam)
            return None  # not contracting: the predictor was too far
        X, lam, prev = X + dX, lam + dlam, step
    return None


def follow(problem_at: Callable[[float], Any], X0: np.ndarray, lam0: float = 0.0, lam1: float = 1.0, *,
           ds0: float = 0.05, ds_max: float = 0.5, ds_min: float = 1e-6, max_steps: int = 500,
           tol: float = 1e-9, lam_min: float | None = None) -> tuple[np.ndarray, ArclengthPath]:
    """Follow the solution curve of ``problem_at(λ)`` from a solution X0 at λ0 to λ = λ1 (> λ0).

    Parameters
    ----------
    problem_at : callable
        λ ↦ :class:`~ktgf.couette.equations.Problem`.
    X0 : ndarray
        A solution at λ0 (the corrector converges from it).
    ds0, ds_max, ds_min : float
        First, largest and smallest arclength step.
    max_steps : int
        Bound on accepted plus rejected steps.
    tol : float
        Corrector tolerance on the step length (RMS norm above).
    lam_min : float, optional
        The curve may turn back below λ0 (between two folds) down to this value (default λ0).

    Returns
    -------
    X : ndarray
        The solution at λ1 on the curve through X0 (polish it with the solver's Newton).
    path : ArclengthPath
        Every accepted point, the folds passed and the corrector work.

    Raises
    ------
    ArclengthStall
        With a diagnosis, if the step collapses below ``ds_min``, the curve returns past λ0 or
        ``max_steps`` is exhausted.
    """
    family = _Family(problem_at)
    lam_min = lam0 if lam_min is None else lam_min
    n = X0.size
    path = ArclengthPath()
    fixed_lam0 = lambda Y, l: l - lam0  # noqa: E731 - constraint λ = λ0
    first = _correct(family, X0.copy(), lam0, np.zeros(n), 1.0, fixed_lam0, tol)
    if first is None:
        raise ArclengthStall(f"arclength continuation: the start point is not a solution at lambda = {lam0:g}",
                             path, X0, lam0)
    X, lam, _, (J, R_lam) = first
    # tangent at the start: J z = −∂R/∂λ, oriented towards increasing λ
    z = spla.splu(_bordered(J, R_lam, np.zeros(n), 1.0)).solve(np.append(np.zeros(n), 1.0))
    t = z / math.hypot(_rms(z[:n]), z[n])
    path.append(lam, X, t[n])
    ds = ds0
    steps = 0
    while True:
        steps += 1
        if steps > max_steps:
            raise ArclengthStall(
                f"arclength continuation: {max_steps} steps used, stopped at lambda = {lam:.6g} "
                f"(folds passed at lambda = {[round(f, 5) for f in path.folds]})", path, X, lam)
        tX, tl = t[:n], float(t[n])
        ds = min(ds, MAX_PREDICTOR / max(_log_change(tX), 1e-300))
        Xp, lp = X + ds * tX, lam + ds * tl
        row_X = tX / n

        def on_plane(Y, lv, Xk=X, lk=lam, dsk=ds):
            return float(row_X @ (Y - Xk) + tl * (lv - lk) - dsk)

        out = _correct(family, Xp, lp, row_X, tl, on_plane, tol)
        if out is None:
            path.rejected_steps += 1
            ds *= 0.5
            if ds < ds_min:
                near = (f"dlambda/ds = {tl:.3g} at the last point: a turning point is close" if abs(tl) < 0.05
                        else f"dlambda/ds = {tl:.3g}: not near a turning point (a bifurcation or an "
                             f"ill-conditioned Jacobian, e.g. a near-jammed core)")
                raise ArclengthStall(
                    f"arclength continuation stalled at lambda = {lam:.6g}: step length fell below {ds_min:g} "
                    f"after {len(path.lam)} points; {near}; folds passed at lambda = "
                    f"{[round(f, 5) for f in path.folds]}", path, X, lam)
            continue
        Xn, ln, its, (J, R_lam) = out
        path.corrector_iterations += its
        # new tangent: [J ∂R/∂λ; t_old] z = [0; 1] keeps the orientation of the old one
        z = spla.splu(_bordered(J, R_lam, row_X, tl)).solve(np.append(np.zeros(n), 1.0))
        z /= math.hypot(_rms(z[:n]), z[n])
        if (z[:n] @ (Xn - X)) / n + z[n] * (ln - lam) < 0:
            z = -z  # J is from the predictor: keep the tangent pointing along the secant just travelled
        t = z
        if ln >= lam1:  # crossed the end value: the curve's point at λ1, λ held fixed
            Xs = X + (lam1 - lam) / (ln - lam) * (Xn - X)
            land = _correct(family, Xs, lam1, np.zeros(n), 1.0, lambda Y, l: l - lam1, tol)
            if land is None:
                path.rejected_steps += 1
                ds *= 0.5
                if ds < ds_min:
                    raise ArclengthStall(f"arclength continuation: could not land on lambda = {lam1:g}", path, X, lam)
                continue
            path.corrector_iterations += land[2]
            path.append(lam1, land[0], t[n])
            return land[0], path
        X, lam = Xn, ln
        path.append(lam, X, t[n])
        if lam < lam_min:
            raise ArclengthStall(
                f"arclength continuation: the solution curve turned back at lambda = "
                f"{[round(f, 5) for f in path.folds]} and returned below lambda = {lam_min:g}: no solution "
                f"at lambda = {lam1:g} on the curve through the start", path, X, lam)
        ds = min(ds_max, 1.5 * ds) if its <= 4 else (0.7 * ds if its >= 8 else ds)
