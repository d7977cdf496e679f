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
from ..io import run_metadata
from .dem import HCS_COOLING, UNIFORM_SHEAR, read_table
from .framework import Section, SectionContext, closest, join_labels, model_inputs, register_section
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
        {k: (("model", "point"), v, {"long_name": long[k], "units": "1"}) for k, v in data.items()},
        coords={"model": list(names)},
        attrs=run_metadata(None, e=e, phi_max=phi_max, points=n, models=list(names), figure="reduced coefficients"),
    )
    return ds


def _dem_checks(ctx: SectionContext, names: tuple[str, ...]) -> None:
    path = ctx.data_file(HCS_COOLING)
    if path is not None:
        t = read_table(path)
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
            {"p_dem": (("state",), t["p_over_nT"]), "p_model": (("model", "state"), np.array([errs[n] + 1 for n in names]) * t["p_over_nT"])},
            coords={"model": list(names), "phi": (("state",), t["phi"]), "e": (("state",), t["e"])},
            attrs=run_metadata(None, source=HCS_COOLING, quantity="p* = p/(n T)")), "pstar_vs_dem_hcs")
        ctx.number("pstar_mean_abs_error", {n: float(np.mean(np.abs(errs[n]))) for n in names})
        dense = t["phi"] >= 0.3
        ctx.number("pstar_dense_mean_abs_error", {n: float(np.mean(np.abs(errs[n][dense]))) for n in names})
    path = ctx.data_file(UNIFORM_SHEAR)
    if path is not None:
        t = read_table(path)
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
        ctx.number("eta_shear_error", {n: {f"{p:g}": float(v) for p, v in zip(t["phi"], eta_err[n])} for n in names})


def run(ctx: SectionContext) -> None:
    s = ctx.settings
    from ..plotting.coefficients import plot_reduced_coefficients

    labels = ", ".join(get_model(n).label for n in s.models)
    ctx.paragraph(
        f"Reduced coefficients (model.md §1: p* = p/(ρθ), η* = η/η0, κ* = κ/κ0, μ* = φω/(θκ0), ζ0* = ζ0/ν0) of {labels}, "
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
        ctx.add_figure(name, f"Reduced transport coefficients and χ(φ) of the models at e = {e:g} (log scale).", ds)
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
    data_files=(HCS_COOLING, UNIFORM_SHEAR), modules=("ktgf.plotting.coefficients", "ktgf.report.dem"), discuss=discuss,
))
