"""Calibration benchmark: 2-parameter fits on the shared uniform-shear file (target < 10 s) and on the Couette file (< 2 min).

Run: ``.venv/bin/python benchmarks/bench_calibration.py [DATA_DIR]`` (default: ``ktgf.data.locate_data_dir``).
Each fit is timed cold (first in the process: JAX import and compilation included) and warm
(the same fit again: the compiled uniform-shear Jacobian is reused) and "warm, recompiled" (the
cache emptied first: the cost of every fit before that cache); wall and CPU time and the machine's load average are printed, since the
machine is shared.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

T0 = time.perf_counter()
from ktgf import get_model  # noqa: E402
from ktgf.calibration import calibrate, read_data  # noqa: E402
from ktgf.calibration.residuals import _SHEAR_JACOBIANS  # noqa: E402
from ktgf.data import locate_data_dir  # noqa: E402

IMPORT = time.perf_counter() - T0
TARGETS = {"uniform shear": 10.0, "couette": 120.0}


def timed(fn):
    w, c = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - w, time.process_time() - c, out


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else locate_data_dir(None)[0]
    if folder is None:
        sys.exit("no DEM data folder (give it as the first argument)")
    print(f"import {IMPORT:.2f} s; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    cases = [
        ("uniform shear", "visc-div", ["phi_c", "beta"], [folder / "dem_uniform_shear.csv"], {}),
        ("uniform shear", "proposed", ["phi_c", "beta"], [folder / "dem_uniform_shear.csv"], {}),
        ("couette", "proposed", ["specularity", "beta"], [folder / "dem_couette_e0.9_phi0.50.csv"], {"n_cells": 100}),
        ("couette", "proposed", ["specularity", "beta"], [folder / "dem_couette_e0.9_phi0.50.csv"], {"n_cells": 200}),
    ]
    for kind, model, names, files, kw in cases:
        data = [read_data(f) for f in files]
        for run in ("cold", "warm") + (("warm, recompiled",) if kind == "uniform shear" else ()):
            if run == "warm, recompiled":  # what every fit cost before the compiled Jacobians were cached
                _SHEAR_JACOBIANS.clear()
            wall, cpu, fit = timed(lambda: calibrate(get_model(model), data, names, **kw))
            ok = "OK" if wall < TARGETS[kind] else "SLOW"
            vals = ", ".join(f"{n}={v:.5g}±{s:.2g}" for n, v, s in zip(fit.names, fit.values, fit.stderr))
            print(f"{kind:13s} {model:9s} {','.join(names):18s} {str(kw):16s} {run}: wall {wall:6.2f} s, CPU {cpu:6.2f} s "
                  f"(target {TARGETS[kind]:g} s: {ok}); {fit.evaluations} evaluations, cost {fit.cost:.4g}; {vals}; "
                  f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
