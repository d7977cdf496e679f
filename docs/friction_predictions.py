"""Print docs/friction.md §6.2: the registered ``frictional`` against ktgf's own LAMMPS runs (never fitted).

    python docs/friction_predictions.py

Reads ``docs/data/ktgf_dem_uniform_shear_predictions.csv`` (``ktgf dem shear`` runs at μ and e the shared files
do not have) and prints one markdown row per state: model/DEM − 1 of T, p/(nT), τ/p and T_rot/T, with the DEM's
contacts per sphere.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ktgf import get_model
from ktgf.data import read_friction_shear
from ktgf.shear.steady import steady_shear

FILE = Path(__file__).resolve().parent / "data" / "ktgf_dem_uniform_shear_predictions.csv"


def main() -> None:
    print("| μ | φ | e | contacts/sphere | T | p/(nT) | τ/p | T_rot/T |")
    print("|---|---|---|---|---|---|---|---|")
    worst = {"T": 0.0, "p_over_nT": 0.0, "tau_over_p": 0.0}
    for r in sorted(read_friction_shear(FILE), key=lambda r: (r["e"], r["mu"], r["phi"])):
        s = steady_shear(get_model("frictional", mu=r["mu"]), np.array([r["phi"]]), r["e"])
        dem = {"T": r["T"], "p_over_nT": r["p_star"] / (r["phi"] * r["T"]), "tau_over_p": r["tau_over_p"],
               "Trot_over_T": r["Trot_over_T"]}
        err = {q: float(np.asarray(getattr(s, q))[0]) / v - 1.0 if v > 0 else float("nan") for q, v in dem.items()}
        for q in worst:
            worst[q] = max(worst[q], abs(err[q]))
        cells = " | ".join("—" if np.isnan(err[q]) else f"{100 * err[q]:+.1f} %" for q in dem)
        print(f"| {r['mu']:g} | {r['phi']:g} | {r['e']:g} | {r['contacts_per_particle']:.3f} | {cells} |")
    print("\nmax |error|: " + ", ".join(f"{q} {100 * v:.1f} %" for q, v in worst.items()))


if __name__ == "__main__":
    main()
