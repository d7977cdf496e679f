"""Reproduce the fit tables of docs/dense.md and docs/friction.md: the one family for all μ, its fit and its
leave-one-state-out cross-validation.

Run from the repository root:  python docs/dense_fit.py        (reads the data shipped in ktgf.data)

Step 1 (``dense``): a, b of χ and c of the EKT length on the frictionless uniform shear, e = 0.9, φ 0.3–0.6
(dem_uniform_shear.csv + dem_uniform_shear_extra.csv).  Step 2 (``frictional``): μ_Z and k on the μ = 0.5
uniform shear, e = 0.7, φ 0.3–0.57 (dem_uniform_shear_friction.csv + _extra), step 1 held.  Predicted, never
fitted: the μ = 0, e = 0.7 row and the Couette file (`ktgf couette compare --model dense`).
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import least_squares

from ktgf import get_model
from ktgf.calibration.registry_fits import (
    FRICTIONLESS_PARAMETERS,
    OBSERVABLES,
    family_model,
    fit_frictional,
    fit_frictionless,
    frictional_states,
    frictionless_states,
    leave_one_out,
    log_errors,
    registered_parameters,
    subset,
)
from ktgf.data import HCS_COOLING, read_cooling, shipped

LABELS = {"T": "T", "p_over_nT": "p/(nT)", "tau_over_p": "τ/p"}


def pct(x: float, sign: str = "+") -> str:
    return "refused" if not np.isfinite(x) else f"{100 * x:{sign}.1f} %"


def report_fit(title, fit):
    print(f"\n### {title}: {fit.n_points} points, {len(fit.names)} parameters "
          f"({fit.points_per_parameter:.0f} per parameter), converged: {fit.success}")
    for n in fit.names:
        print(f"- {n} = {fit.values[n]:.4g} ± {fit.stderr[n]:.2g}")
    print("- correlation matrix:", np.array2string(fit.correlation, precision=3, suppress_small=True).replace("\n", ""))
    big = [(fit.names[i], fit.names[j], fit.correlation[i, j]) for i in range(len(fit.names))
           for j in range(i + 1, len(fit.names)) if abs(fit.correlation[i, j]) > 0.95]
    for a, b, r in big:
        print(f"- WARNING: {a} and {b} are {r:+.3f} correlated")


def table(states, fit_err, loo_err, mu_label):
    cols = " | ".join(f"{LABELS[k]} fit | {LABELS[k]} LOO" for k in OBSERVABLES)
    print(f"\n| μ | φ | e | {cols} |")
    print("|---|---|---|" + "---|---|" * len(OBSERVABLES))
    for i in range(states["phi"].size):
        cells = " | ".join(f"{pct(np.expm1(fit_err[k, i]))} | {pct(loo_err[k, i])}" for k in range(len(OBSERVABLES)))
        print(f"| {mu_label(i)} | {states['phi'][i]:g} | {states['e'][i]:g} | {cells} |")
    mean = " | ".join(f"{pct(np.mean(np.abs(np.expm1(fit_err[k]))), '')} | {pct(np.nanmean(np.abs(loo_err[k])), '')}"
                      for k in range(len(OBSERVABLES)))
    worst = " | ".join(f"{pct(np.max(np.abs(np.expm1(fit_err[k]))), '')} | {pct(np.nanmax(np.abs(loo_err[k])), '')}"
                       for k in range(len(OBSERVABLES)))
    print(f"| mean abs. | | | {mean} |")
    print(f"| max abs. | | | {worst} |")


t0 = time.perf_counter()
fl, fr = frictionless_states(), frictional_states()
f1 = fit_frictionless(fl)
f2 = fit_frictional(f1.values, fr)
report_fit("step 1, frictionless (dense): a, b, c", f1)
report_fit("step 2, μ = 0.5 (frictional): mu_scale, amplitude_growth", f2)
reg = registered_parameters()
print("\nregistered:", reg)


loo1 = leave_one_out(lambda s: fit_frictionless(s).values, fl)
loo2 = leave_one_out(lambda s: {**f1.values, **fit_frictional(f1.values, s).values}, fr)
print("\n## frictionless, e = 0.9 (fit set of step 1): fit residuals and leave-one-state-out errors")
table(fl, f1.residuals, loo1, lambda i: "0")
print("\n## μ = 0.5, e = 0.7 (fit set of step 2, step 1 held): fit residuals and leave-one-state-out errors")
table(fr, f2.residuals, loo2, lambda i: f"{fr['mu'][i]:g}")

print("\n## predicted, never fitted: the μ = 0, e = 0.7 row (registered parameters)")
every = frictional_states(frictional_only=False)
zero = subset(every, every["mu"] == 0.0)
err = np.expm1(log_errors(reg, zero))
for i in range(zero["phi"].size):
    print(f"- μ = 0, φ = {zero['phi'][i]:g}, e = {zero['e'][i]:g}: "
          + ", ".join(f"{LABELS[k]} {pct(err[j, i])}" for j, k in enumerate(OBSERVABLES)))

print("\n## predicted, never fitted: homogeneous cooling (dem_hcs_cooling.csv), p/(nT) = 1 + 2(1 + e)φχ of dense")

hcs = read_cooling(shipped(HCS_COOLING))
dense = get_model("dense")
print("| φ | e | p/(nT) DEM | dense | err | Carnahan–Starling χ (RET) | err |")
print("|---|---|---|---|---|---|---|")
for phi, e, p in zip(hcs["phi"], hcs["e"], hcs["p_over_nT"]):
    model, cs = float(dense.reduced(phi, e, hcs=True).p), float(get_model("ret").reduced(phi, e).p)
    print(f"| {phi:g} | {e:g} | {p:.4f} | {model:.4f} | {pct(model / p - 1)} | {cs:.4f} | {pct(cs / p - 1)} |")

print("\n## variant: the cooling-state p/(nT) added to the step-1 residuals (10 more points)")
names = tuple(FRICTIONLESS_PARAMETERS)


def with_hcs(x):
    p = dict(zip(names, x))
    m = family_model(**p)
    cool = [float(m.reduced(phi, e, hcs=True).p) for phi, e in zip(hcs["phi"], hcs["e"])]
    return np.concatenate([log_errors(p, fl).ravel(), np.log(np.array(cool) / hcs["p_over_nT"])])


lo, hi = zip(*((v[1], v[2]) for v in FRICTIONLESS_PARAMETERS.values()))
v = least_squares(with_hcs, [f1.values[n] for n in names], bounds=(lo, hi))
r = np.expm1(with_hcs(v.x))
print(", ".join(f"{n} = {x:.4g}" for n, x in zip(names, v.x)) + "; max |error| shear T, p/(nT), τ/p: "
      + ", ".join(pct(np.max(np.abs(r[k * fl['phi'].size:(k + 1) * fl['phi'].size])), '') for k in range(3))
      + f"; cooling p/(nT): {pct(np.max(np.abs(r[3 * fl['phi'].size:])), '')}")

print("\n## alternative kept for comparison: Chialvo–Sundaresan's exponent b = 1.5 held (a, c fitted)")
g1 = fit_frictionless(fl, hold={"exponent": 1.5})
g2 = fit_frictional({**g1.values, "exponent": 1.5}, fr)
gp = {**g1.values, "exponent": 1.5, **g2.values}
print(f"a = {g1.values['a']:.4g} ± {g1.stderr['a']:.2g}, c = {g1.values['c']:.4g} ± {g1.stderr['c']:.2g}; "
      f"mu_scale = {g2.values['mu_scale']:.4g}, amplitude_growth = {g2.values['amplitude_growth']:.4g}")
g_loo1 = leave_one_out(lambda s: {**fit_frictionless(s, hold={"exponent": 1.5}).values, "exponent": 1.5}, fl)
g_loo2 = leave_one_out(lambda s: {**gp, **fit_frictional(gp, s).values}, fr)
table(fl, g1.residuals, g_loo1, lambda i: "0")
table(fr, g2.residuals, g_loo2, lambda i: f"{fr['mu'][i]:g}")
e0 = np.expm1(log_errors(gp, zero))
print("μ = 0, e = 0.7 row:", ", ".join(f"{LABELS[k]} {pct(e0[j, 0])}" for j, k in enumerate(OBSERVABLES)))

print("\n## φ_J(μ) alone (amplitude_growth k = 0 held, mu_scale fitted)")
h = fit_frictional(f1.values, fr, hold={"amplitude_growth": 0.0})
print(f"mu_scale = {h.values['mu_scale']:.4g}; max |error| T, p/(nT), τ/p: "
      + ", ".join(pct(np.max(np.abs(np.expm1(h.residuals[k])))) for k in range(len(OBSERVABLES))))

print(f"\n(wall time {time.perf_counter() - t0:.1f} s)")
