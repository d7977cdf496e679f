"""Section 2: the homogeneous cooling state — Haff's law, DEM cooling rates, dispersion relations, stability map.

Units of the Haff and DEM parts follow the DEM data (d = m = 1, θ0 = 1), in which the cooling
rate A = ζ0/√θ = (96/5)(φ/√π) ζ0* (model.md §1).  The stability map uses the closed-form
critical wavenumbers of model.md §8 (vectorised over φ and e); the dispersion relations are the
eigenvalues of the full longitudinal matrix, and the section reports how closely the last
unstable wavenumber found from them matches the closed form.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr
from scipy.optimize import brentq

from ..closures.models import get_model
from ..hcs.haff import cooling_rate, haff_temperature
from ..hcs.stability import (
    critical_box_size,
    critical_wavenumbers,
    longitudinal_growth_rates,
    transverse_growth_rate,
)
from ..io import run_metadata
from .dem import HCS_COOLING, read_table
from .framework import Section, SectionContext, closest, join_labels, model_inputs, register_section
from .hcs_plots import plot_cooling_errors, plot_dispersion, plot_haff, plot_stability_map
from .settings import ReportSettings

#: Solid fractions of the critical-size table.
TABLE_PHI = (0.1, 0.3, 0.5)
#: Relative difference below which two critical sizes count as the same (well under DEM/MD resolution).
SAME = 0.01


def inputs(s: ReportSettings) -> dict[str, Any]:
    return {
        "models": model_inputs(s.models), "stability_e": s.stability_e, "stability_points": s.stability_points,
        "stability_phi": s.stability_phi, "dispersion": [s.dispersion_phi, s.dispersion_e, s.dispersion_points],
        "haff_states": s.haff_states, "table_phi": TABLE_PHI,
    }


def _labels(names: tuple[str, ...]) -> list[str]:
    return [get_model(n).label or n for n in names]


# -- Haff's law and DEM cooling rates ---------------------------------------------------------
def _dem_row(dem: dict[str, np.ndarray] | None, phi: float, e: float) -> int | None:
    if dem is None:
        return None
    hit = np.flatnonzero(np.isclose(dem["phi"], phi) & np.isclose(dem["e"], e))
    return int(hit[0]) if hit.size else None


def haff_curves(names: tuple[str, ...], states: tuple[tuple[float, float], ...], dem: dict[str, np.ndarray] | None,
                n: int = 200) -> xr.Dataset:
    """θ(t)/θ0 for each model and state (d = m = θ0 = 1), with the DEM's fitted Haff curve where available."""
    ns = len(states)
    time = np.empty((ns, n))
    theta = np.empty((len(names), ns, n))
    theta_dem = np.full((ns, n), np.nan)
    for j, (phi, e) in enumerate(states):
        rates = [float(cooling_rate(m, phi, e, 1.0, d=1.0)) for m in names]
        time[j] = np.linspace(0.0, 8.0 / min(rates), n)  # down to θ/θ0 ≈ 1/25 for the slowest model
        for i, z in enumerate(rates):
            theta[i, j] = haff_temperature(time[j], 1.0, 2.0 / z)
        row = _dem_row(dem, phi, e)
        if row is not None:
            theta_dem[j] = haff_temperature(time[j], 1.0, 2.0 / dem["A_early"][row])
    return xr.Dataset(
        {
            "theta": (("model", "state", "t"), theta, {"long_name": "theta/theta0", "units": "1"}),
            "theta_dem": (("state", "t"), theta_dem, {"long_name": "DEM Haff fit over T0 -> T0/2 (A_early)", "source": HCS_COOLING}),
            "time": (("state", "t"), time, {"long_name": "t sqrt(theta0)/d", "units": "1"}),
        },
        coords={"model": list(names), "label": ("model", _labels(names)),
                "phi": ("state", [s[0] for s in states]), "e": ("state", [s[1] for s in states])},
        attrs=run_metadata(None, models=list(names), states=[list(s) for s in states], units="d = m = theta0 = 1"),
    )


def cooling_comparison(names: tuple[str, ...], dem: dict[str, np.ndarray]) -> xr.Dataset:
    """Each model's cooling rate A = ζ0/√θ at the DEM states, and its relative error against both DEM fits."""
    a = np.array([np.asarray(cooling_rate(m, dem["phi"], dem["e"], 1.0, d=1.0), dtype=float) for m in names])
    return xr.Dataset(
        {
            "A_model": (("model", "state"), a, {"long_name": "zeta0/sqrt(theta), d = m = 1"}),
            "A_early": (("state",), dem["A_early"], {"long_name": "DEM fit T0 -> T0/2"}),
            "A_main": (("state",), dem["A_main"], {"long_name": "DEM fit T0 -> T0/4"}),
            "error_early": (("model", "state"), a / dem["A_early"] - 1.0),
            "error_main": (("model", "state"), a / dem["A_main"] - 1.0),
            "dem_rel_sem": (("state",), dem["A_main_sem"] / dem["A_main"]),
        },
        coords={"model": list(names), "label": ("model", _labels(names)), "phi": ("state", dem["phi"]), "e": ("state", dem["e"])},
        attrs=run_metadata(None, source=HCS_COOLING, models=list(names), comparison="A_model/A_DEM - 1, no fitted parameter"),
    )


# -- dispersion relations and stability map ----------------------------------------------------
def _last_unstable_k(model: Any, phi: float, e: float, kmax: float, n: int) -> float:
    """Largest k* at which a longitudinal mode grows, from the eigenvalues (grid scan, then root refinement)."""
    r = model.reduced(phi, e)

    def lead(k: float) -> float:
        return float(np.max(longitudinal_growth_rates(r, np.asarray(k)).real))

    k = np.linspace(kmax / n, kmax, n)
    s = np.max(longitudinal_growth_rates(r, k).real, axis=-1)
    pos = np.flatnonzero(s > 0)
    if pos.size == 0:
        return 0.0
    i = pos[-1]
    if i == k.size - 1:
        return math.inf
    return brentq(lead, k[i], k[i + 1], xtol=1e-14, rtol=1e-12)


def dispersion(names: tuple[str, ...], phi: float, e: float, n: int) -> xr.Dataset:
    """s⊥(k*) and the three longitudinal growth rates for each model at one state, with the closed-form k⊥*, k∥*."""
    models = [get_model(m) for m in names]
    crit = [critical_wavenumbers(m.reduced(phi, e)) for m in models]
    kmax = 1.6 * max(float(max(kp, kl)) for kp, kl in crit)
    k = np.linspace(0.0, kmax, n)
    s_perp = np.array([np.asarray(transverse_growth_rate(m.reduced(phi, e), k), dtype=float) for m in models])
    s_par = np.array([np.asarray(longitudinal_growth_rates(m.reduced(phi, e), k)) for m in models])
    k_scan = np.array([_last_unstable_k(m, phi, e, kmax, n) for m in models])
    return xr.Dataset(
        {
            "s_perp": (("model", "kstar"), s_perp, {"long_name": "transverse growth rate / nu0"}),
            "s_par_real": (("model", "kstar", "branch"), s_par.real, {"long_name": "Re longitudinal growth rates / nu0"}),
            "s_par_imag": (("model", "kstar", "branch"), s_par.imag, {"long_name": "Im longitudinal growth rates / nu0"}),
            "k_perp": (("model",), [float(c[0]) for c in crit], {"long_name": "closed-form critical k* (vortex)"}),
            "k_par": (("model",), [float(c[1]) for c in crit], {"long_name": "closed-form critical k* (cluster)"}),
            "k_par_eigen": (("model",), k_scan, {"long_name": "last unstable k* of the eigenvalues of -M"}),
        },
        coords={"model": list(names), "label": ("model", _labels(names)), "kstar": k, "branch": [0, 1, 2],
                "phi": phi, "e": e},
        attrs=run_metadata(None, models=list(names), phi=phi, e=e, points=n, equation="model.md section 8"),
    )


def stability_map(names: tuple[str, ...], es: tuple[float, ...], phi_range: tuple[float, float], n: int) -> xr.Dataset:
    """L⊥/d and L∥/d on a (model, e, φ) grid; NaN where φ is at or above a model's packing limit."""
    phi = np.linspace(phi_range[0], phi_range[1], n)
    shape = (len(names), len(es), n)
    out = {k: np.full(shape, np.nan) for k in ("L_perp", "L_par", "k_perp", "k_par")}
    for i, name in enumerate(names):
        m = get_model(name)
        ok = phi < 0.995 * m.phi_max
        ph, ee = np.meshgrid(phi[ok], np.asarray(es, dtype=float), indexing="xy")
        kp, kl = critical_wavenumbers(m.reduced(ph, ee))
        out["k_perp"][i][:, ok], out["k_par"][i][:, ok] = kp, kl
        out["L_perp"][i][:, ok], out["L_par"][i][:, ok] = critical_box_size(ph, kp), critical_box_size(ph, kl)
    attrs = {"L_perp": "critical side L/d of a periodic cube, vortex (shear) mode",
             "L_par": "critical side L/d of a periodic cube, cluster (heat) mode",
             "k_perp": "critical k* = k l, vortex mode", "k_par": "critical k* = k l, cluster mode"}
    return xr.Dataset(
        {k: (("model", "e", "phi"), v, {"long_name": attrs[k]}) for k, v in out.items()},
        coords={"model": list(names), "label": ("model", _labels(names)), "e": list(es), "phi": phi},
        attrs=run_metadata(None, models=list(names), e=list(es), phi_range=list(phi_range), points=n,
                           equation="model.md section 8, closed form"),
    )


def compare_pair(ds: xr.Dataset, a: str, b: str) -> dict[str, Any]:
    """How model ``b``'s critical sizes differ from model ``a``'s over the map (for the RET/Proposed sentence)."""
    out: dict[str, Any] = {}
    both = np.isfinite(ds.L_perp.sel(model=a)) & np.isfinite(ds.L_perp.sel(model=b))
    phi = ds.phi.values
    for var in ("L_perp", "L_par"):
        la, lb = ds[var].sel(model=a).values, ds[var].sel(model=b).values
        rel = np.where(both.values, lb / la - 1.0, np.nan)
        big = np.abs(rel) > SAME
        first = [float(phi[np.argmax(row)]) if row.any() else None for row in big]
        k = np.unravel_index(np.nanargmax(np.abs(rel)), rel.shape)
        out[var] = {
            "max_rel_diff": float(np.nanmax(np.abs(rel))),
            "at_phi": float(phi[k[1]]), "at_e": float(ds.e.values[k[0]]), "signed": float(rel[k]),
            "first_phi_differing": min((f for f in first if f is not None), default=None),
        }
    # "Predicts the instabilities": finite critical sizes, vortex threshold below the cluster one.
    for name in (a, b):
        lp, ll = ds.L_perp.sel(model=name).values, ds.L_par.sel(model=name).values
        valid = np.isfinite(ds.k_perp.sel(model=name).values)
        out[f"{name}_all_finite"] = bool(np.all(np.isfinite(lp[valid]) & np.isfinite(ll[valid])))
        out[f"{name}_vortex_first"] = bool(np.all(lp[valid] < ll[valid]))
        out[f"{name}_phi_top"] = float(phi[valid.any(axis=0)].max())
    return out


def run(ctx: SectionContext) -> None:
    s = ctx.settings
    names = s.models
    path = ctx.data_file(HCS_COOLING)
    dem = read_table(path) if path is not None else None

    ctx.paragraph(
        "A uniform granular gas at rest cools by inelastic collisions as θ(t) = θ0/(1 + ζ0(θ0)t/2)² (Haff 1983). "
        "The models differ only through their cooling rate ζ0* (Enskog/Lun: no Sonine correction; RET: with it) and χ."
    )
    ctx.step("Haff's law")
    ds = haff_curves(names, s.haff_states, dem)
    plot_haff(ds, ctx.figure_path("haff"))
    ctx.add_figure("haff", "Haff's law for each model (units d = m = θ0 = 1)"
                   + (", with the DEM's fitted Haff curve (dem_hcs_cooling.csv, early window) where the state was simulated." if dem is not None else "."), ds)

    if dem is not None:
        cmp = cooling_comparison(names, dem)
        plot_cooling_errors(cmp, ctx.figure_path("cooling_rate_vs_dem"))
        ctx.add_figure("cooling_rate_vs_dem", f"Relative error of each model's cooling rate against the DEM ({HCS_COOLING}, "
                       "fit over T0 → T0/2, the cleanest test of an instantaneous ζ0). Grey: DEM uncertainty.", cmp)
        labels = _labels(names)
        rows = []
        for i, n in enumerate(names):
            ee, em = cmp.error_early.values[i], cmp.error_main.values[i]
            rows.append([labels[i], 100 * float(np.mean(np.abs(ee))), 100 * float(np.max(np.abs(ee))),
                         100 * float(np.mean(np.abs(em))), 100 * float(np.max(np.abs(em)))])
        ctx.table(f"Cooling-rate error against DEM ({HCS_COOLING}), {cmp.sizes['state']} states",
                  ["model", "mean |err| % (T0→T0/2)", "max |err| % (T0→T0/2)", "mean |err| % (T0→T0/4)", "max |err| % (T0→T0/4)"],
                  rows, note="Error = A_model/A_DEM − 1. Nothing was fitted to these data. DEM uncertainty ±0.5–1 %.")
        best = [closest({n: abs(float(cmp.error_early[i, j])) for i, n in enumerate(names)}) for j in range(cmp.sizes["state"])]
        state_rows = [[f"φ={float(cmp.phi[j]):g}, e={float(cmp.e[j]):g}", *(100 * float(cmp.error_early[i, j]) for i in range(len(names))),
                       join_labels(best[j])] for j in range(cmp.sizes["state"])]
        ctx.table("Cooling-rate error per state (T0 → T0/2), %", ["state", *labels, "closest"], state_rows)
        ctx.number("cooling_mean_abs_error", {n: float(np.mean(np.abs(cmp.error_early.values[i]))) for i, n in enumerate(names)})
        ctx.number("cooling_best", {f"{float(cmp.phi[j]):g},{float(cmp.e[j]):g}": best[j] for j in range(len(best))})
        ctx.number("cooling_signed_mean", {n: float(np.mean(cmp.error_early.values[i])) for i, n in enumerate(names)})

    ctx.step("dispersion relations")
    disp = dispersion(names, s.dispersion_phi, s.dispersion_e, s.dispersion_points)
    plot_dispersion(disp, ctx.figure_path("dispersion"))
    ctx.add_figure("dispersion", f"Growth rates of perturbations of the HCS against k* = kℓ at φ = {s.dispersion_phi:g}, "
                   f"e = {s.dispersion_e:g} (model.md §8): modes with positive rate grow.", disp)
    check = np.abs(disp.k_par_eigen.values / disp.k_par.values - 1.0)
    ctx.number("eigen_vs_closed_form_max_rel", float(np.nanmax(check)))
    ctx.table(f"Critical wavenumbers at φ = {s.dispersion_phi:g}, e = {s.dispersion_e:g}",
              ["model", "k⊥* (closed form)", "k∥* (closed form)", "k∥* (eigenvalues)", "L⊥/d", "L∥/d"],
              [[str(disp.label[i].values), float(disp.k_perp[i]), float(disp.k_par[i]), float(disp.k_par_eigen[i]),
                float(critical_box_size(s.dispersion_phi, float(disp.k_perp[i]))),
                float(critical_box_size(s.dispersion_phi, float(disp.k_par[i])))] for i in range(len(names))],
              note="k∥* (eigenvalues): last wavenumber at which an eigenvalue of −M has a positive real part (scan + root refinement).")

    ctx.step("stability map")
    smap = stability_map(names, s.stability_e, s.stability_phi, s.stability_points)
    plot_stability_map(smap, ctx.figure_path("stability_map"))
    ctx.add_figure("stability_map", "Critical sizes of a periodic cube against φ for each e and model (model.md §8, closed form). "
                   "A cube smaller than L⊥ stays homogeneous, between L⊥ and L∥ it grows vortices, above L∥ also clusters.", smap)
    rows = []
    for i, n in enumerate(names):
        for phi in TABLE_PHI:
            if phi >= 0.995 * get_model(n).phi_max:
                continue
            vals = []
            for e in s.stability_e:
                r = get_model(n).reduced(phi, e)
                kp, kl = critical_wavenumbers(r)
                vals += [float(critical_box_size(phi, kp)), float(critical_box_size(phi, kl))]
            rows.append([f"{get_model(n).label}, φ={phi:g}", *vals])
    ctx.table("Critical sizes L⊥/d and L∥/d", ["model, φ", *[f"{q} e={e:g}" for e in s.stability_e for q in ("L⊥/d", "L∥/d")]], rows)
    if "ret" in names and "proposed" in names:
        ctx.number("ret_vs_proposed", compare_pair(smap, "ret", "proposed"))
    if "enskog" in names and "visc-div" in names:
        ctx.number("enskog_vs_viscdiv", compare_pair(smap, "enskog", "visc-div"))
    ctx.number("phi_range", list(s.stability_phi))
    ctx.number("stability_e", list(s.stability_e))


def ret_proposed_sentence(c: dict[str, Any], phi_range: list[float], es: list[float]) -> str:
    """The paper's RET/Proposed comparison, stated from the numbers of :func:`compare_pair`."""
    keeps = c["proposed_all_finite"] and c["proposed_vortex_first"]
    ret_ok = c["ret_all_finite"] and c["ret_vortex_first"]
    span = f"φ = {phi_range[0]:g}–{min(phi_range[1], c['proposed_phi_top']):.2f} and e = {', '.join(f'{e:g}' for e in es)}"
    if keeps and ret_ok:
        head = (f"Like RET, the Proposed model predicts both instabilities of the cooling gas at every state of the map ({span}): "
                "finite critical sizes, with vortices (L⊥) setting in before clusters (L∥ > L⊥) — it keeps the ability to predict the instabilities.")
    elif ret_ok:
        head = f"Unlike RET, the Proposed model does not predict both instabilities everywhere in {span} (finite L⊥ < L∥ fails somewhere)."
    else:
        head = f"RET itself does not predict finite L⊥ < L∥ everywhere in {span}; the comparison below is quantitative only."
    parts = []
    for var, name in (("L_perp", "L⊥"), ("L_par", "L∥")):
        d = c[var]
        first = d["first_phi_differing"]
        same = f"identical to RET's (within {100 * SAME:g} %) up to φ ≈ {first:.2f}" if first is not None else f"within {100 * SAME:g} % of RET's everywhere"
        parts.append(f"its {name} is {same}, and differs by at most {100 * d['max_rel_diff']:.0f} % "
                     f"({'larger' if d['signed'] > 0 else 'smaller'} at φ = {d['at_phi']:.2f}, e = {d['at_e']:g})")
    return head + " Quantitatively, " + "; ".join(parts) + "."


def discuss(nb: dict[str, Any]) -> list[str]:
    out = []
    if "ret_vs_proposed" in nb:
        out.append(ret_proposed_sentence(nb["ret_vs_proposed"], nb["phi_range"], nb["stability_e"]))
    if "enskog_vs_viscdiv" in nb:
        d = nb["enskog_vs_viscdiv"]["L_perp"]
        out.append(f"Visc.div.'s faster viscosity divergence moves its vortex threshold L⊥ by up to {100 * d['max_rel_diff']:.0f} % "
                   f"from Enskog's (at φ = {d['at_phi']:.2f}), since L⊥ ∝ √(η*/ζ0*).")
    if "eigen_vs_closed_form_max_rel" in nb:
        out.append(f"The closed-form cluster threshold k∥* agrees with the last unstable wavenumber of the full eigenvalue problem "
                   f"to {nb['eigen_vs_closed_form_max_rel']:.1e} (relative) for every model.")
    ce = nb.get("cooling_mean_abs_error")
    if ce:
        best = closest(ce)
        signed = nb.get("cooling_signed_mean", {})
        wins: dict[str, list[str]] = {}
        for state, ms in nb.get("cooling_best", {}).items():
            wins.setdefault(join_labels(ms), []).append(state)
        out.append(
            "Cooling rate against DEM (early window): mean |error| "
            + ", ".join(f"{get_model(n).label} {100 * v:.1f} %" for n, v in ce.items())
            + f". {join_labels(best)} {'is' if len(best) == 1 else 'are'} closest overall; per state the closest is "
            + "; ".join(f"{who} at (φ, e) = " + ", ".join(f"({s})" for s in st) for who, st in wins.items())
            + ". "
            + ("All models cool faster than the DEM on average (" + ", ".join(f"{get_model(n).label} {100 * v:+.1f} %" for n, v in signed.items())
               + "), as the data's README expects from velocity correlations that Enskog-type theories neglect." if signed and all(v > 0 for v in signed.values()) else "")
        )
    return out


SECTION = register_section(Section(
    "hcs", "2. Homogeneous cooling state: Haff's law and instabilities", run, inputs, order=20,
    data_files=(HCS_COOLING,), modules=("ktgf.report.hcs_plots", "ktgf.report.dem"), discuss=discuss,
))
