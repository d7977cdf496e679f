"""Couette benchmark: one planar profile on 200 cells (target < 0.5 s), the closure-heavy cells (sheared χ, frictional
walls) as multiples of it, and the four-model comparison, cold and warm.

Run: ``python benchmarks/bench_couette.py``.
"Cold" is the first call in a fresh process (imports and first-use costs included); "warm"
the best of repeated calls.  The solver is NumPy/SciPy (no JIT), so cold and warm differ only
by import and cache effects.
"""

from __future__ import annotations

import time

T0 = time.perf_counter()
from ktgf.closures import PAPER_MODELS  # noqa: E402
from ktgf.couette import PlanarCell, Wall  # noqa: E402
from ktgf.couette.run import Material, run  # noqa: E402

IMPORT = time.perf_counter() - T0
WALL = Wall(specularity=0.1, restitution=0.9)
CELL = PlanarCell(0.02, 1.0)
MAT = Material(1e-3, 2500.0, 0.9)


def one(model: str = "ret", mean_phi: float = 0.5, n_cells: int = 200):
    return run(model, CELL, WALL, WALL, mean_phi, MAT, n_cells=n_cells)


def frictional_wall_cell():
    """μ 0.5, φ̄ 0.55, Schaeffer stress, JJ walls with δ_w 25° (tests/helpers/friction_couette.py): continuation in
    the wall friction from the naive start; returns the solver's info."""
    from ktgf.closures import get_model
    from ktgf.couette.equations import Problem
    from ktgf.couette.geometry import stretched_nodes
    from ktgf.couette.solver import solve

    model = get_model("frictional", mu=0.5, stress="schaeffer", regularisation=1e-3)
    g = PlanarCell(20.0, 1.0)
    w = Wall(specularity=0.2, restitution=0.85, friction_angle=25.0, slip_regularisation=1e-3)
    x0, x1 = g.bounds(1.0)
    pr = Problem(model, g, w, w, 0.55, 0.7, stretched_nodes(x0, x1, 80, 1.5), v_scale=1.0, stress_scale=2500.0)
    return solve(pr)[1]


def four():
    return [one(m) for m in PAPER_MODELS]


def timed(fn, repeat: int = 1) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main() -> None:
    cold, ds = timed(one)
    warm, ds = timed(one, repeat=5)
    print(f"import ktgf.couette: {IMPORT:.3f} s")
    print(f"one profile (RET, mean phi 0.5, 200 cells): cold {cold:.3f} s, warm {warm:.3f} s "
          f"({1 / warm:.1f} profiles/s; {ds.attrs['solver_iterations']} Newton iterations; target < 0.5 s: "
          f"{'met' if warm < 0.5 else 'NOT met'})")
    for m in PAPER_MODELS:
        t, d = timed(lambda: one(m), repeat=3)
        print(f"  {m:9s} 200 cells: {t:.3f} s ({d.attrs['solver_iterations']} iterations)")
    for n in (100, 400, 800):
        t, _ = timed(lambda: one(n_cells=n), repeat=3)
        print(f"  RET {n:4d} cells: {t:.3f} s ({t / warm:.2f} x the 200-cell time)")
    # the closures dominate here: the sheared χ's five-colour Jacobian (30 stacked profiles) and the frictional
    # closures (Walton friction, Schaeffer stress, wall friction); the cell of docs/friction.md §8
    t, d = timed(lambda: one("dense"), repeat=3)
    print(f"  dense (sheared chi) 200 cells: {t:.3f} s ({t / warm:.2f} x RET; {d.attrs['solver_iterations']} iterations)")
    t, info = timed(frictional_wall_cell)
    print(f"  frictional wall cell (mu 0.5, mean phi 0.55, wall friction 25 deg, 80 cells): {t:.2f} s "
          f"({t / warm:.0f} x RET; {info['iterations']} iterations; 44.3 s CPU before the stacked Jacobian, "
          "7.5 s after, same machine, 8 Dec 2026)")
    c4, _ = timed(four)
    w4, _ = timed(four, repeat=3)
    print(f"four-model comparison (200 cells each): cold {c4:.3f} s, warm {w4:.3f} s")
    from ktgf.data import locate_data_dir

    data_dir, _ = locate_data_dir(None)  # $KTGF_DATA or shared/data beside the repository
    dem = data_dir / "dem_couette_e0.9_phi0.50.csv" if data_dir is not None else None
    if dem is not None and dem.exists():
        from ktgf.couette.compare import compare_with_dem

        t, _ = timed(lambda: compare_with_dem(dem))
        print(f"four-model DEM comparison with per-model specularity calibration: {t:.2f} s")


if __name__ == "__main__":
    main()
