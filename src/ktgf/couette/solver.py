"""Steady Couette solver: damped Newton on the discrete balances, with continuation as a fallback.

Newton's method uses a sparse Jacobian (coloured finite differences, :meth:`Problem.jacobian`)
factorised once per iteration (SuperLU); the step length follows Deuflhard's natural
monotonicity test (the simplified Newton correction at the trial point must shrink), which is
invariant to the scaling of the equations, and steps in ln θ and logit φ are limited so that
a single step cannot change θ or φ/(φ_max − φ) by more than a factor e^3.  Positivity of θ and
φ < φ_max hold by construction of the unknowns.

When Newton fails from the naive start (uniform φ̄, linear velocity, θ of uniform shear), the
solver first continues a frictional wall (δ_w > 0) in tan δ_w from the solution with δ_w = 0
(itself solved by every path below; :func:`_wall_friction_continuation`; by arclength past a fold), then tries
pseudo-transient continuation, then follows homotopies from an easy problem
(mean φ ≤ 0.3, e ≥ 0.9, specularity ≥ 0.1, no centripetal term in the annular cell) to the
target with adaptive steps: one parameter group per stage, then all at once
(:func:`homotopy_paths`).  Natural-parameter steps cannot pass a turning point (fold) of the
solution curve; if every path stalls (a stage's step below 1e-3), each path is resumed where it
stalled and the rest of that stage is followed by pseudo-arclength continuation
(:mod:`ktgf.couette.arclength`), which can (``continuation="arclength"`` uses it for every stage).
If that fails too, the last fallback is mesh sequencing (:func:`_mesh_sequenced`): the same paths on every other
node (repeatedly, to at most 64 nodes), then Newton on each finer grid from the coarser solution.
The fallback is the default because it leaves every case that natural steps solve on its old
path, solution and time (docs/dense.md §5.2).  Near-jammed plug states (φ within ~1e-4 of φ_c, θ ~ 1e-8 U²) have
Jacobian condition numbers of 1e12–1e13 and are where the solver can stop.  If it fails it raises :class:`~ktgf.errors.ConvergenceError`
carrying the residual history and the last iterate.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse.linalg as spla

from ..errors import ConvergenceError, InputError
from . import arclength
from .equations import N_VARS, Problem
from ..shear.steady import steady_temperature

#: Largest change of ln θ or of logit φ in one Newton step.
MAX_LOG_STEP = 3.0


@dataclass
class NewtonReport:
    """Outcome of one Newton solve: iterations, history of (|R|_rel, |Δx|, λ) and success flag."""

    converged: bool
    iterations: int
    history: list[tuple[float, float, float]] = field(default_factory=list)
    residual: float = math.inf
    message: str = ""


class CouetteConvergenceError(ConvergenceError):
    """The steady solver did not converge.

    Attributes
    ----------
    history : list of (relative residual, step norm, damping factor) per Newton iteration.
    last_iterate : ndarray, the last state reached (solver unknowns).
    problem : the discrete problem (to turn the iterate into fields).
    """

    def __init__(self, message: str, history: list, last_iterate: np.ndarray, problem: Problem) -> None:
        super().__init__(message)
        self.history = history
        self.last_iterate = last_iterate
        self.problem = problem


def relative_residual(problem: Problem, X: np.ndarray) -> float:
    """max_i |R_i| / (magnitude of the terms of equation i)."""
    t = problem.terms(X)
    R = problem.residual(X, t)
    return float(np.max(np.abs(R) / problem.residual_scales(t)))


def newton(
    problem: Problem, X0: np.ndarray, *, tol: float = 1e-10, max_iter: int = 60, lambda_min: float = 1e-4,
    residual_tol: float = 1e-8,
) -> tuple[np.ndarray, NewtonReport]:
    """Damped Newton iteration; returns the last iterate and a report (never raises on non-convergence).

    Converged when a full step is shorter than ``tol`` (RMS over the unknowns u/V, ln θ, logit φ),
    or, if the line search stalls, when the relative residual is already below ``residual_tol``.
    """
    X = X0.copy()
    rep = NewtonReport(False, 0)
    lam = 1.0
    with np.errstate(all="ignore"):
        for it in range(max_iter):
            t = problem.terms(X)
            R = problem.residual(X, t)
            rel = float(np.max(np.abs(R) / problem.residual_scales(t)))
            if not np.all(np.isfinite(R)):
                rep.message = "residual is not finite"
                return X, rep
            J = problem.jacobian(X, R)
            try:
                lu = spla.splu(J)
            except RuntimeError as exc:  # singular Jacobian
                rep.message = f"singular Jacobian ({exc})"
                return X, rep
            dX = -lu.solve(R)
            norm = float(np.sqrt(np.mean(dX**2)))
            if not np.isfinite(norm):
                rep.message = "Newton step is not finite"
                return X, rep
            logs = np.abs(dX.reshape(-1, N_VARS)[:, 1:]).max()
            lam = min(1.0, 4.0 * lam, MAX_LOG_STEP / max(logs, 1e-300))
            scales = problem.residual_scales(t)
            res_norm = float(np.sqrt(np.mean((R / scales) ** 2)))
            while True:
                Xt = X + lam * dX
                Rt = problem.residual(Xt)
                if np.all(np.isfinite(Rt)):
                    dXbar = -lu.solve(Rt)
                    nbar = float(np.sqrt(np.mean(dXbar**2)))
                    if nbar <= (1.0 - 0.25 * lam) * norm or norm < tol:
                        break
                    # second acceptance rule (helps at kinks of piecewise closures, e.g. Torquato's χ at φ_f):
                    # sufficient decrease of the scaled residual
                    if float(np.sqrt(np.mean((Rt / scales) ** 2))) <= (1.0 - 0.25 * lam) * res_norm:
                        break
                lam *= 0.5
                if lam < lambda_min:
                    rep.history.append((rel, norm, lam))
                    rep.iterations = it + 1
                    rep.residual = rel
                    if rel < residual_tol:
                        # every balance already holds to residual_tol of its largest term; the step
                        # cannot shrink further because of round-off in an ill-conditioned system
                        rep.converged = True
                        rep.message = f"stopped at round-off level (relative residual {rel:.2g})"
                    else:
                        rep.message = f"damping factor fell below {lambda_min:g} (no descent direction)"
                    return X, rep
            X = Xt
            rep.history.append((rel, norm, lam))
            rep.iterations = it + 1
            if lam == 1.0 and norm < tol:
                rep.converged = True
                rep.residual = relative_residual(problem, X)
                return X, rep
        rep.residual = relative_residual(problem, X)
        rep.message = f"no convergence in {max_iter} iterations"
    return X, rep


def pseudo_transient(
    problem: Problem, X0: np.ndarray, *, dt0: float | None = None, max_iter: int = 400, switch: float = 1e-6
) -> tuple[np.ndarray, NewtonReport]:
    """Pseudo-transient continuation (ΨTC, Kelley & Keyes 1998) towards the steady state.

    Each step solves (M/δt)ΔX + J ΔX = −R once, with the physical mass matrix of the
    balances (ρV on u, (3/2)ρθV on ln θ; the normal-momentum rows are algebraic), so the
    iterates follow an approximate time evolution of the cell; δt grows as the scaled residual
    falls (switched evolution relaxation).  Once the relative residual is below ``switch`` the
    state is handed to :func:`newton`.
    """
    import scipy.sparse as sp

    X = X0.copy()
    rep = NewtonReport(False, 0)
    x = problem.x
    if dt0 is None:
        dt0 = 0.1 * (x[-1] - x[0]) / abs(problem.u_wall[1] - problem.u_wall[0])
    dt = dt0
    res0 = None
    with np.errstate(all="ignore"):
        for it in range(max_iter):
            t = problem.terms(X)
            R = problem.residual(X, t)
            rel_all = np.abs(R) / problem.residual_scales(t)
            rel = float(np.max(rel_all))
            res = float(np.sqrt(np.mean(rel_all**2)))
            rep.history.append((rel, res, dt))
            rep.iterations = it + 1
            if not np.isfinite(res):
                rep.message = "residual is not finite"
                return X, rep
            if rel < switch:
                Xn, rn = newton(problem, X)
                rep.history += rn.history
                rep.iterations += rn.iterations
                rep.converged, rep.residual, rep.message = rn.converged, rn.residual, rn.message
                return (Xn if rn.converged else X), rep
            res0 = res if res0 is None else res0
            dt = min(dt0 * res0 / res, 1e12) if it else dt0
            mass = np.zeros((problem.n, N_VARS))
            mass[:, 0] = problem.V * t["phi"]
            mass[:, 1] = 1.5 * problem.V * t["phi"] * t["theta"]
            for k, i in ((0, 0), (1, -1)):  # Dirichlet rows stay algebraic
                if problem.walls[k].momentum == "prescribed":
                    mass[i, 0] = 0.0
                if problem.walls[k].energy == "prescribed":
                    mass[i, 1] = 0.0
            J = problem.jacobian(X, R)
            for _ in range(20):
                try:
                    dX = -spla.splu((J + sp.diags(mass.ravel() / dt)).tocsc()).solve(R)
                except RuntimeError:
                    dX = np.full_like(X, np.nan)
                logs = np.abs(dX.reshape(-1, N_VARS)[:, 1:]).max()
                if np.isfinite(logs) and logs <= MAX_LOG_STEP and np.all(np.isfinite(problem.residual(X + dX))):
                    break
                dt *= 0.25
                dt0 *= 0.25
            else:
                rep.message = "pseudo-time step collapsed"
                rep.residual = rel
                return X, rep
            X = X + dX
        rep.residual = rel
        rep.message = f"pseudo-transient continuation did not reach the Newton basin in {max_iter} steps"
    return X, rep


def naive_start(problem: Problem) -> np.ndarray:
    """Uniform φ̄, velocity linear between the walls, θ of uniform shear at the nominal rate."""
    x = problem.x
    ub, ut = problem.u_wall
    u = ub + (ut - ub) * (x - x[0]) / (x[-1] - x[0])
    gdot = abs(ut - ub) / (x[-1] - x[0])
    phi = min(problem.mean_phi, 0.95 * problem.phi_max)
    e = min(problem.e, 0.999)
    ratio = float(steady_temperature(problem.model, phi, e))
    theta = np.full(x.size, ratio * gdot**2)
    return problem.pack(u, theta, np.full(x.size, phi))


def _staged_problem(target: Problem, values: dict[str, Any]) -> Problem:
    walls = [dataclasses.replace(w, specularity=values["specularity"][k]) for k, w in enumerate(target.walls)]
    return dataclasses.replace(target, mean_phi=values["mean_phi"], e=values["e"], bottom=walls[0], top=walls[1],
                               centrifugal=values["centrifugal"])


def _interpolate(a: dict[str, Any], b: dict[str, Any], s: float) -> dict[str, Any]:
    """Parameters a fraction s of the way from a to b (specularity geometrically)."""
    return {
        "mean_phi": a["mean_phi"] + s * (b["mean_phi"] - a["mean_phi"]),
        "e": a["e"] + s * (b["e"] - a["e"]),
        "centrifugal": a["centrifugal"] + s * (b["centrifugal"] - a["centrifugal"]),
        "specularity": [math.exp(math.log(x) + s * (math.log(y) - math.log(x))) for x, y in zip(a["specularity"], b["specularity"])],
    }


def homotopy_stages(problem: Problem) -> list[dict[str, Any]]:
    """Parameter states from an easy problem to the target, one parameter group changed per stage.

    Easy: mean φ ≤ 0.3, e ≥ 0.9, specularity ≥ 0.1, no centripetal term.  Stages: restitution and
    centripetal term, then specularity, then inventory.
    """
    target = {"mean_phi": problem.mean_phi, "e": problem.e, "centrifugal": problem.centrifugal,
              "specularity": [w.specularity for w in problem.walls]}
    easy = {"mean_phi": min(problem.mean_phi, 0.3), "e": max(problem.e, 0.9), "centrifugal": 0.0,
            "specularity": [max(w.specularity, 0.1) for w in problem.walls]}
    s1 = {**easy, "e": target["e"], "centrifugal": target["centrifugal"]}
    s2 = {**s1, "specularity": target["specularity"]}
    return [easy, s1, s2, target]


def homotopy_paths(problem: Problem) -> list[list[dict[str, Any]]]:
    """Two paths from the easy state: one parameter group per stage, then all parameters at once."""
    staged = homotopy_stages(problem)
    return [staged, [staged[0], staged[-1]]]


def _follow(problem: Problem, stages: list[dict[str, Any]], history: list, tol: float, max_iter: int,
            ptc_max_iter: int, continuation: str = "natural", resume: tuple | None = None):
    """Continuation through ``stages`` with adaptive steps; returns (X, iterations, steps, folds passed, arclength stages).

    ``continuation``: "natural" (raise where a stage stalls; the error's ``resume`` holds the stage,
    its fraction and the last solution there), "fallback" (from a stall on by arclength; with
    ``resume``, straight from where a natural run stalled) or "arclength" (every stage by arclength).
    """
    steps = 0
    arclength_stages = 0
    folds: list[float] = []

    def by_arclength(a, b, s, X, why):
        nonlocal total_it, steps, arclength_stages
        X, path = _arclength_stage(problem, a, b, s, X, history, tol, why)
        total_it += path.corrector_iterations
        steps += len(path.lam) - 1 + path.rejected_steps
        arclength_stages += 1
        folds.extend(path.folds)
        return X

    if resume is None:
        first, s_first, resume_why = 0, 0.0, ""
        sub = _staged_problem(problem, stages[0])
        X, rep = newton(sub, naive_start(sub), tol=tol, max_iter=max_iter)
        history += rep.history
        total_it = rep.iterations
        if not rep.converged:
            raise CouetteConvergenceError(
                f"Couette solver did not converge from the naive start nor from the easy state ({rep.message}); "
                f"last relative residual {rep.residual:.3g}", history, X, sub)
    else:
        first, s_first, X, resume_why = resume
        total_it = 0
    for k, (a, b) in enumerate(zip(stages[:-1], stages[1:])):
        if k < first:
            continue
        s, ds = (s_first if k == first else 0.0), 0.25
        if continuation == "arclength" or (resume is not None and k == first):
            X = by_arclength(a, b, s, X, resume_why if k == first else "")
            continue
        while s < 1.0:
            s_try = min(1.0, s + ds)
            sub = _staged_problem(problem, _interpolate(a, b, s_try))
            Xt, rep = newton(sub, X, tol=tol, max_iter=min(30, max_iter))
            history += rep.history
            total_it += rep.iterations
            steps += 1
            if rep.converged:
                s, X = s_try, Xt
                ds = min(1.0, 1.5 * ds)
                continue
            ds *= 0.5
            if ds >= 1e-3:
                continue
            where = (f"mean phi {sub.mean_phi:.4f}, e {sub.e:.4f}, specularity "
                     f"{[round(w.specularity, 5) for w in sub.walls]}")
            if continuation == "natural":
                err = CouetteConvergenceError(
                    f"Couette continuation stalled ({where}): {rep.message}; last relative residual "
                    f"{rep.residual:.3g}", history, Xt, sub)
                err.resume = (k, s, X, f"natural-parameter continuation stalled at {where} ({rep.message}); then ")
                raise err
            # natural-parameter steps cannot pass a turning point of the solution curve:
            # follow the rest of this stage by pseudo-arclength continuation
            X = by_arclength(a, b, s, X, f"natural-parameter continuation stalled at {where} ({rep.message}); then ")
            break
    return X, total_it, steps, folds, arclength_stages


def _arclength_then_newton(problem_at, end: Problem, X: np.ndarray, s: float, lam_min: float, history: list,
                           tol: float, stalled, unpolished):
    """Pseudo-arclength continuation of ``problem_at(λ)`` from λ = s to 1, then Newton on ``end`` (the problem at 1).

    ``stalled(exc)`` builds the error raised when the path stalls; ``unpolished(report)`` the message when Newton
    does not converge at the end.  Returns the solution and the path (its corrector count includes the polish).
    """
    try:
        X, path = arclength.follow(problem_at, X, s, 1.0, lam_min=lam_min)
    except arclength.ArclengthStall as exc:
        raise stalled(exc) from None
    Xn, rn = newton(end, X, tol=tol)
    history += rn.history
    path.corrector_iterations += rn.iterations
    if not rn.converged:
        raise CouetteConvergenceError(unpolished(rn), history, Xn, end)
    return Xn, path


def _arclength_stage(problem: Problem, a: dict[str, Any], b: dict[str, Any], s: float, X: np.ndarray,
                     history: list, tol: float, why: str = ""):
    """Pseudo-arclength continuation of one homotopy stage from its fraction s to 1, polished by Newton."""
    def stage(lam):
        return _staged_problem(problem, _interpolate(a, b, lam))

    def stalled(exc):
        last = stage(exc.lam)
        _, theta, phi = last.unpack(exc.X)
        return CouetteConvergenceError(
            f"Couette continuation failed: {why}{exc} (there: mean phi {last.mean_phi:.4f}, e {last.e:.4f}, "
            f"specularity {[round(w.specularity, 5) for w in last.walls]}; the last point has max phi = "
            f"phi_max - {last.phi_max - float(phi.max()):.2g} and min theta = {float(theta.min()):.2g} V^2)",
            history, exc.X, last)

    return _arclength_then_newton(
        stage, _staged_problem(problem, b), X, s, 0.0, history, tol, stalled,
        lambda rn: (f"Couette continuation: the arclength path reached the end of the stage but Newton did not "
                    f"polish it ({rn.message}; relative residual {rn.residual:.3g})"))


def _with_wall_friction(problem: Problem, s: float) -> Problem:
    """``problem`` with each wall's tan δ_w scaled by s (s = 1: the problem itself)."""
    walls = [dataclasses.replace(w, friction_angle=math.degrees(math.atan(s * math.tan(math.radians(w.friction_angle)))))
             for w in problem.walls]
    return dataclasses.replace(problem, bottom=walls[0], top=walls[1])


def _wall_friction_continuation(problem: Problem, start: np.ndarray, tol: float, max_iter: int, ptc_max_iter: int,
                                continuation: str) -> tuple[np.ndarray, dict[str, Any]]:
    """Frictional walls: the cell with δ_w = 0 first (by every path of :func:`solve`), then tan δ_w from 0 to its value.

    Natural-parameter steps in s = tan δ_w / tan δ_w,target (adaptive, as :func:`_follow`), each a Newton solve from
    the previous solution.  Where they stall (a turning point: the wall goes from sliding to sticking through an
    S-shaped curve, docs/friction.md §8) the rest is followed by pseudo-arclength continuation in s.  Raises
    :class:`CouetteConvergenceError` if that stalls too (the caller then takes the generic fallbacks).
    """
    X, info = solve(_with_wall_friction(problem, 0.0), start, tol=tol, max_iter=max_iter, ptc_max_iter=ptc_max_iter,
                    continuation=continuation)
    history = info["history"]
    s, ds, steps = 0.0, 1.0, 0
    while s < 1.0:
        s_try = min(1.0, s + ds)
        sub = _with_wall_friction(problem, s_try)
        Xt, rep = newton(sub, X, tol=tol, max_iter=min(30, max_iter))
        history += rep.history
        info["iterations"] += rep.iterations
        steps += 1
        if rep.converged:
            s, X, ds = s_try, Xt, min(1.0, 1.5 * ds)
            continue
        ds *= 0.5
        if ds >= 1e-3:
            continue
        why = (f"continuation in the wall friction angle stalled at tan(delta_w) = {s_try:.4f} of its value: "
               f"{rep.message}")
        if s == 0.0:  # no arclength start: ∂R/∂s is a central difference, and s < 0 is no wall
            raise CouetteConvergenceError(why, history, Xt, sub)
        X, path = _arclength_then_newton(
            lambda lam: _with_wall_friction(problem, lam), problem, X, s, 0.5 * s, history, tol,
            lambda exc: CouetteConvergenceError(f"{why}; then {exc}", history, exc.X, sub),
            lambda rn: f"{why}; the arclength path reached tan(delta_w) but Newton did not polish it ({rn.message})")
        info["iterations"] += path.corrector_iterations
        steps += len(path.lam) - 1 + path.rejected_steps
        info["wall_friction_folds"] = path.folds  # the values of s at the turning points passed
        break
    how = " by arclength" if "wall_friction_folds" in info else ""
    info.update(continuation_steps=info.get("continuation_steps", 0) + steps, residual=relative_residual(problem, X),
                path=f"delta_w-continuation{how} ({info['path']} at delta_w = 0)", method="wall-friction continuation")
    return X, info


#: Mesh sequencing coarsens a grid (every other node) down to at most this many nodes.
COARSEST_NODES = 64


def prolonged(coarse: Problem, fine: Problem, X: np.ndarray) -> np.ndarray:
    """The unknowns ``X`` of ``coarse`` interpolated linearly in (u, ln θ, ψ) onto the nodes of ``fine``."""
    Xm = X.reshape(coarse.n, -1)
    return np.column_stack([np.interp(fine.x, coarse.x, Xm[:, k]) for k in range(Xm.shape[1])]).ravel()


def _mesh_sequenced(problem: Problem, tol: float, max_iter: int, ptc_max_iter: int,
                    continuation: str) -> tuple[np.ndarray, dict[str, Any]] | None:
    """The last fallback: solve on every other node, repeatedly (to at most :data:`COARSEST_NODES` nodes), then
    Newton on each finer grid from the coarser solution interpolated linearly in (u, ln θ, ψ).

    Continuation in φ̄ on a fine grid can snake through fold pairs, one per cell that a front crosses, until its
    steps run out, while the target state is reached at once from the coarse solution (docs/dense_physics.md §8).
    Returns None where the grid cannot be coarsened (too few nodes, or an even node count).
    """
    levels = [problem]
    while levels[-1].n > COARSEST_NODES and (levels[-1].n - 1) % 2 == 0:
        levels.append(dataclasses.replace(levels[-1], x=levels[-1].x[::2]))
    if len(levels) == 1:
        return None
    X, info = solve(levels[-1], tol=tol, max_iter=max_iter, ptc_max_iter=ptc_max_iter, continuation=continuation)
    coarsest = f"{info['path']} on {levels[-1].n - 1} cells"
    for coarse, fine in zip(levels[:0:-1], levels[-2::-1]):
        X, rep = newton(fine, prolonged(coarse, fine, X), tol=tol, max_iter=max_iter)
        info["history"] = list(info["history"]) + list(rep.history)
        info["iterations"] += rep.iterations
        if not rep.converged:
            raise CouetteConvergenceError(f"Newton on {fine.n - 1} cells from the {coarse.n - 1}-cell solution did not "
                                          f"converge ({rep.message})", info["history"], X, fine)
    info.update(residual=relative_residual(problem, X), method="mesh sequencing",
                path=f"mesh-sequencing ({coarsest})")
    return X, info


def solve(problem: Problem, X0: np.ndarray | None = None, *, tol: float = 1e-10, max_iter: int = 60,
          ptc_max_iter: int = 400, continuation: str = "natural") -> tuple[np.ndarray, dict[str, Any]]:
    """Solve the steady problem; returns the unknowns and a dict of solver diagnostics.

    ``max_iter`` bounds each Newton solve, ``ptc_max_iter`` each pseudo-transient run.
    ``continuation``: ``"natural"`` (default: natural-parameter homotopy paths; only if every one
    stalls, each resumed where it stalled with pseudo-arclength continuation) or
    ``"arclength"`` (pseudo-arclength for every homotopy stage).  The diagnostics hold
    ``folds``: the stage fractions of the turning points passed.

    Raises
    ------
    CouetteConvergenceError
        With the residual history and the last iterate, if neither Newton from the start, nor
        the continuation, nor mesh sequencing converges.
    """
    if continuation not in ("natural", "arclength"):
        raise InputError(f"continuation = {continuation!r} is not valid: choose 'natural' or 'arclength'")
    start = naive_start(problem) if X0 is None else X0
    X, rep = newton(problem, start, tol=tol, max_iter=max_iter)
    history = list(rep.history)
    if rep.converged:
        return X, {"iterations": rep.iterations, "continuation_steps": 0, "residual": rep.residual, "history": history,
                   "path": "newton"}
    if any(w.friction_angle > 0.0 for w in problem.walls):
        try:
            X, info = _wall_friction_continuation(problem, start, tol, max_iter, ptc_max_iter, continuation)
        except CouetteConvergenceError as exc:
            history += exc.history  # fall back on the generic paths, with the wall friction on all along
        else:
            info["iterations"] += rep.iterations
            info["history"] = history + info["history"]
            return X, info
    X, rep2 = pseudo_transient(problem, start, max_iter=ptc_max_iter)
    history += rep2.history
    if rep2.converged:
        return X, {"iterations": rep.iterations + rep2.iterations, "continuation_steps": 0,
                   "residual": rep2.residual, "history": history, "method": "pseudo-transient",
                   "path": "pseudo-transient"}

    total_it = rep.iterations + rep2.iterations
    steps = 0
    # natural-parameter paths first, so that every case they solve keeps its solution (a fold passed
    # by arclength can lead to another branch: docs/dense.md §5.2); arclength only where they stall
    rounds = ("natural", "fallback") if continuation == "natural" else ("arclength",)
    done = False
    paths = homotopy_paths(problem)
    resumes: list[tuple | None] = [None] * len(paths)
    for mode in rounds:
        failure: CouetteConvergenceError | None = None
        for i, stages in enumerate(paths):
            try:
                X, it, st, folds, n_arc = _follow(problem, stages, history, tol, max_iter, ptc_max_iter, mode,
                                           resumes[i] if mode == "fallback" else None)
            except CouetteConvergenceError as exc:
                failure = failure or exc
                resumes[i] = getattr(exc, "resume", None)
                continue
            total_it, steps, done = total_it + it, steps + st, True
            break
        if done:
            break
    if not done:
        assert failure is not None
        try:
            sequenced = _mesh_sequenced(problem, tol, max_iter, ptc_max_iter, continuation)
        except CouetteConvergenceError as exc:
            raise CouetteConvergenceError(f"{failure}; then mesh sequencing failed: {exc}", history,
                                          failure.last_iterate, failure.problem) from None
        if sequenced is None:
            raise failure
        X, info = sequenced
        info["iterations"] += total_it
        info["history"] = history + info["history"]
        return X, info
    return X, {"iterations": total_it, "continuation_steps": steps, "residual": relative_residual(problem, X),
               "history": history, "method": "continuation", "folds": folds,
               "path": "arclength" if n_arc else "natural"}
