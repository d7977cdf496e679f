"""Run ktgf and OpenFOAM twoPhaseEulerFoam on the same 3D cooling box; time both end to end and compare θ(t).

    apt-get install openfoam       # Debian (v1912): the runner sources /usr/share/openfoam/etc/bashrc itself
    PYTHONPATH=src python benchmarks/openfoam/run_compare.py              # 32³, benchmarks/openfoam/cooling_box.toml
    PYTHONPATH=src python benchmarks/openfoam/run_compare.py --cells 8 --end 0.5   # a tiny check

Both runs are separate processes timed end to end (start-up, JAX compilation, mesh generation
included): wall time, and CPU time (user + system of the child processes). ktgf writes no VTK
or PNG files; OpenFOAM writes its fields at the ktgf output times. θ is the mass-weighted mean
(ktgf ``theta_mean`` = Σρθ/Σρ; OpenFOAM ``weightedVolAverage`` of Theta.particles with weight
alpha.particles), compared with Haff's law of the ``enskog`` model (:mod:`ktgf.hcs.haff`).

OpenFOAM's adjustable time step (maxCo) sees the phase velocities only, not the granular sound
speed, and the run diverged at Δt ≈ 0.3 Δx/c. The runner therefore runs OpenFOAM in
``--segments`` pieces, each capped (maxDeltaT) at ktgf's own acoustic limit 0.4 Δx/(3c) at the
Haff temperature of the segment's start: both codes take steps of about the same size.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


#: Debian's openfoam package: binaries in /usr/bin, but they need the environment of this bashrc.
BASHRC = Path("/usr/share/openfoam/etc/bashrc")


def _foam(cmd: list[str]) -> list[str]:
    """An OpenFOAM command, inside the OpenFOAM environment if it is not set up already."""
    if os.environ.get("WM_PROJECT_DIR") or not BASHRC.is_file():
        return cmd
    return ["bash", "-c", f"source {BASHRC} > /dev/null 2>&1; exec {' '.join(cmd)}"]


def _timed(cmd: list[str], cwd: Path, log: Path) -> tuple[float, float]:
    """Run a command; (wall, CPU of the child) in seconds. Raises with the log tail on failure."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    with open(log, "w") as f:
        rc = subprocess.run(cmd, cwd=cwd, stdout=f, stderr=subprocess.STDOUT).returncode
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if rc != 0:
        tail = "".join(log.read_text().splitlines(keepends=True)[-15:])
        raise RuntimeError(f"{' '.join(cmd)} failed (exit {rc}) in {cwd}; end of {log}:\n{tail}")
    return wall, cpu


def _config_text(config: Path, cells: int | None, end: float | None) -> str:
    text = config.read_text()
    if cells is not None:
        text = re.sub(r"^cells\s*=.*$", f"cells = [{cells}, {cells}, {cells}]", text, flags=re.M)
    if end is not None:
        text = re.sub(r"^end\s*=.*$", f"end = {end!r}", text, flags=re.M)
    return text + '\n[output]\ndirectory = "ktgf"\nvtk = false\npng = false\n'


def run_ktgf(cfg_path: Path, work: Path) -> dict:
    ktgf = shutil.which("ktgf") or str(Path(sys.executable).with_name("ktgf"))
    wall, cpu = _timed([ktgf, "run", str(cfg_path), "-o", str(work / "ktgf"), "--no-progress", "--overwrite"],
                       work, work / "log.ktgf")
    import xarray as xr

    with xr.open_dataset(work / "ktgf" / "cooling.nc") as ds:
        series = {k: ds[v].values.tolist() for k, v in (("t", "time"), ("theta", "theta_mean"),
                                                         ("density_variance", "density_variance"))}
        return {"wall_s": wall, "cpu_s": cpu, **series, "steps": int(ds.attrs["step_count"]),
                "scheme": str(ds.attrs["time_scheme"])}


def _set(control: Path, key: str, value: str) -> None:
    text = re.sub(rf"^{key}\s+.*;$", f"{key:<16} {value};", control.read_text(), flags=re.M)
    control.write_text(text)


def run_openfoam(cfg, work: Path, segments: int, info: dict) -> dict:
    from ktgf.hcs.haff import haff_temperature

    case = work / "openfoam"
    control = case / "system" / "controlDict"
    wall, cpu = _timed(_foam(["blockMesh"]), case, case / "log.blockMesh")
    t_end, t0, theta0 = info["t_end"], info["t_haff"], info["theta0"]
    # segment ends on output (write) times, so that each restart starts from the previous end
    outs = np.asarray(info["output_times"])
    bounds = outs[np.unique(np.linspace(0, len(outs) - 1, segments + 1).round().astype(int))]
    steps = 0
    for i in range(len(bounds) - 1):
        theta_start = float(haff_temperature(bounds[i], theta0, t0))
        cap = info["acoustic_dt0"] * (theta0 / theta_start) ** 0.5  # ∝ 1/c ∝ θ^(-1/2)
        _set(control, "endTime", f"{bounds[i + 1]:.10g}")
        _set(control, "maxDeltaT", f"{cap:.10g}")
        _set(control, "deltaT", f"{cap:.10g}")
        _set(control, "startFrom", "startTime" if i == 0 else "latestTime")
        w, c = _timed(_foam(["twoPhaseEulerFoam"]), case, case / f"log.twoPhaseEulerFoam.{i}")
        wall, cpu = wall + w, cpu + c
        steps += len(re.findall(r"^Time = ", (case / f"log.twoPhaseEulerFoam.{i}").read_text(), flags=re.M))
    t, theta, alpha = [0.0], [theta0], [info["phi"] * (1.0 + info["density_variance0"])]
    files = (case / "postProcessing" / "thetaMean").glob("*/volFieldValue*.dat")
    for f in sorted(files, key=lambda p: float(p.parent.name)):  # one folder per restart
        for line in f.read_text().splitlines():
            if line.strip() and not line.startswith("#"):
                a, b, c = (float(x) for x in line.split()[:3])
                if a > t[-1]:
                    t.append(a), theta.append(b), alpha.append(c)
    return {"wall_s": wall, "cpu_s": cpu, "t": t, "theta": theta, "alpha_mean": alpha, "steps": steps}


def compare(ktgf: dict, foam: dict, info: dict) -> dict:
    """θ/θ_Haff of both at the ktgf output times, and their relative difference."""
    from ktgf.hcs.haff import haff_temperature

    t = np.asarray(ktgf["t"])
    haff = np.asarray(haff_temperature(t, info["theta0"], info["t_haff"]))
    k = np.asarray(ktgf["theta"]) / haff
    f = np.interp(t, foam["t"], foam["theta"]) / haff
    return {"t_over_t0": (t / info["t_haff"]).tolist(), "ktgf_over_haff": k.tolist(), "openfoam_over_haff": f.tolist(),
            "max_ktgf_haff_dev": float(np.max(np.abs(k - 1))), "max_openfoam_haff_dev": float(np.max(np.abs(f - 1))),
            "max_openfoam_ktgf_diff": float(np.max(np.abs(f / k - 1))),
            # ⟨α²⟩/⟨α⟩ (alpha-weighted mean of alpha)/φ − 1 = ⟨δφ²⟩/φ², ktgf's density_variance
            # (⟨α⟩ = φ: OpenFOAM prints the volume fraction, conserved to its 8 digits)
            "density_variance_ktgf": [ktgf["density_variance"][0], ktgf["density_variance"][-1]],
            "density_variance_openfoam": [a / info["phi"] - 1 for a in (foam["alpha_mean"][0], foam["alpha_mean"][-1])]}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default=str(HERE / "cooling_box.toml"))
    ap.add_argument("--cells", type=int, help="override grid.cells (N³)")
    ap.add_argument("--end", type=float, help="override time.end (in the config's unit)")
    ap.add_argument("--work", default="openfoam-compare", help="working folder (recreated)")
    ap.add_argument("--segments", type=int, default=5, help="OpenFOAM runs with a maxDeltaT each (see above)")
    ap.add_argument("--skip-ktgf", action="store_true")
    args = ap.parse_args(argv)
    if shutil.which("twoPhaseEulerFoam") is None:
        sys.exit("run_compare: twoPhaseEulerFoam is not on PATH: apt-get install openfoam (Debian, v1912), "
                 "or source the bashrc of an openfoam.com installation")
    import jax

    jax.config.update("jax_enable_x64", True)
    from ktgf.solver.config import load_config
    from make_case import write_case

    work = Path(args.work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    cfg_path = work / "ktgf.toml"
    cfg_path.write_text(_config_text(Path(args.config), args.cells, args.end))
    cfg = load_config(cfg_path)
    load0 = os.getloadavg()
    info = write_case(cfg, work / "openfoam")
    foam = run_openfoam(cfg, work, args.segments, info)
    load1 = os.getloadavg()
    ktgf = None if args.skip_ktgf else run_ktgf(cfg_path, work)
    load2 = os.getloadavg()
    out = {"cells": info["cells"], "phi": info["phi"], "e": info["e"], "t_end_s": info["t_end"],
           "t_haff_s": info["t_haff"],
           "gas": info["gas"], "granular": info["granular"], "drag_over_collisional_dissipation":
           info["drag_over_collisional_dissipation"], "density_ratio": info["density_ratio"],
           "openfoam": {k: v for k, v in foam.items() if k in ("wall_s", "cpu_s", "steps")},
           "load_average": {"start": load0, "after_openfoam": load1, "after_ktgf": load2}}
    if ktgf is not None:
        out["ktgf"] = {k: v for k, v in ktgf.items() if k in ("wall_s", "cpu_s", "steps", "scheme")}
        out["ratio_wall"] = foam["wall_s"] / ktgf["wall_s"]
        out["ratio_cpu"] = foam["cpu_s"] / ktgf["cpu_s"]
        out["theta"] = compare(ktgf, foam, info)
    (work / "summary.json").write_text(json.dumps(out, indent=1))
    print(json.dumps({k: v for k, v in out.items() if k != "theta"}, indent=1))
    if ktgf is not None:
        th = out["theta"]
        print("t/t0   ktgf/Haff  OpenFOAM/Haff")
        for a, b, c in zip(th["t_over_t0"], th["ktgf_over_haff"], th["openfoam_over_haff"]):
            print(f"{a:5.2f}  {b:.5f}    {c:.5f}")
        print(f"max |ktgf/Haff - 1| {th['max_ktgf_haff_dev']:.4f}, "
              f"max |OpenFOAM/Haff - 1| {th['max_openfoam_haff_dev']:.4f}, "
              f"max |OpenFOAM/ktgf - 1| {th['max_openfoam_ktgf_diff']:.4f}")
        print("density variance start, end: ktgf", th["density_variance_ktgf"],
              "OpenFOAM", th["density_variance_openfoam"])
        print(f"time-to-solution OpenFOAM/ktgf: wall {out['ratio_wall']:.2f}, CPU {out['ratio_cpu']:.2f}")
    return out


if __name__ == "__main__":
    main()
