"""Reproduce the fit tables of docs/dense.md and docs/friction.md: the one family for all μ, its fit and its
leave-one-state-out cross-validation.

Run from the repository root:  python docs/dense_fit.py        (reads the data shipped in ktgf.data)

Step 1 (``dense``): a, b and the sheared part A of χ and c of the EKT length on the frictionless uniform shear,
e = 0.9, φ 0.3–0.6 (dem_uniform_shear.csv + dem_uniform_shear_extra.csv), p/(nT) of the cooling states
(dem_hcs_cooling.csv) and Torquato's (1995, Eq. 13) static contact value at φ 0.55–0.6 (the last two held in
every leave-one-out refit).  Step 2 (``frictional``): μ_Z and k on the μ = 0.5 uniform shear, e = 0.7,
φ 0.3–0.57 (dem_uniform_shear_friction.csv + _extra), step 1 held.  Predicted, never fitted: the μ = 0, e = 0.7
row, the cooling rates and the Couette file (`ktgf couette compare --model dense`).
"""

from __future__ import annotations

import time

import numpy as np

from ktgf.calibration.registry_fits import (
    OBSERVABLES,
    cooling_log_errors,
    cooling_states,
    fit_frictional,
    fit_frictionless,
    fit_sheared_structure,
    frictional_states,
    frictionless_states,
    leave_one_out,
    log_errors,
    registered_parameters,
    static_contact_states,
    static_log_errors,
    subset,
)

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
fl, fr, cool, static = frictionless_states(), frictional_states(), cooling_states(), static_contact_states()
f1 = fit_sheared_structure(fl, cool, static=static)
f2 = fit_frictional(f1.values, fr)
report_fit("step 1, frictionless (dense): a, b, c, A (shear states, cooling p/(nT), static χ)", f1)
report_fit("step 2, μ = 0.5 (frictional): mu_scale, amplitude_growth", f2)
reg = registered_parameters()
print("\nregistered:", reg)


def step1(states):
    return fit_sheared_structure(states, cool, static=static).values


loo1 = leave_one_out(step1, fl)
loo2 = leave_one_out(lambda s: {**f1.values, **fit_frictional(f1.values, s).values}, fr)
print("\n## frictionless, e = 0.9 (fit set of step 1): fit residuals and leave-one-state-out errors")
table(fl, f1.residuals, loo1, lambda i: "0")
print("\n## μ = 0.5, e = 0.7 (fit set of step 2, step 1 held): fit residuals and leave-one-state-out errors")
table(fr, f2.residuals, loo2, lambda i: f"{fr['mu'][i]:g}")


print("\n## fitted in step 1 besides the shear states: χ without shear (registered parameters)")
cool_err = np.expm1(cooling_log_errors(reg, cool))
print("| φ | e | p/(nT) DEM | error |\n|---|---|---|---|")
for phi, e, p, x in zip(cool["phi"], cool["e"], cool["p_over_nT"], cool_err):
    print(f"| {phi:g} | {e:g} | {p:.4f} | {pct(x)} |")
print("static χ against Torquato (1995) Eq. 13 at φ " + ", ".join(f"{x:g}" for x in static["phi"]) + ": "
      + ", ".join(pct(x) for x in np.expm1(static_log_errors(reg, static))))

print("\n## predicted, never fitted: the μ = 0, e = 0.7 row (registered parameters)")
every = frictional_states(frictional_only=False)
zero = subset(every, every["mu"] == 0.0)
err = np.expm1(log_errors(reg, zero))
for i in range(zero["phi"].size):
    print(f"- μ = 0, φ = {zero['phi'][i]:g}, e = {zero['e'][i]:g}: "
          + ", ".join(f"{LABELS[k]} {pct(err[j, i])}" for j, k in enumerate(OBSERVABLES)))

print("\n## alternative kept for comparison: no sheared part (A = 0), a, b, c on the shear states only "
      "(the registered fit before 2026-12)")
g1 = fit_frictionless(fl)
g2 = fit_frictional(g1.values, fr)
gp = {**g1.values, **g2.values}
print(", ".join(f"{k} = {v:.4g}" for k, v in gp.items()))
g_loo1 = leave_one_out(lambda s: fit_frictionless(s).values, fl)
g_loo2 = leave_one_out(lambda s: {**gp, **fit_frictional(gp, s).values}, fr)
table(fl, g1.residuals, g_loo1, lambda i: "0")
table(fr, g2.residuals, g_loo2, lambda i: f"{fr['mu'][i]:g}")
e0 = np.expm1(log_errors(gp, zero))
print("μ = 0, e = 0.7 row, max |error|: " + ", ".join(f"{LABELS[k]} {pct(np.max(np.abs(e0[j])), '')}"
                                                      for j, k in enumerate(OBSERVABLES)))
print("cooling p/(nT), max |error|: " + pct(np.max(np.abs(np.expm1(cooling_log_errors(gp, cool)))), ""))
print("static χ: " + ", ".join(pct(x) for x in np.expm1(static_log_errors(gp, static))))

print("\n## alternative: Chialvo–Sundaresan's exponent b = 1.5 held (a, c, A fitted)")
h1 = fit_sheared_structure(fl, cool, static=static, hold={"exponent": 1.5})
hp = {**h1.values, "exponent": 1.5}
print(", ".join(f"{k} = {v:.4g}" for k, v in hp.items()) + "; max |error| shear T, p/(nT), τ/p: "
      + ", ".join(pct(np.max(np.abs(np.expm1(h1.residuals[k]))), "") for k in range(len(OBSERVABLES)))
      + "; static χ: " + ", ".join(pct(x) for x in np.expm1(static_log_errors(hp, static))))

print("\n## φ_J(μ) alone (amplitude_growth k = 0 held, mu_scale fitted)")
h = fit_frictional(f1.values, fr, hold={"amplitude_growth": 0.0})
print(f"mu_scale = {h.values['mu_scale']:.4g}; max |error| T, p/(nT), τ/p: "
      + ", ".join(pct(np.max(np.abs(np.expm1(h.residuals[k])))) for k in range(len(OBSERVABLES))))

print(f"\n(wall time {time.perf_counter() - t0:.1f} s)")
