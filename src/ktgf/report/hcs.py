"""Section 2: the homogeneous cooling state — Haff's law, DEM cooling rates, dispersion relations, stability map.

Units of the Haff and DEM parts follow the DEM data (d = m = 1, θ0 = 1), in which the cooling
rate A = ζ0/√θ = (96/5)(φ/√π) ζ0* (model.md §1).  The stability map uses the closed-form
critical wavenumbers of model.md §8 (vectorised over φ and e); the dispersion relations are the
eigenvalues of the full longitudinal matrix, and the section reports how closely the last
unstable wavenumber found from them matches the closed form.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..closures.models import get_model
from ..hcs.critical import critical_wavenumbers_eig
from ..hcs.dispersion import dispersion_relation
from ..hcs.haff import cooling_rate, haff_history
from ..hcs.stability import critical_box_size, critical_wavenumbers
from ..hcs.stability_map import stability_map
from ..io import run_metadata
from ..plotting.hcs import plot_haff, plot_stability_map
from ..data import HCS_COOLING, read_cooling
from .framework import Section, SectionContext, closest, join_labels, model_inputs, register_section
from ..plotting.hcs import plot_cooling_errors, plot_dispersion_comparison
from .overlap import overlap_sentence
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
def reduced_haff(ds: xr.Dataset) -> xr.Dataset:
    """A :func:`ktgf.hcs.haff_history` run at d = 1, θ0 = 1, relabelled in the reduced units it is in.

    With d = 1 and θ0 = 1 every number is already reduced (time in d/√θ0, θ in θ0): only the
    ``units`` attributes (``s`` and ``m2 s-2`` for SI runs) change, to ``1`` with a long name saying so.
    """
    ds = ds.copy()
    ds["t"].attrs = {"long_name": "time t sqrt(theta0)/d", "units": "1"}
    for v in ("theta_haff", "theta_numeric"):
        ds[v].attrs = {"long_name": ds[v].attrs.get("long_name", v) + ", theta/theta0", "units": "1"}
    ds["zeta0"].attrs = {"long_name": "cooling rate at theta0, zeta0 d/sqrt(theta0)", "units": "1"}
    ds["t0"].attrs = {"long_name": "Haff time 2/zeta0(theta0) in units of d/sqrt(theta0)", "units": "1"}
    return ds


def cooling_comparison(names: tuple[str, ...], dem: dict[str, np.ndarray]) -> xr.Dataset:
    """Each model's cooling rate A = ζ0/√θ at the DEM states, and its relative error against both DEM fits."""
    a = np.array([np.asarray(cooling_rate(m, dem["phi"], dem["e"], 1.0, d=1.0), dtype=float) for m in names])
    return xr.Dataset(
        {
            "A_model": (("model", "state"), a, {"long_name": "cooling rate zeta0/sqrt(theta) in DEM units d = m = 1", "units": "1"}),
            "A_early": (("state",), dem["A_early"], {"long_name": "DEM cooling rate, fit T0 -> T0/2, in DEM units", "units": "1"}),
            "A_main": (("state",), dem["A_main"], {"long_name": "DEM cooling rate, fit T0 -> T0/4, in DEM units", "units": "1"}),
            "error_early": (("model", "state"), a / dem["A_early"] - 1.0, {"long_name": "A_model/A_early - 1", "units": "1"}),
            "error_main": (("model", "state"), a / dem["A_main"] - 1.0, {"long_name": "A_model/A_main - 1", "units": "1"}),
            "dem_rel_sem": (("state",), dem["A_main_sem"] / dem["A_main"], {"long_name": "relative standard error of A_main", "units": "1"}),
        },
        coords={"model": list(names), "label": ("model", _labels(names)),
                "phi": ("state", dem["phi"], {"long_name": "solid fraction", "units": "1"}),
                "e": ("state", dem["e"], {"long_name": "normal restitution coefficient", "units": "1"})},
        attrs=run_metadata(None, source=HCS_COOLING, models=list(names), comparison="A_model/A_DEM - 1, no fitted parameter"),
    )


# -- dispersion relations and the RET/Proposed comparison --------------------------------------
def dispersion(names: tuple[str, ...], phi: float, e: float, n: int) -> xr.Dataset:
    """s⊥(k*) and the three longitudinal growth rates of each model at one state, with k⊥*, k∥*
    from the closed form and from the eigenvalues (:func:`ktgf.hcs.critical_wavenumbers_eig`)."""
    models = [get_model(m) for m in names]
    red = [m.reduced(phi, e) for m in models]
    crit = [critical_wavenumbers(r) for r in red]
    kmax = 1.6 * max(float(max(kp, kl)) for kp, kl in crit)
    k = np.linspace(0.0, kmax, n)
    rel = [dispersion_relation(r, k) for r in red]
    eig = [critical_wavenumbers_eig(r) for r in red]
    return xr.Dataset(
        {
            "s_perp": (("model", "kstar"), np.array([d.transverse for d in rel]), {"long_name": "transverse growth rate / nu0", "units": "1"}),
            "s_par_real": (("model", "kstar", "branch"), np.array([d.longitudinal.real for d in rel]),
                           {"long_name": "Re longitudinal growth rates / nu0", "units": "1"}),
            "s_par_imag": (("model", "kstar", "branch"), np.array([d.longitudinal.imag for d in rel]),
                           {"long_name": "Im longitudinal growth rates / nu0", "units": "1"}),
            "k_perp": (("model",), [float(c[0]) for c in crit], {"long_name": "closed-form critical k* (vortex)", "units": "1"}),
            "k_par": (("model",), [float(c[1]) for c in crit], {"long_name": "closed-form critical k* (cluster)", "units": "1"}),
            "k_perp_eigen": (("model",), [float(c[0]) for c in eig], {"long_name": "critical k* from the eigenvalues (vortex)", "units": "1"}),
            "k_par_eigen": (("model",), [float(c[1]) for c in eig], {"long_name": "critical k* from the eigenvalues (cluster)", "units": "1"}),
        },
        coords={"model": list(names), "label": ("model", _labels(names)),
                "kstar": ("kstar", k, {"long_name": "reduced wavenumber k ell", "units": "1"}), "branch": [0, 1, 2],
                "phi": ((), phi, {"long_name": "solid fraction", "units": "1"}),
                "e": ((), e, {"long_name": "normal restitution coefficient", "units": "1"})},
        attrs=run_metadata(None, models=list(names), phi=phi, e=e, points=n, equation="model.md section 8"),
    )


def compare_pair(ds: xr.Dataset, a: str, b: str) -> dict[str, Any]:
    """How model ``b``'s critical sizes differ from model ``a``'s over the map (for the RET/Proposed sentence)."""
    out: dict[str, Any] = {}
    ds = ds.transpose("model", "e", "phi")
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
    # "Predicts the instabilities": finite, positive critical sizes, vortex threshold below the cluster one.
    for name in (a, b):
        lp, ll = ds.L_perp.sel(model=name).values, ds.L_par.sel(model=name).values
        valid = np.isfinite(ds.k_perp.sel(model=name).values)
        out[f"{name}_all_finite"] = bool(np.all(np.isfinite(lp[valid]) & np.isfinite(ll[valid]) & (lp[valid] > 0) & (ll[valid] > 0)))
        out[f"{name}_vortex_first"] = bool(np.all(lp[valid] < ll[valid]))
        out[f"{name}_phi_top"] = float(phi[valid.any(axis=0)].max())
    return out


def run(ctx: SectionContext) -> None:
    s = ctx.settings
    names = s.models
    path = ctx.data_file(HCS_COOLING)
    dem = read_cooling(path) if path is not None else None

    ctx.paragraph(
        "A uniform granular gas at rest cools by inelastic collisions as θ(t) = θ0/(1 + ζ0(θ0)t/2)² (Haff 1983). "
        "The models differ only through their cooling rate ζ0* (Enskog/Lun: no Sonine correction; RET: with it) and χ."
    )
    for phi, e in s.haff_states:
        ctx.step(f"Haff's law at φ = {phi:g}, e = {e:g}")
        ds = reduced_haff(haff_history(names, phi, e, 1.0, d=1.0))
        name = f"haff_phi{phi:g}_e{e:g}"
        plot_haff(ds, ctx.figure_path(name))
        t0 = {n: float(ds.t0.sel(model=n)) for n in names}
        ctx.add_figure(name, f"Haff's law (lines) and the integrated cooling equation (markers) at φ = {phi:g}, e = {e:g}, "
                       "in units d = 1, θ0 = 1 (time in units of d/√θ0)." + overlap_sentence(t0, "Haff time t0"), ds)

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
    plot_dispersion_comparison(disp, ctx.figure_path("dispersion"))
    ctx.add_figure("dispersion", f"Growth rates of perturbations of the HCS against k* = kℓ at φ = {s.dispersion_phi:g}, "
                   f"e = {s.dispersion_e:g} (docs/model.md §8): modes with positive rate grow.", disp)
    check = np.abs(np.concatenate([disp.k_par_eigen.values / disp.k_par.values, disp.k_perp_eigen.values / disp.k_perp.values]) - 1.0)
    ctx.number("eigen_vs_closed_form_max_rel", float(np.nanmax(check)))
    ctx.table(f"Critical wavenumbers at φ = {s.dispersion_phi:g}, e = {s.dispersion_e:g}",
              ["model", "k⊥* (closed form)", "k⊥* (eigenvalues)", "k∥* (closed form)", "k∥* (eigenvalues)", "L⊥/d", "L∥/d"],
              [[str(disp.label[i].values), float(disp.k_perp[i]), float(disp.k_perp_eigen[i]), float(disp.k_par[i]), float(disp.k_par_eigen[i]),
                float(critical_box_size(s.dispersion_phi, float(disp.k_perp[i]))),
                float(critical_box_size(s.dispersion_phi, float(disp.k_par[i])))] for i in range(len(names))],
              note="Eigenvalues: last wavenumber at which the mode's growth rate is positive (scan + root refinement, ktgf.hcs.critical).")

    ctx.step("stability map")
    smap = stability_map(names, np.linspace(*s.stability_phi, s.stability_points), np.asarray(s.stability_e))
    plot_stability_map(smap, s.stability_e, ctx.figure_path("stability_map"))
    ctx.add_figure("stability_map", "Critical sizes of a periodic cube against φ for each e and model (docs/model.md §8, closed form). "
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
        out.append(f"The closed-form thresholds k⊥*, k∥* agree with the last unstable wavenumbers of the full eigenvalue problem "
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
    data_files=(HCS_COOLING,), modules=("ktgf.plotting", "ktgf.data"), discuss=discuss,
))
