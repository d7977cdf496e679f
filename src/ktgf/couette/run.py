"""High-level Couette runs: build the problem, solve, and return an xarray Dataset in SI units.

Glossary of the Dataset (coordinate ``y`` [m] for the planar cell, ``r`` [m] for the annular one):
``u`` tangential velocity, ``phi`` solid fraction, ``theta`` granular temperature, ``p`` pressure,
``shear_rate``, ``shear_stress`` (η × shear rate at the nodes), ``heat_flux`` (q_x on the faces),
``wall_*`` per wall (bottom = y = −H/2 or r = R_i; top = y = +H/2 or r = R_o), the energy budget
and the validity flag (:func:`validity`: max φ against φ_rcp and the model's packing limit, θ collapse).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from ..closures import get_model
from ..errors import ConvergenceError
from ..io import run_metadata, write_netcdf
from ..validation import check_positive, check_range
from .equations import Problem
from .geometry import stretched_nodes
from .solver import CouetteConvergenceError, solve
from .walls import Wall

WALLS = ("bottom", "top")
#: A core is jammed when max φ is within this fraction of the model's own packing limit ...
JAM_TOLERANCE = 0.01
#: ... or when θ has collapsed: min θ below this fraction of max θ, or below this fraction of U².
THETA_COLLAPSE_RATIO = 1e-4
THETA_COLLAPSE_U2 = 1e-10


def validity(max_phi: float, phi_rcp: float, phi_max_model: float, theta: np.ndarray, v_scale: float,
             model_name: str = "", jam_tolerance: float = JAM_TOLERANCE) -> str:
    """``"ok"`` or why a Couette solution is not physical (model.md §9 and issue 11).

    Three tests, for every model: max φ above random close packing φ_rcp; max φ within
    ``jam_tolerance`` (relative) of the model's own packing limit, where its pressure and
    viscosity diverge and the "solution" is a jammed plug (models whose limit is φ_rcp could
    never trip the first test); and a collapsed temperature (min θ < 1e-4 max θ or < 1e-10 U²:
    a frozen core, e.g. θ ≈ 1e-17 U²).
    """
    reasons = []
    if max_phi > phi_rcp:
        reasons.append(f"max phi = {max_phi:.4f} exceeds phi_rcp = {phi_rcp:g}")
    if phi_max_model < 1.0 and max_phi >= (1.0 - jam_tolerance) * phi_max_model:
        reasons.append(f"jammed core: max phi = {max_phi:.4f} is within {jam_tolerance:.0%} of the packing limit "
                       f"{phi_max_model:g} of {model_name or 'the model'}")
    t_min, t_max = float(np.min(theta)), float(np.max(theta))
    if not (np.isfinite(t_min) and t_min >= THETA_COLLAPSE_RATIO * t_max and t_min >= THETA_COLLAPSE_U2 * v_scale**2):
        reasons.append(f"collapsed temperature: min theta = {t_min / v_scale**2:.3g} U^2 "
                       f"({t_min / t_max if t_max > 0 else float('nan'):.3g} of max theta)")
    return "ok" if not reasons else "invalid: " + "; ".join(reasons) + " (model.md section 9)"


@dataclass(frozen=True)
class Material:
    """Particle diameter d [m], material density ρ_s [kg/m³] and restitution e."""

    d: float
    rho_s: float
    e: float

    def __post_init__(self) -> None:
        check_positive("particle diameter d", self.d, "m")
        check_positive("material density rho_s", self.rho_s, "kg/m^3")
        check_range("restitution coefficient e", self.e, low=0.0, high=1.0, low_open=True)


def build_problem(model, geometry, bottom: Wall, top: Wall, mean_phi: float, material: Material,
                  n_cells: int = 200, stretch: float = 1.5) -> Problem:
    """The discrete problem in solver units (lengths in d, velocities in the wall-speed scale, ρ_s = 1)."""
    model = get_model(model)
    check_range("mean solid fraction mean_phi", mean_phi, low=0.0, high=model.phi_max, low_open=True,
                high_open=True, why=f"packing limit of {model.label or model.name}")
    x0, x1 = geometry.bounds(material.d)
    if x1 - x0 < 1.0:
        from ..errors import InputError

        raise InputError(f"gap = {(x1 - x0) * material.d:g} m is out of range: valid gap >= one particle diameter d = {material.d:g} m")
    x = stretched_nodes(x0, x1, n_cells, stretch)
    V = geometry.velocity_scale()
    return Problem(model, geometry, bottom, top, float(mean_phi), material.e, x, v_scale=V,
                   stress_scale=material.rho_s * V**2)


def to_dataset(problem: Problem, X: np.ndarray, material: Material, *, phi_rcp: float = 0.64,
               info: dict[str, Any] | None = None, converged: bool = True) -> xr.Dataset:
    """Fields, wall quantities, budget and metadata of a (converged or last) iterate, in SI units."""
    g, d, rho = problem.geometry, material.d, material.rho_s
    V = g.velocity_scale()
    t = problem.terms(X)
    coord = g.coordinate
    x_si = problem.x * d
    u, theta, phi = t["u"], t["theta"], t["phi"]
    gdot_hat = g.shear_rate(u, problem.x)
    stress_scale = rho * V**2
    flux_scale = rho * V**3

    # wall quantities (shear traction, heat flux into the medium, slip work): from the balances of the
    # wall half-cells, so they are defined for every wall condition
    S = g.stress_metric(problem.x[[0, -1]])
    Bw = g.volume_metric(problem.x[[0, -1]])
    F_face = t["F"]
    tau_wall = np.array([F_face[0], F_face[-1]]) / S  # wall half-cells carry no momentum source
    n0 = 0.5 * t["P"][0] - problem.V[0] * t["gamma"][0]
    nN = 0.5 * t["P"][-1] - problem.V[-1] * t["gamma"][-1]
    Q_b = t["E"][0] + n0          # = E_wall[0] at a solution
    Q_t = t["E"][-1] - nN
    heat_in = np.array([-Q_b / Bw[0], Q_t / Bw[1]])
    slip = t["slip"]
    slip_work = np.array([1.0, -1.0]) * tau_wall * slip  # traction power lost to slip at each wall
    wbar = g.angular(np.array(problem.u_wall), problem.x[[0, -1]])
    power_in = float(np.mean(F_face) * (wbar[1] - wbar[0]))
    dissipation = float(problem.V @ t["gamma"]) + float(np.sum(t["frictional_work"]))  # collisions + contact friction
    budget = power_in - dissipation + float(np.sum(Bw * (heat_in - slip_work)))
    max_phi = float(phi.max())
    verdict = validity(max_phi, phi_rcp, float(problem.model.phi_max), theta * V**2, V,
                       problem.model.label or problem.model.name)
    if "collapsed temperature" in verdict and float(t["p_frictional"][int(np.argmin(theta))]) > 0.0:
        # with a frictional stress a cold core is a creeping quasi-static layer, not a frozen collisional one
        verdict += (" [the coldest node carries a frictional stress: a creeping core whose theta is set by the "
                    "regularisation eps, docs/friction.md section 8]")
    valid = verdict == "ok"

    ds = xr.Dataset(
        {
            "u": (coord, u * V, {"long_name": "tangential velocity", "units": "m/s"}),
            "phi": (coord, phi, {"long_name": "solid volume fraction", "units": "1"}),
            "theta": (coord, theta * V**2, {"long_name": "granular temperature", "units": "m2/s2"}),
            "p": (coord, t["p"] * stress_scale, {"long_name": "pressure (kinetic-collisional + frictional)", "units": "Pa"}),
            "p_frictional": (coord, t["p_frictional"] * stress_scale,
                             {"long_name": "frictional (enduring-contact) pressure, blended", "units": "Pa"}),
            "shear_rate": (coord, gdot_hat * V / d, {"long_name": "shear rate", "units": "1/s"}),
            "shear_stress": (coord, t["eta"] * gdot_hat * stress_scale,
                             {"long_name": "shear stress eta*shear rate at the nodes", "units": "Pa"}),
            "shear_stress_face": (f"{coord}_face", F_face / g.stress_metric(problem.xf) * stress_scale,
                                  {"long_name": "conserved shear stress flux on the faces", "units": "Pa"}),
            "heat_flux": (f"{coord}_face", -t["E"] / problem.B * flux_scale,
                          {"long_name": f"heat flux q_{coord} (kappa and omega terms)", "units": "W/m2"}),
            "wall_shear_stress": ("wall", tau_wall * stress_scale, {"units": "Pa"}),
            "wall_slip": ("wall", slip * V, {"long_name": "u - u_wall at the wall", "units": "m/s"}),
            "wall_heat_flux": ("wall", heat_in * flux_scale, {"long_name": "heat flux into the medium", "units": "W/m2"}),
            "wall_theta": ("wall", theta[[0, -1]] * V**2, {"units": "m2/s2"}),
            "wall_phi": ("wall", phi[[0, -1]], {"units": "1"}),
        },
        coords={
            coord: (coord, x_si, {"units": "m"}),
            f"{coord}_face": (f"{coord}_face", problem.xf * d, {"units": "m"}),
            "wall": ("wall", list(WALLS)),
        },
    )
    params = {
        **g.describe(), "mean_phi": problem.mean_phi, "e": material.e, "d": d, "rho_s": rho,
        "walls": {k: w.describe() for k, w in zip(WALLS, problem.walls)},
        "n_cells": int(problem.n - 1), "phi_rcp": phi_rcp,
    }
    ds.attrs.update(run_metadata(problem.model, **params))
    info = info or {}
    ds.attrs.update({
        "geometry": g.kind,
        "converged": int(converged),
        "solver_iterations": int(info.get("iterations", -1)),
        "solver_relative_residual": float(info.get("residual", np.nan)),
        "max_phi": max_phi,
        "phi_rcp": phi_rcp,
        "physically_valid": int(valid),
        "validity": verdict,
        "model_packing_limit": float(problem.model.phi_max),
        "theta_min_over_U2": float(theta.min()),
        "power_in": power_in * flux_scale,
        "bulk_dissipation": dissipation * flux_scale,
        "energy_budget_relative_error": abs(budget) / abs(power_in) if power_in else np.nan,
        "velocity_scale": V,
    })
    hist = info.get("history")
    if hist:
        h = np.asarray(hist, dtype=float)
        ds["residual_history"] = ("iteration", h[:, 0], {"long_name": "relative residual per iteration"})
    return ds


def run(model, geometry, bottom: Wall, top: Wall, mean_phi: float, material: Material, *,
        n_cells: int = 200, stretch: float = 1.5, phi_rcp: float = 0.64, tol: float = 1e-10,
        failed_path: str | Path | None = None, start: np.ndarray | None = None,
        max_iter: int = 60, ptc_max_iter: int = 400) -> xr.Dataset:
    """Solve one Couette cell and return the Dataset.

    Raises :class:`~ktgf.errors.ConvergenceError` (a one-line message) if the solver fails; the
    last iterate and the residual history are then written to ``failed_path`` (if given) and
    attached to the exception as ``.dataset``.
    """
    check_range("random close packing phi_rcp", phi_rcp, low=0.0, high=1.0, low_open=True)
    problem = build_problem(model, geometry, bottom, top, mean_phi, material, n_cells, stretch)
    try:
        X, info = solve(problem, start, tol=tol, max_iter=max_iter, ptc_max_iter=ptc_max_iter)
    except CouetteConvergenceError as exc:
        ds = to_dataset(exc.problem, exc.last_iterate, material, phi_rcp=phi_rcp,
                        info={"history": exc.history, "iterations": len(exc.history)}, converged=False)
        msg = str(exc)
        if failed_path is not None:
            write_netcdf(ds, failed_path)
            msg += f"; last iterate and residual history saved to {failed_path}"
        err = ConvergenceError(msg)
        err.dataset = ds  # type: ignore[attr-defined]
        err.history = exc.history  # type: ignore[attr-defined]
        raise err from None
    ds = to_dataset(problem, X, material, phi_rcp=phi_rcp, info=info)
    ds.attrs["solver_state"] = json.dumps({"continuation_steps": info.get("continuation_steps", 0),
                                           "folds_passed": len(info.get("folds", [])),
                                           "path": info.get("path", "")})
    return ds
