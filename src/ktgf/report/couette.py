"""Section 3: the planar Couette cell — u, φ and θ profiles of the models against the DEM.

The case is the DEM run of ``dem_couette_e0.9_phi0.50.csv`` (U = 10, mean φ = 0.50, e = 0.9,
units d = m = 1); the continuum cell is the slab between the planes tangent to the wall spheres,
H = 19 d (wall-sphere centres at ±10).  The profiles come from
:func:`ktgf.couette.compare.report_profiles` (one call per model, :func:`solve_profiles`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from ..closures.models import get_model
from ..io import run_metadata
from ..data import COUETTE, read_table
from ..couette.compare import report_profiles
from ..plotting.couette import plot_profile_comparison
from .framework import Section, SectionContext, closest, join_labels, model_inputs, register_section
from .overlap import overlap_sentence
from .settings import ReportSettings

#: DEM units: d = 1, m = 1 → ρ_s = 6/π.
RHO_S_DEM = 6.0 / math.pi


#: Error metrics of the profile table: key of :func:`profile_errors` -> (column title, factor shown).
#: Further columns (e.g. wall stresses against the DEM) are added by extending this mapping.
ERROR_COLUMNS = {
    "u_rms_over_U": ("RMS(u−u_DEM)/U", 1.0),
    "phi_rms": ("RMS(φ−φ_DEM)", 1.0),
    "theta_rms_rel": ("RMS(θ/θ_DEM−1) %", 100.0),
}
LONG_NAMES = {"u": "mean velocity along the walls in DEM units", "phi": "solid fraction",
              "theta": "granular temperature per unit mass in DEM units"}



def solve_profiles(model: Any, s: ReportSettings, dem_path: Any = None) -> xr.Dataset:
    """Steady profiles of one model for the report's Couette case (the only call into the solver).

    With the DEM file, the solver fits each model's wall specularity to the DEM slip.
    """
    extra = {"dem_path": dem_path} if dem_path is not None else {}
    return report_profiles(model, phi_mean=s.couette_phi_mean, e=s.couette_e, height=s.couette_height,
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


def run(ctx: SectionContext) -> None:
    s = ctx.settings
    path = ctx.data_file(COUETTE)
    dem = read_table(path).as_dict() if path is not None else None
    sols = {}
    for n in s.models:
        ctx.step(f"solving the Couette cell with {get_model(n).label}")
        sols[n] = solve_profiles(get_model(n), s, path)
    y = np.asarray(sols[s.models[0]].y, dtype=float)
    data: dict[str, Any] = {}
    for var in ("u", "phi", "theta"):
        data[var] = (("model", "y"), np.array([np.interp(y, np.asarray(sols[n].y), np.asarray(sols[n][var])) for n in s.models]),
                     {"long_name": LONG_NAMES[var], "units": "1"})
    dem_units = {"units": "1"}
    coords: dict[str, Any] = {"model": list(s.models), "label": ("model", [get_model(n).label for n in s.models]),
                              "y": ("y", y, {"long_name": "distance from the channel centre in particle diameters", "units": "1"}),
                              "wall_speed": ((), s.couette_wall_speed, {"long_name": "relative wall speed U in DEM units", "units": "1"})}
    if dem is not None:
        for var, col in (("u", "ux"), ("phi", "phi"), ("theta", "theta")):
            data[f"{var}_dem"] = (("y_dem",), dem[col], {"source": COUETTE, "long_name": "DEM " + LONG_NAMES[var], **dem_units})
            data[f"{var}_dem_sem"] = (("y_dem",), dem[f"{col}_sem"], {"long_name": "standard error of the DEM " + var, **dem_units})
        coords["y_dem"] = ("y_dem", dem["y"], {"long_name": "DEM bin centre, distance from the channel centre in diameters", "units": "1"})
    ds = xr.Dataset(data, coords=coords, attrs=run_metadata(None, **{k: v for k, v in inputs(s).items() if k != "models"},
                                                            models=list(s.models), units="d = m = 1"))
    plot_profile_comparison(ds, ctx.figure_path("couette_profiles"))
    overlaps = "".join(overlap_sentence({n: ds[v].sel(model=n).values for n in s.models}, f"{v} profiles")
                       for v in ("u", "phi", "theta"))
    ctx.add_figure("couette_profiles", f"Velocity u/U, solid fraction and temperature θ/U² across the Couette cell (H = {s.couette_height:g} d, "
                   f"U = {s.couette_wall_speed:g}, mean φ = {s.couette_phi_mean:g}, e = {s.couette_e:g}; DEM units d = m = 1)"
                   + (f", against the DEM ({COUETTE})." if dem is not None else ".") + overlaps, ds)
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
            row += [errs[n][k] * f for k, (_, f) in ERROR_COLUMNS.items()]
        rows.append(row)
    cols = ["model", "max φ", "physically valid"]
    if dem is not None:
        cols += [title for title, _ in ERROR_COLUMNS.values()]
        ctx.table("Couette profiles: validity and profile-shape error against DEM", cols, rows,
                  note="Errors over the DEM bins inside the slab |y| < H/2 − d/2. The wall condition is calibrated on this same DEM case "
                       "(see the solver's attrs), so these errors measure the bulk closures, not a blind prediction.")
        ctx.number("couette_errors", errs)
    else:
        ctx.table("Couette profiles: validity (no DEM data, so no error column)", cols, rows,
                  note="Without the DEM file the wall condition is the solver's default (not calibrated); "
                       "the profiles are predictions with nothing to compare them with.")
    ctx.number("couette_max_phi", {n: float(r[1]) for n, r in zip(s.models, rows)})


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
    modules=("ktgf.couette", "ktgf.data"), discuss=discuss,
))
