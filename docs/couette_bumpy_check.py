"""Tables of docs/dense.md §5.1 and docs/dense_physics.md §6: Couette cells between bumpy walls against the DEM.

    PYTHONPATH=src python docs/couette_bumpy_check.py [--cells 100]

The Couette file is validation: the wall geometry comes from its header, e_w = e, nothing is fitted to it
(the Johnson–Jackson rows fit the specularity to the DEM slip, as ``ktgf couette compare`` does).
Table 1: every model between bumpy walls on the layer of the centres (``compare_with_dem(wall="bumpy")``).
Table 2: the same walls with the continuum cell ending at other planes (same particles), to show how much the
wall stresses depend on where the continuum cell ends.  Table 3: Johnson–Jackson walls fitted to the slip, on
the slab to the tangent planes (the default) and on the layer of the centres.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

from ktgf.couette.compare import bumpy_dem_case, calibrate_specularity, compare_with_dem, dem_bumpy_wall, dem_cell
from ktgf.data import read_couette, shipped_data_dir

MODELS = ("dense", "proposed", "ret", "enskog", "visc-div")


def _row(label: str, ds, dem) -> str:
    tau = float(np.mean(np.abs(ds["wall_shear_stress"].values)))
    p = float(ds["p"].values[0])
    th = np.interp(dem.y, ds["y"].values, ds["theta"].values) / dem.theta - 1.0
    centre = int(np.argmin(np.abs(dem.y)))
    ratio = tau / p / (dem.tau_wall / dem.p_wall) - 1.0
    u1 = float(np.mean(np.abs(np.interp(dem.y[[0, -1]], ds["y"].values, ds["u"].values))))
    return (f"| {label} | {tau / dem.tau_wall - 1:+.1%} | {p / dem.p_wall - 1:+.1%} | {ratio:+.1%} | "
            f"{0.5 * (th[0] + th[-1]):+.1%} | {th[centre]:+.1%} | {u1:.2f} | {float(ds.attrs['max_phi']):.3f} | "
            f"{bool(ds.attrs['physically_valid'])} |")


HEAD = ("| {} | err τ_w | err p_w | err τ/p | err θ first bin | err θ centre | u first bin (DEM {:.2f}) | max φ | valid |\n"
        "|---|---|---|---|---|---|---|---|---|")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cells", type=int, default=100)
    n = ap.parse_args().cells
    path = shipped_data_dir() / "dem_couette_e0.9_phi0.50.csv"
    dem = read_couette(path)
    wall = dem_bumpy_wall(dem.case)
    cell = bumpy_dem_case(dem.case, wall)
    u_dem = dem.slip_speed()

    t0, c0 = time.time(), time.process_time()
    _, extra = compare_with_dem(path, MODELS, n_cells=n, wall="bumpy")
    print(f"Table 1: bumpy walls, layer of the centres (gap {cell.gap:.4f} d, mean phi {cell.mean_phi:.4f}); "
          f"{time.time() - t0:.1f} s wall, {time.process_time() - c0:.1f} s CPU\n")
    print(HEAD.format("model", u_dem))
    for name in MODELS:
        print(_row(name, extra["datasets"][name], dem))

    t0, c0 = time.time(), time.process_time()
    half_h = dem.case.gap / 2 + 0.5
    planes = (("tangent planes (wall-sphere tops)", half_h - 0.5 * wall.wall_sphere_diameter),
              ("resting centre over a hollow, H/2 − h (as table 1)", half_h - wall.spheres.resting_height),
              ("contact over a saddle, H/2 − σ cos θ_w", half_h - wall.spheres.sigma * math.cos(wall.spheres.bumpiness)),
              ("contact on top of a wall sphere, H/2 − σ", half_h - wall.spheres.sigma))
    print("\nTable 2: bumpy walls, the continuum cell ending at other planes (same particles)\n")
    print(HEAD.format("cell ends at y = ± … d / model", u_dem))
    for label, half in planes:
        case = dataclasses.replace(dem.case, gap=2 * half, mean_phi=dem.case.mean_phi * dem.case.gap / (2 * half))
        for name in ("dense", "proposed", "ret"):
            ds = dem_cell(math.nan, name, case, n_cells=n, wall=wall)
            print(_row(f"{label}: {half:.3f} (mean φ {case.mean_phi:.4f}) / {name}", ds, dem))
    print(f"\n({time.time() - t0:.1f} s wall, {time.process_time() - c0:.1f} s CPU)")

    t0, c0 = time.time(), time.process_time()
    print("\nTable 3: Johnson–Jackson walls, e_w = e, specularity fitted to the DEM slip\n")
    print(HEAD.format("cell / model (φ')", u_dem))
    for label, case in (("tangent planes", dem.case), ("layer of the centres", cell)):
        for name in ("dense", "proposed", "ret"):
            spec, ds = calibrate_specularity(name, dataclasses.replace(dem, case=case), n_cells=n)
            print(_row(f"{label} / {name} ({spec:.3g})", ds, dem))
    print(f"\n({time.time() - t0:.1f} s wall, {time.process_time() - c0:.1f} s CPU)")


if __name__ == "__main__":
    main()
