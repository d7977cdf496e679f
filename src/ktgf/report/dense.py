"""Section 5: the dense regime — uniform-shear η*, p* and p/(nT) against φ, and Couette wall stresses, against DEM.

Models: ``settings.dense_models``, by default the report's models plus ``dense`` when the registry
has it (the recommended dense composition of issue 9).  Curves: the Navier–Stokes uniform-shear
closed forms of model.md §9 (:func:`ktgf.shear.steady.steady_shear`) in the DEM files'
dimensionless columns (d = m = 1, γ̇ = 1):

* T = θ/(γ̇d)² from the energy balance η γ̇² = (3/2)ρθζ0;
* η* = η d²/√(mT) = (5/(16√π)) η/η0 (the ``eta_star`` column of ``dem_uniform_shear.csv``);
* p* = p/(ρ_s d² γ̇²) = φ T p/(nT) (the ``p_star`` column of ``dem_uniform_shear_friction.csv``);
* p/(nT), the model's reduced pressure.

DEM points: ``dem_uniform_shear.csv`` (e = 0.9) and the frictionless μ = 0 row of
``dem_uniform_shear_friction.csv`` (e = 0.7), read by :mod:`ktgf.data`.  Couette:
every model in the case of ``dem_couette_e0.9_phi0.50.csv``'s header with its specularity fitted
to the DEM slip (:func:`ktgf.couette.compare.compare_with_dem`); the wall shear stress and
pressure are predictions.  No parameter of the four paper models is fitted to any of these data.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from ..closures.models import get_model, list_models
from ..io import run_metadata
from ..data import COUETTE, FRICTION_SHEAR as FRICTION, UNIFORM_SHEAR, read_uniform_shear
from ..shear.steady import ETA0_DEM, steady_shear
from ..couette.compare import compare_with_dem
from ..plotting.shear import plot_shear_curves
from .framework import Section, SectionContext, closest, join_labels, model_inputs, register_section
from .settings import ReportSettings

#: Restitution of the curves: the two DEM uniform-shear sets.
CURVE_E = (0.9, 0.7)
QUANTITIES = {"T": "T = θ/(γ̇d)²", "eta_star": "η* = η d²/√(mT)", "p_star": "p* = p/(ρ_s d² γ̇²)", "p_over_nT": "p/(nT)"}


def section_models(s: ReportSettings) -> tuple[str, ...]:
    """The models of this section: the setting, else the report's models plus ``dense`` if registered."""
    if s.dense_models is not None:
        return s.dense_models
    registered = {m.name for m in list_models()}
    return tuple(s.models) + (("dense",) if "dense" in registered and "dense" not in s.models else ())


def inputs(s: ReportSettings) -> dict[str, Any]:
    return {"models": model_inputs(section_models(s)), "points": s.dense_points, "e": CURVE_E, "couette_cells": s.couette_cells}


def shear_state(model: Any, phi: np.ndarray, e: float) -> dict[str, np.ndarray]:
    """The four DEM columns of the uniform-shear closed forms at (φ, e)."""
    phi = np.asarray(phi, dtype=float)
    s = steady_shear(model, phi, e)
    return {k: np.broadcast_to(np.asarray(getattr(s, k), dtype=float), phi.shape) for k in ("T", "eta_star", "p_star", "p_over_nT")}


def shear_curves(names: tuple[str, ...], n: int) -> xr.Dataset:
    """Curves of every model at each e of :data:`CURVE_E` on φ ∈ [0.25, min(0.63, 0.995 φ_max)] (NaN beyond)."""
    phi = np.linspace(0.25, 0.63, n)
    data = {k: np.full((len(names), len(CURVE_E), n), np.nan) for k in QUANTITIES}
    for i, name in enumerate(names):
        m = get_model(name)
        ok = phi < 0.995 * m.phi_max
        for j, e in enumerate(CURVE_E):
            st = shear_state(m, phi[ok], e)
            for k in QUANTITIES:
                data[k][i, j, ok] = st[k]
    return xr.Dataset(
        {k: (("model", "e", "phi"), v, {"long_name": QUANTITIES[k], "units": "1"}) for k, v in data.items()},
        coords={"model": list(names), "label": ("model", [get_model(n).label or n for n in names]),
                "e": ("e", list(CURVE_E), {"long_name": "restitution coefficient", "units": "1"}),
                "phi": ("phi", phi, {"long_name": "solid fraction", "units": "1"})},
        attrs=run_metadata(None, models=list(names), points=n, figure="uniform shear, Navier-Stokes closed forms (model.md section 9)",
                           units="d = m = 1, shear rate 1"),
    )


def dem_points(ctx: SectionContext) -> dict[str, np.ndarray] | None:
    """The frictionless uniform-shear DEM states of both files (those present), in the four columns with errors."""
    sets = [read_uniform_shear(p) for p in (ctx.data_file(UNIFORM_SHEAR), ctx.data_file(FRICTION)) if p is not None]
    if not sets:
        return None
    phi = np.concatenate([d.phi for d in sets])
    e = np.concatenate([d.e for d in sets])
    T, dT = (np.concatenate([getattr(d, a)["T"] for d in sets]) for a in ("values", "sigmas"))
    eta, deta = (np.concatenate([getattr(d, a)["eta_over_eta0"] for d in sets]) for a in ("values", "sigmas"))
    p, dp = (np.concatenate([getattr(d, a)["p_over_nT"] for d in sets]) for a in ("values", "sigmas"))
    source = np.concatenate([[d.path.name] * d.phi.size for d in sets])
    # p* = φ T p/(nT): first-order propagation of the two (independent) standard errors
    pstar = phi * T * p
    return {"phi": phi, "e": e, "source": source, "T": T, "dT": dT, "eta_star": ETA0_DEM * eta,
            "deta_star": ETA0_DEM * deta, "p_star": pstar, "dp_star": pstar * np.hypot(dT / T, dp / p),
            "p_over_nT": p, "dp_over_nT": dp}


def _shear_table(ctx: SectionContext, names: tuple[str, ...], dem: dict[str, np.ndarray]) -> None:
    errs: dict[str, dict[str, list[float]]] = {}
    rows = []
    for n in names:
        m = get_model(n)
        errs[n] = {k: [] for k in ("T", "eta_star", "p_over_nT")}
        for j in range(dem["phi"].size):
            if dem["phi"][j] >= m.phi_max:
                errs[n]["T"].append(math.nan)
                errs[n]["eta_star"].append(math.nan)
                errs[n]["p_over_nT"].append(math.nan)
                continue
            st = shear_state(m, np.array([dem["phi"][j]]), float(dem["e"][j]))
            for k in errs[n]:
                errs[n][k].append(float(st[k][0] / dem[k][j] - 1.0))
    for j in range(dem["phi"].size):
        rows.append([f"φ={dem['phi'][j]:g}, e={dem['e'][j]:g} ({dem['source'][j]})", float(dem["eta_star"][j]), float(dem["p_over_nT"][j])]
                    + [100 * errs[n][k][j] for n in names for k in ("eta_star", "p_over_nT")])
    ctx.table("Uniform shear: model/DEM − 1 (%) of η* and p/(nT)",
              ["state", "DEM η*", "DEM p/(nT)", *[f"{get_model(n).label} {q}" for n in names for q in ("η*", "p/(nT)")]], rows,
              note="Navier–Stokes closed forms at the DEM's (φ, e); the DEM's a* = γ̇/ν0 ≈ 0.2–0.3 is beyond Navier–Stokes order. "
                   "No parameter of the paper's models was fitted to these data.")
    ctx.dataset(xr.Dataset(
        {**{f"{k}_dem": (("state",), dem[k], {"long_name": f"DEM {QUANTITIES[k]}", "units": "1"})
            for k in ("T", "eta_star", "p_star", "p_over_nT")},
         **{f"{k}_error": (("model", "state"), np.array([errs[n][k] for n in names]),
                           {"long_name": f"relative error of {QUANTITIES[k]}, model/DEM - 1", "units": "1"})
            for k in ("T", "eta_star", "p_over_nT")}},
        coords={"model": list(names), "phi": (("state",), dem["phi"], {"long_name": "solid fraction", "units": "1"}),
                "e": (("state",), dem["e"], {"long_name": "restitution coefficient", "units": "1"}),
                "source": (("state",), dem["source"].astype(str))},
        attrs=run_metadata(None, quantity="relative error model/DEM - 1", sources=sorted(set(dem["source"].tolist())))), "shear_errors")
    ctx.number("shear_errors", {n: {k: {f"{p:g}@{e:g}": v for p, e, v in zip(dem["phi"], dem["e"], errs[n][k])} for k in errs[n]}
                                for n in names})


def _couette_table(ctx: SectionContext, names: tuple[str, ...]) -> None:
    path = ctx.data_file(COUETTE)
    if path is None:
        return
    ctx.step("Couette cell of the DEM header, every model")
    rows, extra = compare_with_dem(path, list(names), n_cells=ctx.settings.couette_cells)
    c = extra["case"]
    table, nums = [], {}
    for n, r in zip(names, rows):
        table.append([r["model"], r["specularity"], r["tau_wall"], r["tau_wall_dem"], 100 * r["tau_error"], r["p"], r["p_dem"],
                      100 * r["p_error"], r["max_phi"], "yes" if r["valid"] else ("no" + (f": {r['message']}" if r["message"] else ""))])
        nums[n] = {"tau_error": r["tau_error"], "p_error": r["p_error"], "valid": bool(r["valid"])}
    ctx.table(f"Couette wall shear stress and pressure against the DEM ({COUETTE}: e = {c.e:g}, mean φ = {c.mean_phi:g}, "
              f"gap {c.gap:g} d, U = {c.wall_speed:g})",
              ["model", "specularity φ'", "τ_w", "τ_w DEM", "τ error %", "p", "p DEM", "p error %", "max φ", "valid"], table,
              note=f"Johnson–Jackson walls, e_w = e, specularity fitted per model to the DEM slip at |y| = {extra['dem'].slip_y:g} d "
                   f"(one number); wall stresses are predictions. {ctx.settings.couette_cells} cells.", with_figure=False)
    ctx.dataset(xr.Dataset(
        {k: (("model",), np.array([float(r[k]) for r in rows]), {"long_name": WALL_NAMES[k], "units": "1"})
         for k in ("specularity", "tau_wall", "tau_wall_dem", "p", "p_dem", "max_phi")}
        | {"valid": (("model",), np.array([int(bool(r["valid"])) for r in rows]),
                     {"long_name": "physically valid profile (1) or not (0)", "units": "1"})},
        coords={"model": list(names)},
        attrs=run_metadata(None, source=COUETTE, case=vars(c), cells=ctx.settings.couette_cells)), "couette_wall_stresses")
    ctx.number("couette_wall", nums)


#: Long names of the Couette wall quantities (DEM units d = m = 1, so stresses are in m U²/d³ of the DEM).
WALL_NAMES = {
    "specularity": "specularity coefficient fitted to the DEM slip",
    "tau_wall": "wall shear stress (DEM units d = m = 1)",
    "tau_wall_dem": "DEM wall shear stress (d = m = 1)",
    "p": "wall normal stress (DEM units d = m = 1)",
    "p_dem": "DEM wall normal stress p_yy (d = m = 1)",
    "max_phi": "largest solid fraction of the profile",
}


def run(ctx: SectionContext) -> None:
    names = section_models(ctx.settings)
    ctx.paragraph(
        "The dense regime (φ ≳ 0.5) is where the paper's models part from each other and from the particle data. Uniform shear "
        "isolates the closures (no walls); the Couette cell adds walls and a dense core (φ ≈ 0.58). Models: "
        + ", ".join(get_model(n).label or n for n in names) + ("." if "dense" in names else
                                                             " (no model named 'dense' is registered in this build).")
    )
    ds = shear_curves(names, ctx.settings.dense_points)
    dem = dem_points(ctx)
    plot_shear_curves(ds, dem, ctx.figure_path("uniform_shear_dense"))
    ctx.add_figure("uniform_shear_dense", "Uniform shear against φ: T, η*, p* and p/(nT) of the models (solid e = 0.9, dashed e = 0.7)"
                   + (f" with the frictionless DEM ({UNIFORM_SHEAR}, μ = 0 row of {FRICTION})." if dem is not None else "."), ds)
    if dem is not None:
        _shear_table(ctx, names, dem)
    _couette_table(ctx, names)


def discuss(nb: dict[str, Any]) -> list[str]:
    out = []
    se = nb.get("shear_errors")
    if se:
        states = list(next(iter(se.values()))["eta_star"])
        for st in states:
            phi = float(st.split("@")[0])
            if phi < 0.45:
                continue
            for k, what in (("eta_star", "η*"), ("p_over_nT", "p/(nT)")):
                vals = {n: abs(se[n][k][st]) for n in se if math.isfinite(se[n][k][st])}
                if vals:
                    out.append(f"Dense uniform shear (φ, e = {st.replace('@', ', ')}): {what} errors "
                               + ", ".join(f"{get_model(n).label} {100 * se[n][k][st]:+.0f} %" for n in vals)
                               + f"; closest: {join_labels(closest(vals))}.")
    cw = nb.get("couette_wall")
    if cw:
        for k, what in (("tau_error", "wall shear stress"), ("p_error", "wall pressure")):
            vals = {n: abs(v[k]) for n, v in cw.items() if math.isfinite(v[k])}
            if vals:
                out.append(f"Couette {what} against the DEM: " + ", ".join(f"{get_model(n).label} {100 * cw[n][k]:+.0f} %" for n in vals)
                           + f"; closest: {join_labels(closest(vals))}.")
    return out


SECTION = register_section(Section(
    "dense", "5. Dense regime: uniform shear and Couette wall stresses", run, inputs, order=50,
    data_files=(UNIFORM_SHEAR, FRICTION, COUETTE), modules=("ktgf.shear", "ktgf.couette", "ktgf.data", "ktgf.plotting"),
    discuss=discuss,
))
