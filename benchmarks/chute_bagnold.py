"""Deep inclined layers (Bagnold regime) in the 3D solver against the 1D inclined-layer solver.

Run from the repository root.  Four commands:

``python benchmarks/chute_bagnold.py oned [--angle 18]``
    The 1D solver (:func:`ktgf.couette.chute.solve_chute`) alone: the local depth exponent
    d ln u(H)/d ln H over H = 10 … 280 d, the bulk profile against Bagnold's shape
    u ∝ H^{3/2} − (H − y)^{3/2}, the uniform-shear stress-ratio range that decides whether the
    model has a Bagnold interior at the angle at all, and the 1D solver's own error at the
    3D grid's resolution.

``python benchmarks/chute_bagnold.py run --depth 90 --angle 18 [--cells-per-d 1] [--thin] [--scheme imex]``
    One 3D run of the chute (RET, φ̄ 0.3, bumpy base, zero-flux lid, IMEX unless ``--scheme``) to steady state
    (``time.steady_tol`` 1e-4) from a sheared start scaled with Bagnold's law from the 10 d
    example (``tests/helpers/chute_case.bagnold_case``: γ̇0 = 100/s (H/10d)^{1/2}, θ0 = 0.03 m²/s² (H/10d),
    not the 1D answer), checkpointed into the folder ``chute_bagnold_<H>d``, then ``summarize``.
    ``--thin``: a 4 × N × 4 box instead of the 1D grid.

``python benchmarks/chute_bagnold.py summarize FOLDER …``
    A run's last checkpoint (finished or not) against the 1D solver on 4 cells per d: profile
    errors (u, φ, θ), u(H), steps, time reached, the last steady change, wall/CPU time and load;
    written to ``FOLDER/bagnold.json``.

``python benchmarks/chute_bagnold.py report FOLDER …``
    The table of the summarized runs and the depth exponent between them, 3D against 1D and 3/2.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from helpers.chute_case import bagnold_case  # noqa: E402

from ktgf.closures import get_model  # noqa: E402
from ktgf.couette.chute import solve_chute  # noqa: E402
from ktgf.couette.run import Material  # noqa: E402
from ktgf.shear.steady import steady_shear  # noqa: E402

MAT = Material(d=1e-3, rho_s=2500.0, e=0.9)
MEAN_PHI = 0.3


def bagnold_shape_error(y: np.ndarray, u: np.ndarray, H: float, lo: float = 0.25, hi: float = 0.75) -> float:
    """Max |u − fit|/u(H) over lo·H < y < hi·H of the least-squares fit u = a + b(H^{3/2} − (H − y)^{3/2})."""
    m = (y > lo * H) & (y < hi * H)
    A = np.stack([np.ones(m.sum()), H**1.5 - (H - y[m]) ** 1.5], axis=1)
    coef, *_ = np.linalg.lstsq(A, u[m], rcond=None)
    return float(np.max(np.abs(A @ coef - u[m])) / u[-1])


def oned(angle: float) -> None:
    model = get_model("ret")
    ratios = [float(steady_shear(model, p, MAT.e).tau_over_p) for p in np.linspace(0.002, 0.6, 300)]
    print(f"RET e = {MAT.e}: uniform-shear |P_xy|/p spans {min(ratios):.4f} … {max(ratios):.4f}, i.e. a local "
          f"Bagnold balance exists for {math.degrees(math.atan(min(ratios))):.2f}° … "
          f"{math.degrees(math.atan(max(ratios))):.2f}°; tan {angle:g}° = {math.tan(math.radians(angle)):.4f}")
    print(f"\nDepth series at {angle:g}°, φ̄ {MEAN_PHI} (continuation, H × 1.25, max(256, 2H) cells):")
    print("| H/d | u(H) [m/s] | d ln u(H)/d ln H | φ bulk (0.25–0.75 H) | max φ | p(H)/p(0) | Bagnold-shape error |")
    print("|---|---|---|---|---|---|---|")
    ds, H, prev = None, 10.0, None
    while H < 300.0:
        try:
            ds = solve_chute("ret", depth=H * MAT.d, angle_deg=angle, mean_phi=MEAN_PHI, material=MAT,
                             n_cells=int(max(256, 2 * H)), start=ds)
        except Exception as exc:  # where the branch is lost
            print(f"| {H:.1f} | no convergence ({type(exc).__name__}) | | | | | |")
            break
        y, u, phi = ds["y"].values / MAT.d, ds["u"].values, ds["phi"].values
        uh = ds.attrs["surface_velocity"]
        slope = "" if prev is None else f"{math.log(uh / prev[1]) / math.log(H / prev[0]):.4f}"
        m = (y > 0.25 * H) & (y < 0.75 * H)
        print(f"| {H:.1f} | {uh:.3f} | {slope} | {phi[m].min():.3f}–{phi[m].max():.3f} | {phi.max():.3f} | "
              f"{ds.attrs['top_pressure_fraction']:.3f} | {bagnold_shape_error(y, u, H):.4f} |", flush=True)
        prev, H = (H, uh), H * 1.25
    print("\n1D solver at the 3D resolution against 512 cells (max rel. error; u relative to u(H)):")
    for H in (10.0, 20.0, 90.0):
        ref = solve_chute("ret", depth=H * MAT.d, angle_deg=angle, mean_phi=MEAN_PHI, material=MAT, n_cells=512)
        for cpd in (0.5, 1.0, 2.0, 3.2):
            n = int(round(cpd * H))
            if n < 8:  # the 1D solver's minimum
                continue
            ds = solve_chute("ret", depth=H * MAT.d, angle_deg=angle, mean_phi=MEAN_PHI, material=MAT, n_cells=n)
            err = {k: profile_error(ds["y"].values, ds[k].values, ref, k) for k in ("u", "phi", "theta")}
            print(f"  H = {H:g} d, {cpd:g} cells/d ({n}): " + ", ".join(f"{k} {v:.2e}" for k, v in err.items()))


def profile_error(y: np.ndarray, v: np.ndarray, ref, k: str) -> float:
    r = np.interp(y, ref["y"].values, ref[k].values)
    return float(np.max(np.abs(v - r)) / np.max(np.abs(r))) if k == "u" else float(np.max(np.abs(v / r - 1.0)))


def run(depth: float, angle: float, cells_per_d: float, thin: bool, folder: Path, scheme: str = "imex") -> dict:
    """One 3D run to steady state, checkpointed into ``folder``; then :func:`summarize`."""
    from ktgf.solver.config import parse_config
    from ktgf.solver.run import Simulation

    cfg = bagnold_case(depth, angle, cells_per_d, thin, scheme)
    cfg["output"].update(directory=str(folder), checkpoint_every=5)
    sim = Simulation(parse_config(cfg))
    t0, c0 = time.perf_counter(), time.process_time()
    sim.run(progress=False, write_files=True, overwrite=True)
    timing = {"wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0,
              "load_avg_end": list(os.getloadavg())}
    (folder / "timing.json").write_text(json.dumps(timing))
    return summarize(folder)


def summarize(folder: Path) -> dict:
    """The comparison of a run's last checkpoint (finished or not) with the 1D solver on 4 cells per d."""
    from ktgf.solver.config import parse_config
    from ktgf.solver.cases.chute import chute_reference, compare_chute
    from ktgf.solver.io import load_checkpoint
    from ktgf.solver.run import Simulation

    ck = load_checkpoint(folder / "checkpoint.npz")
    cfg = json.loads(ck["config"])
    sim = Simulation(parse_config(cfg))
    h = ck["history"]
    depth = float(cfg["grid"]["length_d"][0] if isinstance(cfg["grid"]["length_d"], list) else cfg["grid"]["length_d"])
    fine = int(4 * depth)  # 4 cells per d: the 1D solver's own θ error is then below 1e-2 (oned)
    cmp = compare_chute(h, sim.phys, sim.grid, sim.phi0, n_cells=fine)
    u = np.asarray(h["u_profile"][-1])
    change = sim.case.steady_change(h)
    timing = json.loads((folder / "timing.json").read_text()) if (folder / "timing.json").exists() else {}
    ref = chute_reference(sim.phys, sim.grid, sim.phi0, n_cells=fine)
    result = {
        "depth_d": depth, "angle_deg": cfg["case"]["inclination_deg"], "cells": cfg["grid"]["cells"],
        "t_s": float(ck["t"]), "t_cap_s": cfg["time"]["end"], "steps": int(ck["steps"]),
        "steady": change is not None and change < cfg["time"]["steady_tol"], "last_change": change,
        **timing, "load_avg_now": list(os.getloadavg()),
        "u_surface_3d": float(1.5 * u[-1] - 0.5 * u[-2]), "u_surface_1d": float(ref["u"].values[-1]),
        "reference_cells": fine, "max_rel_error": cmp["max_rel_error"],
        "base_shear_stress_Pa": cmp["base_shear_stress_Pa"],
    }
    (folder / "bagnold.json").write_text(json.dumps(result, indent=1))
    print(json.dumps(result, indent=1))
    return result


def report(files: list[str]) -> None:
    rows = sorted((json.loads((Path(f) / "bagnold.json").read_text()) for f in files), key=lambda r: r["depth_d"])
    print("| H/d | cells | steady | t [s] | steps | wall [s] | CPU [s] | load | u(H) 3D | u(H) 1D | err u | err φ | err θ |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        e = r["max_rel_error"]
        wall, cpu, load = (r.get(k, math.nan) for k in ("wall_s", "cpu_s", "load_avg_end"))
        print(f"| {r['depth_d']:g} | {'×'.join(map(str, r['cells']))} | {r['steady']} | {r['t_s']:.1f} | "
              f"{r['steps']} | {wall:.0f} | {cpu:.0f} | {load[1] if isinstance(load, list) else load:.1f} | "
              f"{r['u_surface_3d']:.4f} | {r['u_surface_1d']:.4f} | {e['u']:.2e} | {e['phi']:.2e} | {e['theta']:.2e} |")
    steady = [r for r in rows if r["steady"]]  # the exponent between steady runs on the same spacing
    for a, b in zip(steady, steady[1:]):
        if b["depth_d"] == a["depth_d"] or abs(b["cells"][0] / b["depth_d"] - a["cells"][0] / a["depth_d"]) > 0.05:
            continue
        dl = math.log(b["depth_d"] / a["depth_d"])
        s3 = math.log(b["u_surface_3d"] / a["u_surface_3d"]) / dl
        s1 = math.log(b["u_surface_1d"] / a["u_surface_1d"]) / dl
        print(f"H {a['depth_d']:g} → {b['depth_d']:g} d: d ln u(H)/d ln H 3D {s3:.4f}, 1D {s1:.4f}, "
              f"3D − 1D {s3 - s1:+.4f}, 3D − 3/2 {s3 - 1.5:+.4f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    o = sub.add_parser("oned")
    o.add_argument("--angle", type=float, default=18.0)
    r = sub.add_parser("run")
    r.add_argument("--depth", type=float, required=True)
    r.add_argument("--angle", type=float, default=18.0)
    r.add_argument("--cells-per-d", type=float, default=1.0)
    r.add_argument("--thin", action="store_true")
    r.add_argument("--scheme", choices=("imex", "ssprk3", "auto"), default="imex")
    r.add_argument("--out", type=Path, default=None, help="run folder (default chute_bagnold_<H>d[_thin])")
    c = sub.add_parser("summarize")
    c.add_argument("folders", nargs="+", type=Path)
    p = sub.add_parser("report")
    p.add_argument("folders", nargs="+")
    a = ap.parse_args()
    if a.cmd == "oned":
        oned(a.angle)
    elif a.cmd == "run":
        run(a.depth, a.angle, a.cells_per_d, a.thin,
            a.out or Path(f"chute_bagnold_{a.depth:g}d{'_thin' if a.thin else ''}"), a.scheme)
    elif a.cmd == "summarize":
        for f in a.folders:
            summarize(f)
    else:
        report(a.folders)


if __name__ == "__main__":
    main()
