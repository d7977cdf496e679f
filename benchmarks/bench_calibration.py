"""Calibration benchmark: 2-parameter fits on the shared uniform-shear file (target < 10 s) and on the Couette file (< 2 min);
leave-one-state-out cross-validation of a 3-parameter fit on the shared uniform-shear files (< 30 s); prediction bands
against the prediction (< 2x).

Run: ``.venv/bin/python benchmarks/bench_calibration.py [DATA_DIR] [fits|crossval|bands ...]`` (default folder:
``ktgf.data.locate_data_dir``; default parts: all).
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
TARGETS = {"uniform shear": 10.0, "couette": 120.0, "cross-validation": 30.0, "band/prediction": 2.0}


def timed(fn):
    w, c = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - w, time.process_time() - c, out


def main() -> None:
    args = sys.argv[1:]
    parts = [a for a in args if a in ("fits", "crossval", "bands")] or ["fits", "crossval", "bands"]
    rest = [a for a in args if a not in parts]
    folder = Path(rest[0]) if rest else locate_data_dir(None)[0]
    if folder is None:
        sys.exit("no DEM data folder (give it as the first argument)")
    print(f"import {IMPORT:.2f} s; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    for part in parts:
        {"fits": fits, "crossval": crossval, "bands": bands}[part](folder)


def crossval(folder: Path) -> None:
    """Full fit + leave-one-out refits of dense's phi_f, phi_c, beta on dem_uniform_shear.csv + _extra.csv (7 states)."""
    from ktgf.calibration.crossval import cross_validate

    data = [read_data(folder / "dem_uniform_shear.csv"), read_data(folder / "dem_uniform_shear_extra.csv")]
    for model, names in (("dense", ["phi_f", "phi_c", "beta"]), ("proposed", ["phi_f", "phi_c", "beta"]), ("dense", ["beta"])):
        for run in ("cold", "warm"):
            wall, cpu, cv = timed(lambda: cross_validate(get_model(model), data, names))
            ok = "OK" if wall < TARGETS["cross-validation"] else "SLOW"
            evals = sum(r["evaluations"] for r in cv.refits)
            print(f"cross-validation {model:9s} {','.join(names):18s} {run}: wall {wall:6.2f} s, CPU {cpu:6.2f} s "
                  f"(target {TARGETS['cross-validation']:g} s: {ok}); {len(cv.refits)} refits, {evals} evaluations, "
                  f"{len(cv.summary()['failed_refits'])} not converged; mean |error| left out {100 * cv.mean_abs_error:.2f} %, "
                  f"in sample {100 * cv.mean_abs_in_sample_error:.2f} %; load {os.getloadavg()[0]:.2f}")


def bands(folder: Path) -> None:
    """±1σ of ktgf shear's columns (delta method) against the prediction itself: in one process (cold = first call)
    for both Jacobians, then whole commands (`ktgf shear` with and without a model file's band) in new processes."""
    import subprocess
    import tempfile

    import numpy as np

    from ktgf.calibration.bands import _JACOBIANS, shear_bands
    from ktgf.calibration.model_file import fit_text
    from ktgf.cli.shear import shear_rows

    data = [read_data(folder / "dem_uniform_shear.csv"), read_data(folder / "dem_uniform_shear_extra.csv")]
    fit = calibrate(get_model("dense"), data, ["phi_c", "beta"])
    model, cov = fit.model, fit.covariance
    for method in ("differences", "jax"):
        for n_phi in (10, 1000):
            phi, e = np.linspace(0.3, 0.6, n_phi), np.array([0.7, 0.9])
            for run in ("cold", "warm"):
                if run == "cold":
                    _JACOBIANS.clear()
                wp, cp, _ = timed(lambda: shear_rows(model, phi, e))
                wb, cb, (_, used) = timed(lambda: shear_bands(model, fit.names, cov, phi, e, method=method))
                ok = "OK" if cb < TARGETS["band/prediction"] * cp else "SLOW"
                print(f"band {n_phi * e.size:5d} points {run:4s}: prediction wall {wp:7.4f} s CPU {cp:7.4f} s; band ({used}) wall "
                      f"{wb:7.4f} s CPU {cb:7.4f} s; band/prediction CPU {cb / cp:6.2f} (target < {TARGETS['band/prediction']:g}: "
                      f"{ok}); load {os.getloadavg()[0]:.2f}")
    from ktgf.calibration.bands import couette_bands
    from ktgf.couette.compare import compare_with_dem

    dem_file = folder / "dem_couette_e0.9_phi0.50.csv"
    for n_cells in (100, 200):
        wp, cp, (rows, _) = timed(lambda: compare_with_dem(dem_file, [model], n_cells=n_cells))
        wb, cb, sd = timed(lambda: couette_bands(model, fit.names, cov, read_data(dem_file), specularity=rows[0]["specularity"],
                                                 slip_fitted=True, n_cells=n_cells))
        ok = "OK" if cb < TARGETS["band/prediction"] * cp else "SLOW"
        print(f"couette band, {n_cells} cells: prediction (specularity fitted to the slip) wall {wp:6.2f} s CPU {cp:6.2f} s; "
              f"band wall {wb:6.2f} s CPU {cb:6.2f} s; band/prediction CPU {cb / cp:5.2f} ({ok}); tau_wall {rows[0]['tau_wall']:.4g} "
              f"+- {sd['tau_wall']:.2g}, p {rows[0]['p']:.4g} +- {sd['p']:.2g}; load {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as tmp:
        mf = Path(tmp) / "dense-fit.toml"
        mf.write_text(fit_text(fit))
        base = [sys.executable, "-m", "ktgf", "shear", "--phi", "0.3:0.6:10", "--e", "0.7,0.9", "--format", "csv"]
        runs = [("prediction only (--model dense-fit values via -O)", base + ["--model", "dense", "-O", f"phi_c={float(fit.values[0])!r}",
                                                                             "-O", f"beta={float(fit.values[1])!r}"]),
                ("with band, --band-jacobian differences", base + ["--model-file", str(mf), "--band-jacobian", "differences"]),
                ("with band, --band-jacobian jax", base + ["--model-file", str(mf), "--band-jacobian", "jax"])]
        for label, cmd in runs:
            t0, c0 = time.perf_counter(), os.times()
            subprocess.run(cmd, check=True, capture_output=True)
            c1 = os.times()
            print(f"command {label}: wall {time.perf_counter() - t0:6.2f} s, CPU {c1.children_user - c0.children_user + c1.children_system - c0.children_system:6.2f} s")


def fits(folder: Path) -> None:
    """The 2-parameter fits: uniform shear and Couette."""
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
