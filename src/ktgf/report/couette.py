"""Section 3: the planar Couette cell — u, φ and θ profiles of the models against the DEM.

The case is the DEM run of ``dem_couette_e0.9_phi0.50.csv`` (U = 10, mean φ = 0.50, e = 0.9,
units d = m = 1); the continuum cell is the slab between the planes tangent to the wall spheres,
H = 19 d (wall-sphere centres at ±10).  The section needs the Couette
solver (package :mod:`ktgf.couette`); without it the page says "not available in this build".

Contract with the solver (the one thing to wire up)
---------------------------------------------------
The section calls :data:`ENTRY_POINT`, ``ktgf.couette.report_profiles``, once per model::

    report_profiles(model: ktgf.Model, *, phi_mean: float, e: float, height: float,
                    wall_speed: float, d: float, rho_s: float, n_cells: int,
                    dem_path=None) -> xarray.Dataset

returning the steady profiles with

* coordinate ``y``: distance from the channel centre, −height/2 … height/2, in the units of ``d``;
* variables ``u`` (mean velocity along the walls, walls at ∓wall_speed/2), ``phi`` and ``theta``
  (granular temperature per unit mass), all on ``y``;
* attrs from :func:`ktgf.io.run_metadata` including the wall condition used and its calibration
  (e.g. Johnson–Jackson specularity, said to be calibrated on this DEM case), and optionally
  ``valid`` (0/1: max φ below random close packing) and ``max_phi``.

If the solver's API differs, adapt :func:`solve_profiles` (the only call into it).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from ..closures.models import get_model
from ..io import run_metadata
from .dem import COUETTE, read_table
from .framework import Section, SectionContext, closest, join_labels, model_inputs, optional_entry, register_section
from .settings import ReportSettings

#: module, function: the agreed entry point of the Couette solver.
ENTRY_POINT = ("ktgf.couette", "report_profiles")
#: DEM units: d = 1, m = 1 → ρ_s = 6/π.
RHO_S_DEM = 6.0 / math.pi


_entry, available = optional_entry(*ENTRY_POINT, "the Couette solver", "(model, *, phi_mean, e, height, wall_speed, d, rho_s, n_cells)")


def solve_profiles(model: Any, s: ReportSettings, dem_path: Any = None) -> xr.Dataset:
    """Steady profiles of one model for the report's Couette case (the only call into the solver).

    With the DEM file, the solver fits each model's wall specularity to the DEM slip.
    """
    fn = _entry()
    if fn is None:
        raise RuntimeError(available() or "Couette solver unavailable")
    extra = {"dem_path": dem_path} if dem_path is not None else {}
    return fn(model, phi_mean=s.couette_phi_mean, e=s.couette_e, height=s.couette_height,
              wall_speed=s.couette_wall_speed, d=1.0, rho_s=RHO_S_DEM, n_cells=s.couette_cells, **extra)


def inputs(s: ReportSettings) -> dict[str, Any]:
    return {"models": model_inputs(s.models), "phi_mean": s.couette_phi_mean, "e": s.couette_e,
            "height": s.couette_height, "wall_speed": s.couette_wall_speed, "cells": s.couette_cells}


def profile_errors(y: np.ndarray, prof: dict[str, np.ndarray], dem: dict[str, np.ndarray], height: float,
                   wall_speed: float) -> dict[str, float]:
    """Errors of model profiles against the DEM bins inside the slab (|y| < H/2 − d/2, DEM φ > 0.05).

    Returns RMS(u − u_DEM)/U, RMS(φ − φ_DEM) and RMS(θ/θ_DEM − 1): velocity relative to the wall
    speed, solid fraction absolute, temperature relative (θ varies ~10× across the cell).
    """
    inside = (np.abs(dem["y"]) < height / 2 - 0.5) & (dem["phi"] > 0.05) & (dem["theta"] > 0)
    yd = dem["y"][inside]
    order = np.argsort(y)
    at = {k: np.interp(yd, y[order], prof[k][order]) for k in ("u", "phi", "theta")}
    return {
        "u_rms_over_U": float(np.sqrt(np.mean((at["u"] - dem["ux"][inside]) ** 2)) / wall_speed),
        "phi_rms": float(np.sqrt(np.mean((at["phi"] - dem["phi"][inside]) ** 2))),
        "theta_rms_rel": float(np.sqrt(np.mean((at["theta"] / dem["theta"][inside] - 1.0) ** 2))),
    }


def plot_profiles(ds: xr.Dataset, out: Any) -> Any:
    """u, φ and θ across the gap, one line per model, DEM points with error bars."""
    import matplotlib.pyplot as plt

    from ..plotting import save
    from ..plotting.hcs import MODEL_COLOURS

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.4), constrained_layout=True)
    for ax, var, lab in zip(axes, ("u", "phi", "theta"), ("velocity $u$", r"solid fraction $\phi$", r"temperature $\theta$")):
        for i in range(ds.sizes["model"]):
            ax.plot(ds[var][i], ds.y, color=MODEL_COLOURS[i % len(MODEL_COLOURS)], label=str(ds.label[i].values))
        if f"{var}_dem" in ds:
            occupied = ds.phi_dem.values > 0.05  # bins inside the wall layers hold no flowing particles
            ax.errorbar(ds[f"{var}_dem"].values[occupied], ds.y_dem.values[occupied], xerr=ds[f"{var}_dem_sem"].values[occupied],
                        fmt="k.", ms=4, label="DEM")
        ax.set_xlabel(lab)
        ax.set_ylabel("y / d")
        ax.grid(True, alpha=0.3)
    axes[2].set_xscale("log")
    from matplotlib.ticker import NullFormatter

    axes[2].xaxis.set_minor_formatter(NullFormatter())  # minor labels of a one-decade log axis overlap
    axes[0].legend(fontsize=8)
    fig.suptitle("Planar Couette cell: profiles across the gap")
    return save(fig, out)


def run(ctx: SectionContext) -> None:
    s = ctx.settings
    path = ctx.data_file(COUETTE)
    dem = read_table(path) if path is not None else None
    sols = {}
    for n in s.models:
        ctx.step(f"solving the Couette cell with {get_model(n).label}")
        sols[n] = solve_profiles(get_model(n), s, path)
    y = np.asarray(sols[s.models[0]].y, dtype=float)
    data: dict[str, Any] = {}
    for var in ("u", "phi", "theta"):
        data[var] = (("model", "y"), np.array([np.interp(y, np.asarray(sols[n].y), np.asarray(sols[n][var])) for n in s.models]))
    coords: dict[str, Any] = {"model": list(s.models), "label": ("model", [get_model(n).label for n in s.models]), "y": y}
    if dem is not None:
        for var, col in (("u", "ux"), ("phi", "phi"), ("theta", "theta")):
            data[f"{var}_dem"] = (("y_dem",), dem[col], {"source": COUETTE})
            data[f"{var}_dem_sem"] = (("y_dem",), dem[f"{col}_sem"])
        coords["y_dem"] = dem["y"]
    ds = xr.Dataset(data, coords=coords, attrs=run_metadata(None, **{k: v for k, v in inputs(s).items() if k != "models"},
                                                            models=list(s.models), units="d = m = 1"))
    plot_profiles(ds, ctx.figure_path("couette_profiles"))
    ctx.add_figure("couette_profiles", f"Velocity, solid fraction and temperature across the Couette cell (H = {s.couette_height:g} d, "
                   f"U = {s.couette_wall_speed:g}, mean φ = {s.couette_phi_mean:g}, e = {s.couette_e:g})"
                   + (f", against the DEM ({COUETTE})." if dem is not None else "."), ds)
    walls = {n: sols[n].attrs.get("wall", sols[n].attrs.get("boundary_condition", "")) for n in s.models}
    if any(walls.values()):
        ctx.paragraph("Wall conditions: " + "; ".join(f"{get_model(n).label}: {w}" for n, w in walls.items() if w) + ".")
    rows, errs = [], {}
    for n in s.models:
        sol = sols[n]
        max_phi = float(sol.attrs.get("max_phi", float(np.max(sol["phi"]))))
        valid = sol.attrs.get("valid", None)
        row: list[Any] = [get_model(n).label, max_phi, "—" if valid is None else ("yes" if int(valid) else "no (φ > φ_rcp)")]
        if dem is not None:
            errs[n] = profile_errors(np.asarray(sol.y), {k: np.asarray(sol[k]) for k in ("u", "phi", "theta")}, dem,
                                     s.couette_height, s.couette_wall_speed)
            row += [errs[n]["u_rms_over_U"], errs[n]["phi_rms"], 100 * errs[n]["theta_rms_rel"]]
        rows.append(row)
    cols = ["model", "max φ", "physically valid"] + (["RMS(u−u_DEM)/U", "RMS(φ−φ_DEM)", "RMS(θ/θ_DEM−1) %"] if dem is not None else [])
    ctx.table("Couette profiles: validity and error against DEM", cols, rows,
              note="Errors over the DEM bins inside the slab |y| < H/2 − d/2. The wall condition is calibrated on this same DEM case "
                   "(see the solver's attrs), so these errors measure the bulk closures, not a blind prediction.")
    if errs:
        ctx.number("couette_errors", errs)


def discuss(nb: dict[str, Any]) -> list[str]:
    errs = nb.get("couette_errors")
    if not errs:
        return []
    out = []
    for key, name in (("u_rms_over_U", "velocity"), ("phi_rms", "solid fraction"), ("theta_rms_rel", "temperature")):
        best = closest({n: errs[n][key] for n in errs})
        out.append(f"Couette {name}: closest to the DEM: {join_labels(best)} ("
                   + ", ".join(f"{get_model(n).label} {errs[n][key]:.3g}" for n in errs) + f"; metric {key}).")
    return out


SECTION = register_section(Section(
    "couette", "3. Couette shear cell", run, inputs, order=30, data_files=(COUETTE,),
    modules=(ENTRY_POINT[0], "ktgf.report.dem"), available=available, discuss=discuss,
))
