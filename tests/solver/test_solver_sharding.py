"""A domain sharded over two CPU devices (jax.sharding) gives the single-device result to round-off.

XLA reads ``--xla_force_host_platform_device_count`` only at start-up, so the comparison runs
in a fresh Python process with the flag set.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = r"""
import json, numpy as np, jax
jax.config.update("jax_enable_x64", True)
from ktgf.solver.config import parse_config
from ktgf.solver.run import Simulation
base = {
    "model": {"name": "proposed", "restitution": 0.7},
    "initial": {"solid_fraction": 0.4, "temperature": 1e-4, "amplitude": 0.05, "seed": 5},
    "grid": {"cells": [16, 8], "relative_to": "transverse", "factor": 1.5},
    "time": {"end": 3.0, "outputs": 2, "scheme": "imex"},
}
out = {"devices": jax.device_count()}
states = []
for ndev in (1, 2):
    sim = Simulation(parse_config({**base, "parallel": {"devices": ndev}}))
    ds = sim.run(progress=False, write_files=False)
    states.append(np.asarray(sim.state))
    out[f"steps{ndev}"] = sim.steps
    out[f"shards{ndev}"] = len(sim.state.sharding.device_set)
    out[f"theta{ndev}"] = float(ds.theta_mean[-1])
scale = np.abs(states[0]).max(axis=(1, 2))
out["maxdiff"] = float((np.abs(states[1] - states[0]).max(axis=(1, 2)) / scale).max())
print(json.dumps(out))
"""


pytestmark = pytest.mark.contract


def test_two_device_sharding_matches_single_device() -> None:
    env = dict(os.environ)
    env["XLA_FLAGS"] = (env.get("XLA_FLAGS", "") + " --xla_force_host_platform_device_count=2").strip()
    env["PYTHONPATH"] = str(Path(__file__).resolve().parents[2] / "src") + os.pathsep + env.get("PYTHONPATH", "")
    res = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=600, check=False)
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["devices"] == 2 and out["shards1"] == 1 and out["shards2"] == 2
    assert out["steps1"] == out["steps2"] > 0
    print(out)
    assert out["maxdiff"] < 1e-12, out


CASES_SCRIPT = r"""
import json, numpy as np, jax
jax.config.update("jax_enable_x64", True)
from ktgf.solver.config import parse_config
from ktgf.solver.run import Simulation
common = {"model": {"name": "ret", "restitution": 0.8}, "output": {"png": False, "vtk": False}}
cases = {
    "uniform-shear": {
        "case": {"kind": "uniform-shear"},
        "initial": {"solid_fraction": 0.3, "temperature": 1e-3, "amplitude": 0.05, "seed": 3},
        "grid": {"cells": [16, 8], "length_d": [8.0, 4.0]},
        "boundaries": {"y": {"kind": "lees-edwards", "shear_rate": 50.0, "flow": "x"}},
        "time": {"end": 0.7, "unit": "strain", "outputs": 2, "scheme": "imex"},
    },
    "couette": {
        "case": {"kind": "couette"},
        "initial": {"solid_fraction": 0.3, "temperature": 1e-3, "amplitude": 0.05, "seed": 3},
        "grid": {"cells": [8, 8], "length_d": [4.0, 8.0]},
        "boundaries": {"y": {"kind": "wall", "flow": "x", "wall_speed": 1.0,
                             "walls": {"type": "johnson-jackson", "specularity": 0.1, "restitution": 0.9}}},
        "time": {"end": 1.0, "unit": "strain", "outputs": 2, "scheme": "imex"},
    },
    "chute": {
        "case": {"kind": "chute", "inclination_deg": 25.0},
        "initial": {"solid_fraction": 0.3, "temperature": 0.03, "shear_rate": 100.0, "amplitude": 0.05, "seed": 3},
        "grid": {"cells": [8, 8], "length_d": [8.0, 10.0]},
        "boundaries": {"y": {"kind": "wall", "flow": "x", "wall_speed": 0.0,
                             "walls": {"type": "johnson-jackson", "specularity": 1.0, "restitution": 0.9,
                                       "top": {"type": "zero-flux"}}}},
        "time": {"end": 0.05, "unit": "s", "outputs": 2, "scheme": "imex"},
    },
}
out = {}
for name, case in cases.items():
    states, steps = [], []
    for ndev in (1, 2):
        sim = Simulation(parse_config({**common, **case, "parallel": {"devices": ndev}}))
        sim.run(progress=False, write_files=False)
        states.append(np.asarray(sim.state))
        steps.append(sim.steps)
    scale = np.abs(states[0]).max(axis=(1, 2))
    out[name] = {"steps": steps, "maxdiff": float((np.abs(states[1] - states[0]).max(axis=(1, 2)) / scale).max())}
print(json.dumps(out))
"""


@pytest.mark.slow(minutes=1.4)
def test_sharded_lees_edwards_and_wall_cases_match_single_device() -> None:
    """The sheared and gravity cases on two devices: the Lees–Edwards image shift rolls along the sharded axis;
    the chute's body force and bumpy base split along the periodic flow axis."""
    env = dict(os.environ)
    env["XLA_FLAGS"] = (env.get("XLA_FLAGS", "") + " --xla_force_host_platform_device_count=2").strip()
    env["PYTHONPATH"] = str(Path(__file__).resolve().parents[2] / "src") + os.pathsep + env.get("PYTHONPATH", "")
    res = subprocess.run([sys.executable, "-c", CASES_SCRIPT], capture_output=True, text=True, env=env, timeout=1200,
                         check=False)
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    print(out)
    for case in out.values():
        assert case["steps"][0] == case["steps"][1] > 0
        assert case["maxdiff"] < 1e-12, out
