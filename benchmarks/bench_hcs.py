"""Benchmark of the HCS stability map (issue 3 speed targets).

Run:  python benchmarks/bench_hcs.py

Prints: the 4 models x 200 phi x 100 e map end to end (in-process, cold and warm; netCDF write;
local process pool; Dask LocalCluster), the per-point cost, and its ratio to one closure
evaluation on the same (phi, e) arrays; also the per-point cost of the root-finding route.
Aim: the whole map in well under 2 s.
"""

from __future__ import annotations

import statistics
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

N_PHI, N_E = 200, 100


def best_of(fn, repeat=7):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times), statistics.median(times)


def main() -> None:
    t_cold = time.perf_counter()
    from ktgf.closures import PAPER_MODELS, get_model
    from ktgf.hcs import critical_wavenumbers_eig, stability_map

    phi = np.linspace(0.005, 0.6, N_PHI)
    e = np.linspace(0.5, 0.99, N_E)
    stability_map(PAPER_MODELS, phi, e)
    cold = time.perf_counter() - t_cold
    n_points = len(PAPER_MODELS) * N_PHI * N_E

    best, med = best_of(lambda: stability_map(PAPER_MODELS, phi, e))
    models = [get_model(m) for m in PAPER_MODELS]
    phi2, e2 = np.meshgrid(phi, e, indexing="ij")
    c_best, c_med = best_of(lambda: [m.reduced(phi2, e2, check=False) for m in models], repeat=15)

    print(f"stability map, {len(PAPER_MODELS)} models x {N_PHI} phi x {N_E} e = {n_points} states")
    print(f"  cold (imports + first call)          : {cold:8.3f} s")
    print(f"  warm, in-process       best / median : {best * 1e3:8.2f} / {med * 1e3:.2f} ms  "
          f"({n_points / best / 1e6:.2f} M states/s, {best / n_points * 1e9:.0f} ns/state)")
    print(f"  closures alone (same arrays)         : {c_best * 1e3:8.2f} / {c_med * 1e3:.2f} ms  "
          f"({c_best / n_points * 1e9:.0f} ns/state)")
    print(f"  per-point cost / one closure evaluation: {best / c_best:.2f}x")

    with tempfile.TemporaryDirectory() as tmp:
        from ktgf.io import write_netcdf

        ds = stability_map(PAPER_MODELS, phi, e)
        w_best, _ = best_of(lambda: write_netcdf(ds, Path(tmp) / "map.nc"), repeat=3)
        print(f"  map + netCDF write (end to end)      : {(best + w_best) * 1e3:8.2f} ms (write {w_best * 1e3:.1f} ms)")

    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as ex:
        stability_map(PAPER_MODELS, phi, e, executor=ex)  # warm the workers
        p_best, _ = best_of(lambda: stability_map(PAPER_MODELS, phi, e, executor=ex), repeat=3)
    print(f"  ProcessPoolExecutor(2), 32 tasks     : {p_best * 1e3:8.2f} ms (scheduling overhead dominates at this size)")
    try:
        import distributed

        with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cl:
            with distributed.Client(cl) as client:
                stability_map(PAPER_MODELS, phi, e, executor=client)
                d_best, _ = best_of(lambda: stability_map(PAPER_MODELS, phi, e, executor=client), repeat=3)
        print(f"  Dask LocalCluster (threads), 32 tasks: {d_best * 1e3:8.2f} ms")
    except ImportError:
        print("  Dask: distributed not installed")

    # Root-finding on the eigenvalues: the independent route, per state (on a 10 x 10 subset).
    sub_phi, sub_e = np.meshgrid(np.linspace(0.05, 0.5, 10), np.linspace(0.5, 0.99, 10), indexing="ij")
    r = get_model("ret").reduced(sub_phi, sub_e)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r_best, _ = best_of(lambda: critical_wavenumbers_eig(r), repeat=3)
    print(f"  eigenvalue root-finding (scan+brentq): {r_best / sub_phi.size * 1e3:8.3f} ms/state "
          f"({r_best / sub_phi.size / (best / n_points):.0f}x the closed-form map per state)")


if __name__ == "__main__":
    main()
