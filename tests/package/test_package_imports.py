"""Importing ktgf changes no process-wide setting; each 3D run carries its own precision.

Run in a subprocess: the test session itself switches JAX's x64 mode on (conftest).
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytest.importorskip("jax")

SCRIPT = r"""
import json, jax, numpy as np
import ktgf, ktgf.cli, ktgf.report
import ktgf.solver
from ktgf.solver.config import parse_config
from ktgf.solver.run import Simulation
out = {"x64_after_import": bool(jax.config.jax_enable_x64)}
base = {"model": {"name": "ret", "restitution": 0.8},
        "initial": {"solid_fraction": 0.25, "temperature": 1e-4, "amplitude": 0.05, "seed": 2},
        "grid": {"cells": [8, 8], "relative_to": "transverse", "factor": 1.5},
        "time": {"end": 0.5, "outputs": 1, "max_steps_per_call": 50}, "output": {"vtk": False, "png": False}}
for prec in ("float64", "float32"):
    sim = Simulation(parse_config({**base, "numerics": {"precision": prec}}))
    ds = sim.run(progress=False, write_files=False)
    out[prec] = {"state": str(sim.state.dtype), "theta": float(ds.theta_mean.values[-1]), "steps": int(sim.steps),
                 "x64_after_run": bool(jax.config.jax_enable_x64)}
out["plain_jnp_after_runs"] = str(jax.numpy.asarray(1.0).dtype)
print(json.dumps(out))
"""


pytestmark = pytest.mark.contract


def test_import_leaves_x64_off_and_runs_keep_their_precision() -> None:
    proc = subprocess.run([sys.executable, "-W", "error::UserWarning", "-c", SCRIPT], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    r = json.loads(proc.stdout.strip().splitlines()[-1])
    assert r["x64_after_import"] is False
    assert r["float64"]["state"] == "float64" and r["float32"]["state"] == "float32"
    assert r["float64"]["x64_after_run"] is False and r["float32"]["x64_after_run"] is False
    assert r["plain_jnp_after_runs"] == "float32"  # the caller's own JAX code is unaffected
    # same run in two precisions: equal to float32 round-off, not to float64's (so the float64 run really is float64)
    a, b = r["float64"]["theta"], r["float32"]["theta"]
    assert r["float64"]["steps"] == r["float32"]["steps"]
    assert 0 < abs(a / b - 1) < 1e-4
