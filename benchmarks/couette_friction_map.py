"""Convergence map of the frictional Couette cell from the naive start (docs/friction.md §8).

Frictional particles (model ``frictional``, frictional stress Schaeffer or Srivastava–Sundaresan) between
Johnson–Jackson walls with a wall friction angle δ_w; the cell of ``tests/couette/test_friction_couette.py``
(20 d planar, 80 cells, e = 0.7, φ' = 0.2, e_w = 0.85, ρ_s V² = 2500 Pa).  Prints one markdown row per case:
converged?, solver path, wall and CPU seconds, max φ, the validity verdict, and the machine load.

    .venv/bin/python benchmarks/couette_friction_map.py [--angles 15,25] [--phi 0.3,0.4,0.5,0.55,0.6] [--mu 0,0.25,0.5]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))

from ktgf.couette.run import Material, to_dataset  # noqa: E402
from ktgf.couette.solver import solve  # noqa: E402
from ktgf.errors import KtgfError  # noqa: E402
from helpers.friction_couette import SCALE, frictional_wall_problem  # noqa: E402


def one(stress: str, mu: float, mean_phi: float, angle: float) -> dict:
    row = {"stress": stress, "mu": mu, "mean_phi": mean_phi, "angle": angle}
    w0, c0 = time.perf_counter(), time.process_time()
    try:
        pr = frictional_wall_problem(mu, mean_phi, angle, stress)
        X, info = solve(pr)
    except KtgfError as exc:
        row.update(converged=False, path="-", message=str(exc).splitlines()[0])
    else:
        ds = to_dataset(pr, X, Material(1.0, SCALE, 0.7))
        row.update(converged=True, path=info["path"], residual=info["residual"], max_phi=ds.attrs["max_phi"],
                   validity=ds.attrs["validity"], budget=ds.attrs["energy_budget_relative_error"],
                   pf_wall=float(pr.terms(X)["p_frictional"][0]))
    row.update(wall=time.perf_counter() - w0, cpu=time.process_time() - c0, load=os.getloadavg()[0])
    return row


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--angles", default="15,25")
    ap.add_argument("--phi", default="0.3,0.4,0.5,0.55,0.6")
    ap.add_argument("--mu", default="0,0.25,0.5")
    ap.add_argument("--stress", default="schaeffer,srivastava-sundaresan")
    a = ap.parse_args()
    vals = lambda s: [float(v) for v in s.split(",")]  # noqa: E731
    print("| stress | μ | δ_w | φ̄ | result | path | wall s | CPU s | load | max φ | p_f,wall/ρ_sV² | validity |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for stress in a.stress.split(","):
        for mu in vals(a.mu):
            for angle in vals(a.angles):
                for phi in vals(a.phi):
                    r = one(stress, mu, phi, angle)
                    if r["converged"]:
                        res = f"converged (res {r['residual']:.1e}, budget {r['budget']:.1e})"
                        tail = f"{r['max_phi']:.4f} | {r['pf_wall']:.3g} | {r['validity']}"
                    else:
                        res, tail = "no solution", f"- | - | {r['message']}"
                    print(f"| {stress} | {mu:g} | {angle:g}° | {phi:g} | {res} | {r['path']} | {r['wall']:.1f} | "
                          f"{r['cpu']:.1f} | {r['load']:.1f} | {tail} |", flush=True)


if __name__ == "__main__":
    main()
