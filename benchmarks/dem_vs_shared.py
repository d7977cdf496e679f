"""Compare a `ktgf dem shear` CSV with a shared DEM file, state by state.

Run:  python benchmarks/dem_vs_shared.py MINE.csv SHARED.csv [SHARED2.csv ...]

For every state of MINE found in the shared files (same mu, phi, e; mu = 0 when a file has no mu
column), prints each common observable with its standard error, the relative deviation, the
deviation in combined standard errors and whether |Δ| ≤ 2σ + 3 % (the issue-32 goal).
"""

from __future__ import annotations

import math
import sys

from ktgf.data import read_table

OBSERVABLES = ("T", "Trot_over_T", "p_star", "tau_star", "tau_over_p", "p_over_nT", "eta_over_eta0", "eta_star")


def main(mine_path: str, *shared_paths: str) -> None:
    shared = [r for p in shared_paths for r in read_table(p).records()]
    for m in read_table(mine_path).records():
        key = (m.get("mu", 0.0), m["phi"], m["e"])
        ref = next((r for r in shared if (r.get("mu", 0.0), r["phi"], r["e"]) == key), None)
        if ref is None:
            continue
        print(f"mu={key[0]:g} phi={key[1]:g} e={key[2]:g}")
        for k in OBSERVABLES:
            if k not in m or k not in ref or ("d" + k) not in m or ref[k] == 0:
                continue
            sigma = math.hypot(m["d" + k], ref["d" + k])
            diff = m[k] - ref[k]
            ok = abs(diff) <= 2 * sigma + 0.03 * abs(ref[k])
            print(f"  {k:14s} ktgf {m[k]:.5g} ± {m['d' + k]:.2g}   shared {ref[k]:.5g} ± {ref['d' + k]:.2g}   "
                  f"{100 * diff / ref[k]:+.1f} %  {diff / sigma:+.1f} σ  {'ok' if ok else 'OUTSIDE 2σ + 3 %'}")


if __name__ == "__main__":
    main(*sys.argv[1:])
