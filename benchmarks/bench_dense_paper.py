"""The dense paper test (model.md §9) as one timed command: RET and Proposed at φ = 0.5, e = 0.7,
boxes of 0.7 L⊥ (16³), 1.5 L⊥ (32³) and 1.3 L∥ (32³), τ = 16, IMEX.

    PYTHONPATH=src python benchmarks/bench_dense_paper.py --precision mixed
    PYTHONPATH=src python benchmarks/bench_dense_paper.py --dim 2 --precision float64   # the CI version

Prints per run: wall and CPU time, the first (compiling) chunk's wall time, steps, wall time per
step, binding step limit, the end/start ratios of K⊥/θ and of the density variance, and the
verdict of tests/solver/test_solver_paper.py (which uses the same :data:`CASES`, :func:`paper_config` and
:func:`verdict`); then the totals and the load average before and after (the machine is shared:
CPU time is the figure that does not depend on the other users).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from typing import Any

#: (relative_to, factor, cells per side in 3D); 2D (CI) uses 16² for all three.
CASES = (("transverse", 0.7, 16), ("transverse", 1.5, 32), ("longitudinal", 1.3, 32))
MODELS = ("ret", "proposed")


def paper_config(model: str, relative_to: str, factor: float, cells: list[int], precision: str = "float64",
                 implicit_tol: float = 1e-6, cfl: float = 0.4, steps_per_call: int = 200) -> Any:
    """The run config of one box of the paper test (seeded random perturbation of the lowest modes)."""
    from ktgf.solver.config import parse_config

    return parse_config({
        "model": {"name": model, "restitution": 0.7},
        "initial": {"solid_fraction": 0.5, "temperature": 1e-4, "amplitude": 3e-4, "max_mode": 1, "seed": 3},
        "grid": {"cells": cells, "relative_to": relative_to, "factor": factor},
        "time": {"end": 16.0, "unit": "tau", "outputs": 4, "scheme": "imex", "max_steps_per_call": steps_per_call},
        "numerics": {"precision": precision, "implicit_tol": implicit_tol, "cfl": cfl},
    })


def verdict(relative_to: str, factor: float, kperp: float, var: float) -> str:
    """'pass' or what failed, for the end/start ratios of K⊥/θ and of the density variance."""
    if factor < 1.0:
        ok, want = kperp < 1e-3 and var < 1e-3, "homogeneous (both ratios < 1e-3)"
    elif relative_to == "transverse":
        ok, want = kperp > 1e2 and var < 0.5, "vortices only (K_perp ratio > 1e2, variance ratio < 0.5)"
    else:
        ok, want = kperp > 1e2 and var > 5.0, "vortices and clusters (ratios > 1e2 and > 5)"
    return "pass" if ok else f"FAIL: expected {want}"


def run_case(model: str, relative_to: str, factor: float, cells: list[int], **numerics: Any) -> dict[str, Any]:
    """Run one box; wall/CPU times, steps, binding limit, growth ratios and verdict."""
    from ktgf.closures.coefficients import mean_free_path
    from ktgf.solver.run import Simulation

    sim = Simulation(paper_config(model, relative_to, factor, cells, **numerics))
    marks: list[float] = []
    t0, c0 = time.perf_counter(), time.process_time()
    ds = sim.run(progress=False, write_files=False, on_chunk=lambda _: marks.append(time.perf_counter()))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    kperp = (ds.ke_transverse / ds.theta_mean).values
    var = ds.density_variance.values
    out = {
        "model": model, "box": f"{factor} L_{'perp' if relative_to == 'transverse' else 'par'}",
        "cells": "x".join(map(str, cells)), "dx_mfp": float(sim.grid.spacing[0] / mean_free_path(0.5, sim.phys.diameter)),
        "wall_s": wall, "cpu_s": cpu, "first_chunk_s": marks[0] - t0,  # compilation + the first chunk's steps
        "steps": int(sim.steps), "ms_per_step": ds.attrs["wall_time_per_step_s"] * 1e3,
        "binding": ds.attrs["binding_step_limit"],
        "kperp_ratio": float(kperp[-1] / kperp[0]), "var_ratio": float(var[-1] / var[0]),
    }
    out["verdict"] = verdict(relative_to, factor, out["kperp_ratio"], out["var_ratio"])
    return out


def _load() -> str:
    return "%.1f %.1f %.1f" % os.getloadavg()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--precision", default="mixed", choices=("float64", "float32", "mixed"))
    ap.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    ap.add_argument("--cases", nargs="+", type=int, default=[0, 1, 2], help="indices into CASES")
    ap.add_argument("--dim", type=int, default=3, choices=(2, 3))
    ap.add_argument("--implicit-tol", type=float, default=1e-6)
    ap.add_argument("--cfl", type=float, default=0.4)
    ap.add_argument("--steps-per-call", type=int, default=200)
    ap.add_argument("--json", help="append the rows (and the settings) to this JSON-lines file")
    args = ap.parse_args()
    settings = {"precision": args.precision, "implicit_tol": args.implicit_tol, "cfl": args.cfl,
                "steps_per_call": args.steps_per_call}
    print("settings", settings, "dim", args.dim, "| load average at start", _load(), flush=True)
    rows, t0, c0 = [], time.perf_counter(), time.process_time()
    for model in args.models:
        for i in args.cases:
            rel, factor, n = CASES[i]
            cells = [16] * 2 if args.dim == 2 else [n] * 3
            load = _load()
            r = run_case(model, rel, factor, cells, **settings)
            r["load_before"], r["load_after"] = load, _load()
            rows.append(r)
            print(f"{r['model']:9s} {r['box']:9s} {r['cells']:9s} dx={r['dx_mfp']:.2f} l  wall {r['wall_s']:7.1f} s  "
                  f"CPU {r['cpu_s']:7.1f} s  first chunk {r['first_chunk_s']:6.1f} s  {r['steps']:5d} steps  "
                  f"{r['ms_per_step']:6.1f} ms/step  binding {r['binding']:10s}  K_perp/theta x{r['kperp_ratio']:.3g}  "
                  f"var x{r['var_ratio']:.3g}  {r['verdict']}  (load {r['load_before']} -> {r['load_after']})",
                  flush=True)
            if args.json:
                with open(args.json, "a") as f:
                    f.write(json.dumps({**settings, "dim": args.dim, **r}) + "\n")
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    bad = [r for r in rows if r["verdict"] != "pass"]
    print(f"TOTAL {len(rows)} runs: wall {wall:.1f} s ({wall / 60:.2f} min), CPU {cpu:.1f} s, "
          f"{'all pass' if not bad else f'{len(bad)} FAIL'} | load average at end {_load()}", flush=True)


if __name__ == "__main__":
    import jax

    jax.config.update("jax_enable_x64", True)
    main()
