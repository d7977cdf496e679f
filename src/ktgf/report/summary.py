"""The report's first screen: model × test case × error against the DEM, a recommendation per regime, caveats.

Everything is read from the numbers the sections recorded (``SectionResult.numbers``) at page
time, so a cached section is summarised like a fresh one, and each row names the netCDF file
that holds the numbers behind it.  Nothing here is a fixed verdict: with other settings, data or
models the table, the recommendations and the caveats change with the numbers.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..closures.models import get_model
from .results import SectionResult

#: Errors closer than this (absolute, in the row's own measure) count as a tie.
TIE = 1e-4


@dataclass
class Row:
    """One test case: what is compared, in which regime, each model's error, and the data file behind it."""

    case: str
    measure: str
    regime: str
    errors: dict[str, float]
    data: str
    percent: bool = True

    @property
    def best(self) -> list[str]:
        low = min(self.errors.values())
        return [n for n, v in self.errors.items() if v <= low + TIE]


def model_names(rows: list[Row]) -> list[str]:
    """Every model of any row, in the order they first appear (a section may add models, e.g. ``dense``)."""
    return list(dict.fromkeys(n for r in rows for n in r.errors))


@dataclass
class Summary:
    rows: list[Row] = field(default_factory=list)
    recommendations: list[str] = field(default_factory=list)
    caveats: list[str] = field(default_factory=list)


def _label(n: str) -> str:
    return get_model(n).label or n


def _join(names: list[str]) -> str:
    labels = [_label(n) for n in names]
    return labels[0] if len(labels) == 1 else ", ".join(labels[:-1]) + " and " + labels[-1]


def _data(r: SectionResult, stem: str) -> str:
    return next((d for d in r.datasets if d.endswith(f"/{stem}.nc")), "")


def summarise(results: list[SectionResult]) -> Summary:
    """Collect the comparison rows from the sections' numbers and derive recommendations and caveats."""
    by = {r.key: r for r in results if r.status in ("computed", "cached")}
    s = Summary()
    hcs, coef, cou, dense = by.get("hcs"), by.get("coefficients"), by.get("couette"), by.get("dense")
    states: list[tuple[float, float]] = []
    if hcs is not None and "cooling_mean_abs_error" in hcs.numbers:
        states = [tuple(float(x) for x in k.split(",")) for k in hcs.numbers.get("cooling_best", {})]
        span = f"φ = {min(p for p, _ in states):g}–{max(p for p, _ in states):g}" if states else ""
        s.rows.append(Row(f"Homogeneous cooling ({len(states)} states, {span})", "cooling rate ζ0: mean |error|",
                          "dilute–moderate", dict(hcs.numbers["cooling_mean_abs_error"]), _data(hcs, "cooling_rate_vs_dem")))
    if coef is not None and "pstar_mean_abs_error" in coef.numbers:
        s.rows.append(Row("Homogeneous cooling (same states)", "pressure p*: mean |error|", "dilute–moderate",
                          dict(coef.numbers["pstar_mean_abs_error"]), _data(coef, "pstar_vs_dem_hcs")))
    if coef is not None and "eta_shear_error" in coef.numbers:
        es = coef.numbers["eta_shear_error"]
        for phi in sorted(next(iter(es.values())), key=float):
            regime = "dense" if float(phi) >= 0.4 else "dilute–moderate"
            s.rows.append(Row(f"Uniform shear, φ = {phi}", "shear viscosity η: |error|", regime,
                              {n: abs(v[phi]) for n, v in es.items()}, _data(coef, "eta_vs_dem_uniform_shear")))
    if cou is not None and "couette_errors" in cou.numbers:
        ce = cou.numbers["couette_errors"]
        data = _data(cou, "couette_profiles")
        phi_mean = cou.inputs.get("phi_mean")
        case = "Couette cell" + (f", mean φ = {phi_mean:g}" if isinstance(phi_mean, (int, float)) else "")
        for key, what, pct in (("phi_rms", "φ profile: RMS(φ − φ_DEM)", False), ("theta_rms_rel", "θ profile: RMS(θ/θ_DEM − 1)", True),
                               ("u_rms_over_U", "u profile: RMS(u − u_DEM)/U", False)):
            s.rows.append(Row(case, what, "dense", {n: v[key] for n, v in ce.items()}, data, pct))
    if dense is not None and "couette_wall" in dense.numbers:
        cw = {n: v for n, v in dense.numbers["couette_wall"].items() if v.get("valid")}
        data = _data(dense, "couette_wall_stresses")
        if cw:
            for key, what in (("tau_error", "wall shear stress τ_w: |error|"), ("p_error", "wall normal stress p: |error|")):
                s.rows.append(Row("Couette cell, wall stresses (predicted)", what, "dense", {n: abs(v[key]) for n, v in cw.items()}, data))
    val = by.get("validation")
    if val is not None and val.numbers.get("validation"):
        _validation_rows(s, val)
    _recommend(s, states)
    _caveats(s, by, hcs)
    return s


def _validation_rows(s: Summary, val: SectionResult) -> None:
    """One row per case and role of the fitted models' validation (regime ``validation``: not ranked, the models
    differ in what they were fitted to), the pooled rows first."""
    per_model = val.numbers["validation"]
    cases = list(dict.fromkeys(c for v in per_model.values() for c in v))
    cases = ["all", *[c for c in cases if c != "all"]]
    for case in cases:
        for role in ("fitted", "predicted"):
            errors = {n: v[case][role] for n, v in per_model.items() if role in v.get(case, {})}
            if errors:
                what = "all DEM files" if case == "all" else case
                s.rows.append(Row(f"Fitted models, {what}: {role} rows", "mean |model/DEM − 1|", "validation", errors,
                                  _data(val, "validation")))


def _recommend(s: Summary, states: list[tuple[float, float]]) -> None:
    for regime, where in (("dilute–moderate", "φ ≲ 0.4 (below the freezing point, where the RDFs coincide)"),
                          ("dense", "φ ≈ 0.5–0.6 (sheared dense flow)")):
        rows = [r for r in s.rows if r.regime == regime]
        if not rows:
            continue
        telling = [r for r in rows if len(r.best) < len(r.errors)]  # a row where every model ties ranks nobody
        same = [r.measure.split(":")[0] for r in rows if r not in telling]
        tail = f"; all models equal in {', '.join(same)}" if same else ""
        if not telling:
            s.recommendations.append(f"{where}: no model is closer than another in these comparisons{tail}.")
            continue
        wins: dict[str, int] = {}
        for r in telling:
            for n in r.best:
                wins[n] = wins.get(n, 0) + 1
        top = max(wins.values())
        best = [n for n in model_names(rows) if wins.get(n, 0) == top]
        groups = {tuple(r.best) for r in telling if set(r.best) <= set(best)}
        if len(groups) > 1:  # e.g. one theory wins one comparison, the other another: say so, pick none
            s.recommendations.append(
                f"{where}: no single best model — " + "; ".join(
                    f"{_join(r.best)} closest in {r.measure.split(':')[0]} ({_fmt(r.errors[r.best[0]], r.percent)})" for r in telling)
                + f"{tail}.")
            continue
        detail = "; ".join(f"{r.measure.split(':')[0]} {_fmt(r.errors[best[0]], r.percent)}" for r in rows if best[0] in r.errors)
        s.recommendations.append(
            f"{where}: {_join(best)} — closest to the DEM in {top} of {len(telling)} comparisons that tell the models apart "
            f"({'tied, identical there' if len(best) > 1 else 'its errors'}: {detail}).")


def _caveats(s: Summary, by: dict[str, SectionResult], hcs: SectionResult | None) -> None:
    if not s.rows:
        s.caveats.append("No DEM reference data were found, so no model is measured against particle simulations here; "
                         "the sections below show the models' predictions only.")
        return
    if hcs is not None:
        signed = hcs.numbers.get("cooling_signed_mean", {})
        if signed and all(v > 0 for v in signed.values()):
            s.caveats.append(f"Every model cools faster than the DEM (mean {min(signed.values()) * 100:+.1f} % to "
                             f"{max(signed.values()) * 100:+.1f} %): velocity correlations that Enskog-type theories neglect.")
    ties = {tuple(r.best) for r in s.rows if len(r.best) > 1 and r.regime != "validation"}  # validation rows: not ranked
    if ties:
        s.caveats.append("Ties are models whose numbers coincide (within 1e-4): " + "; ".join(_join(list(t)) for t in sorted(ties))
                         + ". Below the freezing point φ_f the models of one theory share χ and viscosity, so those data cannot tell them apart.")
    if any(r.case.startswith("Uniform shear") for r in s.rows):
        s.caveats.append("Uniform-shear DEM at a* = γ̇/ν0 ≈ 0.2–0.3 is beyond Navier–Stokes order: its η errors are indicative.")
    if any(r.case.startswith("Couette") for r in s.rows):
        s.caveats.append("Couette: each model's wall specularity is fitted to this same DEM case, so the profile errors test the bulk "
                         "closures, not a blind prediction; the DEM walls are bumpy, the continuum walls Johnson–Jackson.")
        mp = by["couette"].numbers.get("couette_max_phi", {}) if "couette" in by else {}
        over = [n for n, v in mp.items() if v >= 0.62]
        if over:
            s.caveats.append(f"Couette: the maximum φ of {_join(over)} reaches "
                             + ", ".join(f"{mp[n]:.3f}" for n in over) + ", close to random close packing (0.64).")
    if "friction" in by:
        s.caveats.append("The DEM data above are for frictionless spheres, and so are the paper's four models and `dense`; "
                         "real granules have friction: the frictional section compares the `frictional` model with frictional DEM.")
    else:
        s.caveats.append("All DEM data are for frictionless spheres; real granules have friction, which these closures omit.")
    if any(r.regime == "validation" for r in s.rows):
        s.caveats.append("Fitted models: quote the predicted rows (states not in the fit), not the fitted ones; those rows are "
                         "not ranked against the paper's models, which were fitted to none of these data.")
    if "cooling_gas" in by:
        s.caveats.append("The 3D cooling-gas section has no DEM counterpart: it checks the predicted instability thresholds, not accuracy.")


def _fmt(v: float, percent: bool) -> str:
    return f"{100 * v:.1f} %" if percent else f"{v:.3g}"


def summary_html(results: list[SectionResult]) -> str:
    """The summary block of the page (a table, the recommendations and the caveats)."""
    import html

    s = summarise(results)
    names = model_names(s.rows)
    parts = ['<section id="sec-summary"><h2>Summary: which model, where, and how wrong</h2>']
    if s.rows:
        head = "".join(f"<th>{html.escape(_label(n))}</th>" for n in names)
        body = []
        for r in s.rows:
            bold = set(r.best) if r.regime != "validation" else set()  # the fitted models' rows rank nobody
            cells = "".join(
                (f"<td>{'<b>' if n in bold else ''}{html.escape(_fmt(r.errors[n], r.percent))}{'</b>' if n in bold else ''}</td>"
                 if n in r.errors else "<td>—</td>") for n in names)
            link = f'<a href="{html.escape(r.data)}">{html.escape(r.data.rsplit("/", 1)[-1])}</a>' if r.data else "—"
            body.append(f'<tr><td class="l">{html.escape(r.case)}</td><td class="l">{html.escape(r.measure)}</td>{cells}'
                        f'<td class="l">{link}</td></tr>')
        parts.append('<table class="summary"><caption>Error against the DEM (bold: closest; ties in bold together)</caption>'
                     f'<tr><th class="l">test case</th><th class="l">quantity</th>{head}<th class="l">data (netCDF)</th></tr>'
                     + "".join(body) + "</table>")
    if s.recommendations:
        parts.append("<p><b>Recommended model per regime</b> (most comparisons closest to the DEM):</p><ul>"
                     + "".join(f"<li>{html.escape(t)}</li>" for t in s.recommendations) + "</ul>")
    parts.append("<p><b>Caveats</b>:</p><ul>" + "".join(f"<li>{html.escape(c)}</li>" for c in s.caveats) + "</ul>")
    parts.append("</section>")
    return "\n".join(parts)
