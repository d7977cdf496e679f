"""Reproduce the numbers of docs/dense.md: the fit of `dense` and its predictions.

Run from the repository root:  python docs/dense_fit.py [DATA_DIR]   (default ../shared/data)

Fit set: dem_uniform_shear.csv (frictionless, e = 0.9, φ = 0.3 and 0.5).
Held out: the μ = 0 row of dem_uniform_shear_friction.csv (frictionless, e = 0.7, φ = 0.5).
(The Couette file is predicted by `ktgf couette compare`, not used here.)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from ktgf import PAPER_MODELS, get_model
from ktgf.calibration.registry_fits import fit_rdf_option, relative_errors
from ktgf.closures.dense import DENSE_BETA
from ktgf.closures.dissipation import CorrelationLength
from ktgf.closures.rdf import JammingPowerLaw, ViscosityDivergence
from ktgf.data import uniform_shear_records
from ktgf.shear.steady import steady_shear

data = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "shared" / "data"
fit_rows = uniform_shear_records(data / "dem_uniform_shear.csv")
held_rows = uniform_shear_records(data / "dem_uniform_shear_friction.csv", where={"mu": 0.0})
COLS = ["phi", "e", "T", "eta_over_eta0", "p_over_nT"]
rows = np.concatenate([fit_rows[COLS], held_rows[COLS]])
role = ["fit"] * fit_rows.size + ["held out"] * held_rows.size


def table(models):
    print("| model | φ | e | set | η* model | η* DEM | err η* | p/(nT) model | p/(nT) DEM | err p "
          "| T model | T DEM | err T |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, m in models:
        s = steady_shear(m, rows["phi"], rows["e"])
        for i, rec in enumerate(rows):
            eta, p, T = (float(np.broadcast_to(v, rows.shape)[i]) for v in (s.eta_over_eta0, s.p_over_nT, s.T))
            print(f"| {name} | {rec['phi']:g} | {rec['e']:g} | {role[i]} | {eta:.3f} | {rec['eta_over_eta0']:.3f} | "
                  f"{eta / rec['eta_over_eta0'] - 1:+.1%} | {p:.3f} | {rec['p_over_nT']:.3f} | "
                  f"{p / rec['p_over_nT'] - 1:+.1%} | "
                  f"{T:.4f} | {rec['T']:.4f} | {T / rec['T'] - 1:+.1%} |")


print("## fit of dense: beta of the viscosity-divergence RDF with RET, on", data / "dem_uniform_shear.csv")
beta, sol = fit_rdf_option(get_model("ret"), fit_rows, "beta")
J = sol.jac
cov = np.linalg.inv(J.T @ J) * (2 * sol.cost / max(sol.fun.size - 1, 1))
print(f"beta = {beta:.5f} ± {np.sqrt(cov[0, 0]):.5f} (registered {DENSE_BETA}); cost {sol.cost:.5f}; "
      f"residuals {np.round(sol.fun, 4)}")
print("held-out residuals [eta, p]:", np.round(relative_errors(get_model("dense"), held_rows), 4))

print("\n## candidates tried (same fit set, same residuals; held-out = e = 0.7 row)")
base = {"ret": get_model("ret"), "enskog": get_model("enskog")}
candidates = [
    ("beta (phi_f 0.49, phi_c 0.64)", lambda x: ViscosityDivergence(beta=x[0]), [1.75], ([1.0], [8.0])),
    ("phi_f", lambda x: ViscosityDivergence(phi_f=x[0]), [0.49], ([0.3], [0.6])),
    ("phi_f, beta", lambda x: ViscosityDivergence(phi_f=x[0], beta=x[1]), [0.49, 1.75], ([0.3, 0.1], [0.6, 5])),
    ("phi_c, beta (phi_f 0.49)", lambda x: ViscosityDivergence(phi_c=x[0], beta=x[1]), [0.64, 1.75],
     ([0.5, 0.1], [0.7404, 5])),
    ("jamming a (b 1.5)", lambda x: JammingPowerLaw(a=x[0]), [0.3], ([0.0], [5.0])),
    ("jamming a (b 2)", lambda x: JammingPowerLaw(a=x[0], exponent=2.0), [0.3], ([0.0], [5.0])),
    ("jamming a, b", lambda x: JammingPowerLaw(a=x[0], exponent=x[1]), [0.3, 1.5], ([0.0, 0.1], [5.0, 5.0])),
]
print("| theory | fitted | values | cost | max |err| fit | held-out err η*, p |")
print("|---|---|---|---|---|---|")
for tname, b in base.items():
    for label, make, x0, bounds in candidates:
        s = least_squares(lambda x: relative_errors(b.replace(rdf=make(x)), fit_rows), x0, bounds=bounds)
        held = relative_errors(b.replace(rdf=make(s.x)), held_rows)
        values = ", ".join(f"{v:.4g}" for v in s.x)
        print(f"| {tname} | {label} | {values} | {s.cost:.5f} | {np.abs(s.fun).max():.1%} | "
              f"{held[0]:+.1%}, {held[1]:+.1%} |")

print("\n## uniform shear: paper models and dense (Navier–Stokes closed forms, model.md §9)")
table([(n, get_model(n)) for n in (*PAPER_MODELS, "dense")])

print("\n## extended kinetic theory on dense (correlation length constant c)")
table([(f"dense + EKT c={c:g}", get_model("dense").replace(dissipation=CorrelationLength(c=c)))
       for c in (1.0, 1.5, 2.0)])
