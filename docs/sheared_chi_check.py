"""Print docs/dense_physics.md §8: the sheared contact value χ(φ, s), fitted on the shared homogeneous files only.

    python docs/sheared_chi_check.py

Step 1 (``registry_fits.fit_sheared_structure``): a, b, c and A on the shared frictionless uniform shear (e = 0.9),
the cooling states' p/(nT) and the static contact value near jamming (Torquato 1995, Eq. 13, at φ 0.55–0.6);
leave-one-state-out errors.  Step 2 (``fit_frictional``): μ_Z and k on the shared
μ = 0.5 states.  Then predictions (never fitted) at the shared μ = 0, e = 0.7 row and at ktgf's own LAMMPS runs
(``docs/data/ktgf_dem_uniform_shear_predictions.csv``), next to the χ(φ) registered before 7 December 2026 (no
sheared part: ``fit_frictionless`` then ``fit_frictional``).  The registered ``dense``/``frictional`` are this fit.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ktgf.calibration import registry_fits as rf

OWN = Path(__file__).resolve().parent / "data" / "ktgf_dem_uniform_shear_predictions.csv"
NAMES = {"T": "T", "p_over_nT": "p/(nT)", "tau_over_p": "τ/p"}


def _pct(x: float) -> str:
    return f"{100 * x:+.1f} %"


def main() -> None:
    t0, c0 = time.perf_counter(), time.process_time()
    fl, cooling = rf.frictionless_states(), rf.cooling_states()
    before = rf.fit_frictionless(fl).values
    before = {**before, **rf.fit_frictional(before).values}
    fit = rf.fit_sheared_structure(fl, cooling)
    print("step 1:", ", ".join(f"{k} = {v:.4g} ± {fit.stderr[k]:.2g}" for k, v in fit.values.items()),
          f"({fit.n_points} points, {fit.points_per_parameter:.1f} per parameter)")
    print("correlation:\n", np.round(fit.correlation, 3))
    loo = rf.leave_one_out(lambda s: {**rf.registered_parameters(), **rf.fit_sheared_structure(s, cooling).values}, fl)
    res = np.expm1(fit.residuals)
    print("\n| φ | e | T fit | T LOO | p/(nT) fit | p/(nT) LOO | τ/p fit | τ/p LOO |\n|---|---|---|---|---|---|---|---|")
    for i in range(fl["phi"].size):
        cells = " | ".join(f"{_pct(res[q, i])} | {_pct(loo[q, i])}" for q in range(3))
        print(f"| {fl['phi'][i]:g} | {fl['e'][i]:g} | {cells} |")
    print("max |error| fit / LOO: " + ", ".join(f"{NAMES[k]} {100 * np.abs(res[q]).max():.1f} / "
                                                 f"{100 * np.nanmax(np.abs(loo[q])):.1f} %"
                                                 for q, k in enumerate(rf.OBSERVABLES)))
    cool = np.expm1(rf.cooling_log_errors(fit.values, cooling))
    old_cool = np.expm1(rf.cooling_log_errors(before, cooling))
    print(f"cooling p/(nT): max |error| {100 * np.abs(cool).max():.1f} % (χ(φ) before {100 * np.abs(old_cool).max():.1f} %)")
    static = rf.static_contact_states()

    def static_errors(params: dict[str, float]) -> str:
        return ", ".join(_pct(x) for x in np.expm1(rf.static_log_errors(params, static)))

    print("static χ against Torquato (1995) Eq. 13 at φ " + ", ".join(f"{p:g}" for p in static["phi"]) + ": "
          + static_errors(fit.values) + " (χ(φ) before: " + static_errors(before) + ")")

    frictional = rf.frictional_states()
    step2 = rf.fit_frictional(fit.values, frictional)
    params = {**fit.values, **step2.values}
    print("\nstep 2:", ", ".join(f"{k} = {v:.4g} ± {step2.stderr[k]:.2g}" for k, v in step2.values.items()))
    res2 = np.expm1(step2.residuals)
    print("fitted μ = 0.5, e = 0.7, max |error|: " + ", ".join(
        f"{NAMES[k]} {100 * np.abs(res2[q]).max():.1f} %" for q, k in enumerate(rf.OBSERVABLES)))

    shared = rf.frictional_states(frictional_only=False)
    own = rf.frictional_states((OWN,), frictional_only=False)
    rows = rf.subset(shared, shared["mu"] == 0.0)
    states = {k: np.concatenate([rows[k], own[k]]) for k in own}
    new, old = rf.predict(params, states), rf.predict(before, states)
    print("\nPredictions (never fitted), model/DEM − 1: this fit / χ(φ) before\n")
    print("| μ | φ | e | T | p/(nT) | τ/p |\n|---|---|---|---|---|---|")
    order = np.lexsort((states["phi"], states["mu"], states["e"]))
    for i in order:
        cells = " | ".join(f"{_pct(new[k][i] / states[k][i] - 1)} / {_pct(old[k][i] / states[k][i] - 1)}"
                           for k in rf.OBSERVABLES)
        print(f"| {states['mu'][i]:g} | {states['phi'][i]:g} | {states['e'][i]:g} | {cells} |")
    for label, err in (("this fit", new), ("χ(φ) before", old)):
        worst = {k: np.abs(err[k] / states[k] - 1).max() for k in rf.OBSERVABLES}
        print(f"max |error| {label}: " + ", ".join(f"{NAMES[k]} {100 * v:.1f} %" for k, v in worst.items()))
    print(f"\n({time.perf_counter() - t0:.1f} s wall, {time.process_time() - c0:.1f} s CPU)")


if __name__ == "__main__":
    main()
