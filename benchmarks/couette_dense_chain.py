"""Time a chain of runs from a uniform start to a steady dense Couette cell in 3D (issue 34, item 2).

Run:  PYTHONPATH=src python benchmarks/couette_dense_chain.py [examples/couette_dense055_3d.toml]

Every stage runs from scratch in a fresh temporary folder (`ktgf.solver.chain.run_chain`, as
`ktgf run` does: the 4 × 64 × 4 slab from its uniform start, then the 64³ cell from the tiled slab).
Prints, per stage and for the whole chain, the steps, the strain at which it was steady, wall and CPU
time and the load average, then the last stage's largest relative errors against the 1D Couette
solver.  The goal of issue 34: φ̄ 0.55 at 64³ steady within 10 min wall on 2 idle cores and within
1 % of the 1D solver in u, φ and θ (take the figure with no other job running).
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

GOAL_WALL_S, GOAL_ERROR = 600.0, 0.01


def main() -> None:
    from ktgf.solver.chain import earlier_config, run_chain
    from ktgf.solver.config import load_config

    config = Path(sys.argv[1] if len(sys.argv) > 1 else "examples/couette_dense055_3d.toml").resolve()
    stages = [config]
    while (earlier := earlier_config(stages[0], load_config(stages[0]))) is not None:
        stages.insert(0, earlier.resolve())
    with tempfile.TemporaryDirectory() as scratch:
        os.chdir(scratch)
        sim, _ = run_chain(config, progress=False)
        for path in stages:
            ver = json.loads((Path(load_config(path).output.directory) / "verification.json").read_text())
            run, steady = ver["run"], ver["steady"]
            print(f"{path.name:28s} cells {run['cells']}  steps {run['step_count']:5d}  steady at strain "
                  f"{steady['strain']:.1f} ({steady['reached']})  wall {run['wall_time_s']:.0f} s  "
                  f"CPU {run['cpu_time_s']:.0f} s  load {run['load_average'][0]:.2f}")
    total = ver["run"]["sequence"]
    errors = ver["max_rel_error"]
    print(f"chain: {total['steps']} steps, wall {total['wall_time_s']:.0f} s, CPU {total['cpu_time_s']:.0f} s")
    print("largest relative errors against the 1D solver: " + ", ".join(f"{k} {v:.2e}" for k, v in errors.items()))
    met = total["wall_time_s"] <= GOAL_WALL_S and max(errors.values()) < GOAL_ERROR and ver["steady"]["reached"]
    print(f"goal (steady, <= {GOAL_WALL_S:.0f} s wall, errors < {GOAL_ERROR:.0%}): {'met' if met else 'NOT met'}")


if __name__ == "__main__":
    main()
