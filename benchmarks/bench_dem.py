"""Benchmark of one `ktgf dem shear` state (issue 32 target: 864 spheres at φ 0.5 in < 3 min on one core).

Run:  python benchmarks/bench_dem.py [--e 0.9] [--mu 0] [--strain 10]

Runs one seed of N = 864, φ = 0.5 (strain 10, 2 discarded, f_c = 0.01, 50 steps per contact) in a
fresh folder and prints the wall time, the CPU time of the LAMMPS process (getrusage of children), its
"Loop time" (wall), the time steps and the CPU time per particle step.  LAMMPS runs single-process (one MPI rank, OMP_NUM_THREADS=1).
The restitution calibration is excluded (done first, cached).
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--e", type=float, default=0.9)
    ap.add_argument("--mu", type=float, default=0.0)
    ap.add_argument("--phi", type=float, default=0.5)
    ap.add_argument("--strain", type=float, default=10.0)
    args = ap.parse_args()

    from ktgf.dem import ShearRun, calibrate_restitution, find_lammps, run_shear

    lmp = find_lammps()
    t = time.perf_counter()
    rest = calibrate_restitution(args.e, 50.0, lammps=lmp, use_cache=False)
    t_cal = time.perf_counter() - t
    run = ShearRun(phi=args.phi, e=args.e, mu=args.mu, particles=864, seed=1, strain=args.strain, skip=2.0)
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        res = run_shear(run, Path(tmp), lammps=lmp)
        wall = time.perf_counter() - t
    steps = round(args.strain / res["dt"])
    print(json.dumps({
        "lammps": lmp.version, "phi": args.phi, "e": args.e, "mu": args.mu, "N": 864, "strain": args.strain,
        "restitution_calibration_seconds": round(t_cal, 2), "restitution_error": rest.mean_error,
        "state_wall_seconds": round(wall, 1), "lammps_cpu_seconds": round(res["cpu_seconds"], 1),
        "lammps_loop_wall_seconds": round(res["lammps_loop_seconds"], 1),
        "time_steps": steps, "microseconds_per_particle_step": round(1e6 * res["cpu_seconds"] / steps / 864, 3),
        "t_c": res["t_c"], "dt": res["dt"], "target_seconds": 180,
    }, indent=1))


if __name__ == "__main__":
    main()
