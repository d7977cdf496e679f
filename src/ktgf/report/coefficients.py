"""Section 1: reduced transport coefficients of the models against φ, their RDFs, and DEM checks.

Figure: :func:`ktgf.plotting.coefficients.plot_reduced_coefficients` (p*, η*, κ*, μ*, ζ0*, χ).
Data: the same curves on the same grid.  DEM checks (when the files are present): the
compressibility factor p* = p/(nT) measured in the homogeneous cooling runs
(``dem_hcs_cooling.csv``) and the shear viscosity η/η0 and p* of uniform shear
(``dem_uniform_shear.csv``, Navier–Stokes order although a* = γ̇/ν0 ≈ 0.2–0.3 there).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..closures.models import get_model
from ..hcs.stability import critical_box_size, critical_wavenumbers
from ..io import run_metadata
from ..data import HCS_COOLING, UNIFORM_SHEAR, read_cooling, read_table
from .framework import Section, SectionContext, closest, join_labels, model_inputs, register_section
from .overlap import OVERLAP_RTOL, coincide_below
from .settings import ReportSettings

FIELDS = ("p", "eta", "lambda_b", "kappa", "mu", "zeta0", "zeta_u")
TABLE_PHI = (0.1, 0.3, 0.5)


def inputs(s: ReportSettings) -> dict[str, Any]:
    return {
        "models": model_inputs(s.models), "e": s.coefficient_e, "points": s.coefficient_points,
        "phi_max": s.coefficient_phi_max, "table_phi": TABLE_PHI,
    }


def coefficient_curves(names: tuple[str, ...], e: float, phi_max: float, n: int) -> xr.Dataset:
    """Reduced coefficients and χ on the grid of ``plot_reduced_coefficients`` (per model: 1e-3 … min(phi_max, 0.995 φ_max))."""
    models = [get_model(m) for m in names]
    data: dict[str, Any] = {k: np.empty((len(models), n)) for k in (*FIELDS, "chi", "phi")}
    for i, m in enumerate(models):
        phi = np.linspace(1e-3, min(phi_max, 0.995 * m.phi_max), n)
        r = m.reduced(phi, e)
        data["phi"][i] = phi
        data["chi"][i] = m.chi(phi)
        for k in FIELDS:
            data[k][i] = np.broadcast_to(getattr(r, k), phi.shape)
    long = {"p": "p* = p/(rho theta)", "eta": "eta* = eta/eta0", "lambda_b": "lambda_b* = lambda_b/eta0",
            "kappa": "kappa* = kappa/kappa0", "mu": "mu* = phi omega/(theta kappa0)", "zeta0": "zeta0* = zeta0/nu0",
            "zeta_u": "zeta_U", "chi": "radial distribution at contact g0(phi)", "phi": "solid fraction"}
    ds = xr.Dataset(
        {k: (("model", "point"), v, {"long_name": long[k], "units": "1"}) for k, v in data.items() if k != "phi"},
        coords={"model": list(names), "phi": (("model", "point"), data["phi"], {"long_name": long["phi"], "units": "1"})},
        attrs=run_metadata(None, e=e, phi_max=phi_max, points=n, models=list(names), figure="reduced coefficients"),
    )
    return ds


#: Quantities of the coefficient figure, as named in the captions.
SHOWN = {"p": "p*", "eta": "η*", "kappa": "κ*", "mu": "μ*", "zeta0": "ζ0*", "chi": "χ"}
#: Quantities checked for a step at φ_f: the figure's, and the critical sizes of the stability map.
STEPPED = {**SHOWN, "L_perp": "L⊥", "L_par": "L∥"}
#: Relative jump across φ_f above which the page reports a step (a continuous junction gives ~1e-8).
STEP_MIN = 1e-4


def overlap_note(ds: xr.Dataset) -> str:
    """Which models' curves lie on top of each other in the coefficient figure, measured on its grid.

    For every pair of models and every quantity shown: coinciding everywhere, or up to which φ
    (within :data:`~ktgf.report.overlap.OVERLAP_RTOL`).
    """
    names = [str(n) for n in ds.model.values]
    parts = []
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            pa, pb = ds.phi.sel(model=a).values, ds.phi.sel(model=b).values
            top = min(pa[-1], pb[-1])
            grid = pa[pa <= top]
            whole, upto = [], {}
            for k, sym in SHOWN.items():
                va = ds[k].sel(model=a).values[pa <= top]
                vb = np.interp(grid, pb, ds[k].sel(model=b).values)
                c = coincide_below(grid, va, vb)
                if c is None:
                    continue
                if c >= grid[-1]:
                    whole.append(sym)
                else:
                    upto.setdefault(round(c, 2), []).append(sym)
            if len(whole) == len(SHOWN):
                parts.append(f"{get_model(b).label} lies on {get_model(a).label} everywhere")
            elif len(whole) + sum(map(len, upto.values())) == len(SHOWN):  # every curve, up to some φ
                parts.append(f"{get_model(b).label} lies on {get_model(a).label} in every curve up to φ ≈ {min(upto):.2f}")
            elif whole:
                parts.append(f"{get_model(b).label} lies on {get_model(a).label} in {', '.join(whole)} everywhere")
    if not parts:
        return ""
    return f" Curves hidden under others (within {100 * OVERLAP_RTOL:g} %): " + "; ".join(parts) + "."


def junction_steps(names: tuple[str, ...], e: float) -> dict[str, dict[str, float]]:
    """Relative jump of each shown quantity across each model's freezing point φ_f (models without one are left out)."""
    out: dict[str, dict[str, float]] = {}
    for n in names:
        m = get_model(n)
        phi_f = getattr(m.rdf, "phi_f", None)
        if phi_f is None:
            continue
        lo, hi = phi_f * (1 - 1e-9), phi_f * (1 + 1e-9)
        rl, rh = m.reduced(lo, e), m.reduced(hi, e)
        vals = {k: (float(getattr(rl, k)), float(getattr(rh, k))) for k in SHOWN if k != "chi"}
        vals["chi"] = (float(m.chi(lo)), float(m.chi(hi)))
        for key, j in (("L_perp", 0), ("L_par", 1)):  # the stability map's critical sizes (section 2)
            vals[key] = tuple(float(critical_box_size(x, critical_wavenumbers(r)[j])) for x, r in ((lo, rl), (hi, rh)))
        h = 1e-6 * phi_f  # one-sided slopes of χ on either side of φ_f
        vals["dchi"] = ((float(m.chi(phi_f)) - float(m.chi(phi_f - h))) / h, (float(m.chi(phi_f + h)) - float(m.chi(phi_f))) / h)
        out[n] = {"phi_f": float(phi_f), **{k: (b / a - 1.0) if a != 0 else (0.0 if b == 0 else float("inf")) for k, (a, b) in vals.items()}}
    return out


def step_sentence(steps: dict[str, dict[str, float]]) -> str:
    """Explain a step measured at φ_f, or say that the junction is continuous (nothing is assumed)."""
    stepped, smooth = [], []
    for n, v in steps.items():
        big = {k: x for k, x in v.items() if k in STEPPED and abs(x) > STEP_MIN}
        if not big:
            smooth.append(get_model(n).label)
            continue
        text = (f"{get_model(n).label} at φ_f = {v['phi_f']:g}: " + ", ".join(f"{STEPPED[k]} {100 * x:+.3g} %" for k, x in big.items()))
        if "chi" not in big and abs(v.get("dchi", 0.0)) > STEP_MIN:
            text += (f" while χ itself is continuous; its slope χ' = dχ/dφ jumps by {100 * v['dchi']:+.3g} % there "
                     "(the dense branch of the RDF meets Carnahan–Starling with the same value, not the same slope), "
                     "and the quantities built on χ' inherit the jump (μ* through χ'/χ; L∥ through μ* and C = p* + φ dp*/dφ)")
        stepped.append(text)
    out = " Steps measured across the freezing point: " + "; ".join(stepped) + "." if stepped else ""
    if smooth:
        out += f" {', '.join(smooth)}: every curve is continuous across φ_f (relative jump < {STEP_MIN:g})."
    return out


def _dem_checks(ctx: SectionContext, names: tuple[str, ...]) -> None:
    path = ctx.data_file(HCS_COOLING)
    if path is not None:
        t = read_cooling(path)
        rows, errs = [], {}
        for n in names:
            m = get_model(n)
            pstar = np.asarray(m.reduced(t["phi"], t["e"]).p, dtype=float)
            rel = pstar / t["p_over_nT"] - 1.0
            errs[n] = rel
        for j in range(t["phi"].size):
            rows.append([f"φ={t['phi'][j]:g}, e={t['e'][j]:g}", float(t["p_over_nT"][j])]
                        + [100 * float(errs[n][j]) for n in names])
        rows.append(["mean |error| %", None] + [100 * float(np.mean(np.abs(errs[n]))) for n in names])
        ctx.table(f"Compressibility factor p* against DEM homogeneous cooling ({HCS_COOLING}): relative error %",
                  ["state", "DEM p/(nT)", *[get_model(n).label for n in names]], rows,
                  note="Error = model/DEM − 1 (×100). No parameter was fitted to these data.")
        ctx.dataset(xr.Dataset(
            {"p_dem": (("state",), t["p_over_nT"], {"long_name": "DEM compressibility factor p/(n T)", "units": "1"}),
             "p_model": (("model", "state"), np.array([errs[n] + 1 for n in names]) * t["p_over_nT"],
                         {"long_name": "model compressibility factor p*", "units": "1"})},
            coords={"model": list(names), "phi": (("state",), t["phi"], {"long_name": "solid fraction", "units": "1"}),
                    "e": (("state",), t["e"], {"long_name": "normal restitution coefficient", "units": "1"})},
            attrs=run_metadata(None, source=HCS_COOLING, quantity="p* = p/(n T)")), "pstar_vs_dem_hcs")
        ctx.number("pstar_mean_abs_error", {n: float(np.mean(np.abs(errs[n]))) for n in names})
        dense = t["phi"] >= 0.3
        ctx.number("pstar_dense_mean_abs_error", {n: float(np.mean(np.abs(errs[n][dense]))) for n in names})
    path = ctx.data_file(UNIFORM_SHEAR)
    if path is not None:
        t = read_table(path).as_dict()
        rows = []
        eta_err = {}
        for n in names:
            r = get_model(n).reduced(t["phi"], t["e"])
            eta_err[n] = np.asarray(r.eta, dtype=float) / t["eta_over_eta0"] - 1.0
        for j in range(t["phi"].size):
            rows.append([f"φ={t['phi'][j]:g}, e={t['e'][j]:g}, a*={t['astar'][j]:.2f}", float(t["eta_over_eta0"][j]),
                         float(t["deta_over_eta0"][j])] + [100 * float(eta_err[n][j]) for n in names])
        ctx.table(f"Shear viscosity η/η0 against DEM uniform shear ({UNIFORM_SHEAR}): relative error %",
                  ["state", "DEM η/η0", "± DEM", *[get_model(n).label for n in names]], rows,
                  note="Navier–Stokes η* compared at the DEM's shear rate a* = γ̇/ν0 ≈ 0.2–0.3, where shear thinning "
                       "beyond Navier–Stokes order is expected; read as indicative.")
        ctx.dataset(xr.Dataset(
            {"eta_dem": (("state",), t["eta_over_eta0"], {"long_name": "DEM shear viscosity eta/eta0", "units": "1"}),
             "eta_dem_sem": (("state",), t["deta_over_eta0"], {"long_name": "standard error of the DEM eta/eta0", "units": "1"}),
             "eta_model": (("model", "state"), np.array([eta_err[n] + 1 for n in names]) * t["eta_over_eta0"],
                           {"long_name": "model Navier-Stokes eta* = eta/eta0", "units": "1"}),
             "error": (("model", "state"), np.array([eta_err[n] for n in names]), {"long_name": "eta_model/eta_dem - 1", "units": "1"})},
            coords={"model": list(names), "phi": (("state",), t["phi"], {"long_name": "solid fraction", "units": "1"}),
                    "e": (("state",), t["e"], {"long_name": "normal restitution coefficient", "units": "1"}),
                    "astar": (("state",), t["astar"], {"long_name": "reduced shear rate a* = shear rate/nu0", "units": "1"})},
            attrs=run_metadata(None, source=UNIFORM_SHEAR, quantity="eta* = eta/eta0")), "eta_vs_dem_uniform_shear")
        ctx.number("eta_shear_error", {n: {f"{p:g}": float(v) for p, v in zip(t["phi"], eta_err[n])} for n in names})


def run(ctx: SectionContext) -> None:
    s = ctx.settings
    from ..plotting.coefficients import plot_reduced_coefficients

    labels = ", ".join(get_model(n).label for n in s.models)
    ctx.paragraph(
        f"Reduced coefficients (docs/model.md §1: p* = p/(ρθ), η* = η/η0, κ* = κ/κ0, μ* = φω/(θκ0), ζ0* = ζ0/ν0) of {labels}, "
        "and the radial distribution function χ each model uses. Models sharing a theory (Enskog and Visc.div.: "
        "Lun et al. 1984; RET and Proposed: Garzó & Dufty 1999) differ only through χ and the viscosity law, which "
        "depart from Carnahan–Starling above their freezing point φ_f; the two theories differ at every φ (Lun's has "
        "no density-gradient heat flux, μ* = 0, and a different dependence of κ*, η*, ζ0* on e)."
    )
    for e in s.coefficient_e:
        ds = coefficient_curves(s.models, e, s.coefficient_phi_max, s.coefficient_points)
        name = f"coefficients_e{e:g}"
        plot_reduced_coefficients([get_model(n) for n in s.models], e=e, phi_max=s.coefficient_phi_max,
                                  out=ctx.figure_path(name), n=s.coefficient_points)
        ctx.add_figure(name, f"Reduced transport coefficients and χ(φ) of the models at e = {e:g} (log scale)."
                       + overlap_note(ds) + step_sentence(junction_steps(s.models, e)), ds)
    e0 = s.coefficient_e[0]
    rows = []
    ratio: dict[str, dict[str, float]] = {}
    for n in s.models:
        m = get_model(n)
        for phi in TABLE_PHI:
            if phi >= m.phi_max:
                continue
            r = m.reduced(phi, e0)
            rows.append([f"{m.label}, φ={phi:g}", *(float(getattr(r, k)) for k in ("p", "eta", "kappa", "mu", "zeta0")), float(m.chi(phi))])
            ratio.setdefault(n, {})[f"{phi:g}"] = float(r.eta)
    ctx.table(f"Reduced coefficients at e = {e0:g}", ["model, φ", "p*", "η*", "κ*", "μ*", "ζ0*", "χ"], rows)
    ctx.number("eta_star", ratio)
    ctx.number("table_e", e0)
    _dem_checks(ctx, s.models)


def discuss(nb: dict[str, Any]) -> list[str]:
    out = []
    eta = nb.get("eta_star", {})
    labels = {n: get_model(n).label for n in eta}
    if "0.5" in eta.get("ret", {}) and "0.5" in eta.get("proposed", {}):
        out.append(
            f"At φ = 0.5 (e = {nb['table_e']:g}) the Proposed model's shear viscosity is "
            f"{eta['proposed']['0.5'] / eta['ret']['0.5']:.2f} times RET's"
            + (f", and Visc.div.'s is {eta['visc-div']['0.5'] / eta['enskog']['0.5']:.2f} times Enskog's" if "0.5" in eta.get("visc-div", {}) and "0.5" in eta.get("enskog", {}) else "")
            + "."
        )
    pairs = [("ret", "proposed"), ("enskog", "visc-div")]
    same = [p for p in ("0.1", "0.3") if all(a in eta and b in eta and p in eta[a] and p in eta[b]
                                             and abs(eta[b][p] / eta[a][p] - 1) < 1e-12 for a, b in pairs)]
    if same:
        out.append(f"At φ = {' and '.join(same)} the models sharing a theory give identical η* (their χ and viscosity laws coincide there).")
    pe = nb.get("pstar_mean_abs_error")
    if pe:
        best = closest(pe)
        pd = nb.get("pstar_dense_mean_abs_error", {})
        verdict = (f"{join_labels(best)} is closest" if len(best) < len(pe) else
                   "all models give the same p* at these states (φ ≤ 0.4, where their χ coincide), so these data cannot rank them")
        out.append(
            "Against the DEM equation of state measured in homogeneous cooling, the mean |error| of p* is "
            + ", ".join(f"{labels.get(n, get_model(n).label)} {100 * v:.1f} %" for n, v in pe.items())
            + f"; {verdict}"
            + (" (for φ ≥ 0.3: " + ", ".join(f"{get_model(n).label} {100 * v:.1f} %" for n, v in pd.items()) + ")." if pd else ".")
        )
    es = nb.get("eta_shear_error")
    if es:
        phis = sorted(next(iter(es.values())))
        for p in phis:
            best = join_labels(closest({n: abs(es[n][p]) for n in es}))
            out.append(
                f"Uniform-shear DEM at φ = {p}: η* errors "
                + ", ".join(f"{get_model(n).label} {100 * es[n][p]:+.0f} %" for n in es)
                + f"; closest: {best} (indicative only: a* ≈ 0.2–0.3 is beyond Navier–Stokes order)."
            )
    return out


SECTION = register_section(Section(
    "coefficients", "1. Transport coefficients and radial distribution functions", run, inputs, order=10,
    data_files=(HCS_COOLING, UNIFORM_SHEAR), modules=("ktgf.plotting.coefficients", "ktgf.data"), discuss=discuss,
))
