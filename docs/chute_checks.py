"""Reproduce the numbers of docs/chute.md: force balance, first integral and grid convergence of the chute.

Run from the repository root:  python docs/chute_checks.py
"""

from __future__ import annotations

import math
import time

import numpy as np

from ktgf.closures import list_models
from ktgf.couette.chute import solve_chute
from ktgf.couette.run import Material

MAT = Material(d=1e-3, rho_s=2500.0, e=0.9)
ANGLE, DEPTH, MEAN_PHI = 19.0, 0.03, 0.3
TAN = math.tan(math.radians(ANGLE))


def first_integral_error(ds):
    r = np.abs(ds["shear_stress"].values - TAN * (ds["p"].values - ds["p"].values[-1])) / (TAN * ds["p"].values[0])
    return float(r[1:-1].max())


print("| model | base traction / weight − 1 | (p(0) − p(H)) / weight − 1 | energy budget | p(H)/p(0) | u(H) [m/s] | first integral (64 cells) | solve [s] |")
print("|---|---|---|---|---|---|---|---|")
for m in list_models():
    t0 = time.perf_counter()
    ds = solve_chute(m, depth=DEPTH, angle_deg=ANGLE, mean_phi=MEAN_PHI, material=MAT, n_cells=64)
    dt = time.perf_counter() - t0
    a = ds.attrs
    w = MAT.rho_s * 9.81 * a["solid_depth"]
    tr = ds["wall_shear_stress"].values[0] / (w * math.sin(math.radians(ANGLE))) - 1
    pn = (ds["p"].values[0] - ds["p"].values[-1]) / (w * math.cos(math.radians(ANGLE))) - 1
    print(f"| {m.name} | {tr:.1e} | {pn:.1e} | {a['energy_budget_relative_error']:.1e} | {a['top_pressure_fraction']:.3f} | "
          f"{a['surface_velocity']:.3f} | {first_integral_error(ds):.1e} | {dt:.2f} |")

print()
for name in ("ret", "visc-div"):
    runs = {n: solve_chute(name, depth=DEPTH, angle_deg=ANGLE, mean_phi=MEAN_PHI, material=MAT, n_cells=n)
            for n in (16, 32, 64, 128, 256)}
    print(f"{name}: first-integral error (interior nodes) per grid:",
          {n: f"{first_integral_error(d):.2e}" for n, d in runs.items()})
    for f in ("u", "theta", "phi"):
        ref = runs[256][f].values
        e = [np.abs(runs[n][f].values - ref[:: 256 // n]).max() / np.abs(ref).max() for n in (16, 32, 64, 128)]
        print(f"  {f}: errors vs 256 cells {['%.2e' % x for x in e]}, observed orders {np.round(np.log2(np.array(e[:-1]) / np.array(e[1:])), 2)}")

print()
print("Depth series at fixed mean phi (continuation from the previous depth, H x 1.25):")
for name in ("enskog", "ret", "visc-div"):
    ds, rows = None, []
    H = 30.0
    while H < 120.0:
        try:
            ds = solve_chute(name, depth=H * 1e-3, angle_deg=ANGLE, mean_phi=MEAN_PHI, material=MAT,
                             n_cells=int(max(64, 2 * H)), start=ds)
        except Exception as exc:  # report where the branch is lost
            print(f"  {name}: no convergence at H = {H:.1f} d ({type(exc).__name__})")
            break
        mid = ds.sizes["y"] // 2
        rows.append((H, ds.attrs["surface_velocity"], float(ds["phi"][mid]), ds.attrs["top_pressure_fraction"]))
        H *= 1.25
    r = np.array(rows)
    slopes = np.diff(np.log(r[:, 1])) / np.diff(np.log(r[:, 0]))
    print(f"  {name}: H/d {np.round(r[:, 0], 1)}; u(H) {np.round(r[:, 1], 3)} m/s; phi(H/2) {np.round(r[:, 2], 3)}; "
          f"p(H)/p(0) {np.round(r[:, 3], 3)}; d ln u(H)/d ln H {np.round(slopes, 3)}")
