"""The 3D part of a Couette run: rms deviation of φ, u and θ from their x–z plane averages, start and end.

Run:  PYTHONPATH=src python benchmarks/couette_3d_perturbation.py examples/couette_dense_3d.toml \\
          couette_dense_3d_run/checkpoint.npz

The start is the config's initial state (the earlier run mapped onto the grid plus the random
perturbation, as `ktgf run` builds it); the end is the checkpoint's state.  A 3D instability of the
Couette flow would show as a growing deviation; the plane averages themselves are compared with
the 1D solver in the run's verification.json.
"""

from __future__ import annotations

import sys
import tempfile

import numpy as np


def plane_deviation(U: np.ndarray, rho_s: float) -> dict[str, float]:
    """rms of f − ⟨f⟩_xz for φ, u_x, u_y, u_z, θ of a conservative state (5, nx, ny, nz), y the wall-normal axis."""
    rho = U[0]
    u = U[1:4] / rho
    theta = (U[4] / rho - 0.5 * (u**2).sum(0)) / 1.5
    fields = {"phi": rho / rho_s, "u_x": u[0], "u_y": u[1], "u_z": u[2], "theta": theta}
    return {k: float(np.sqrt(np.mean((f - f.mean(axis=(0, 2), keepdims=True)) ** 2))) for k, f in fields.items()}


def main() -> None:
    from ktgf.solver.chain import stage_config
    from ktgf.solver.run import Simulation

    cfg = stage_config(sys.argv[1])  # a chain's earlier stage: its output folder, as configured
    with tempfile.TemporaryDirectory() as scratch:
        start = np.asarray(Simulation(cfg, scratch).initial_state())
    end = np.load(sys.argv[2])["U"]
    a, b = plane_deviation(start, cfg.particles.density), plane_deviation(end, cfg.particles.density)
    for k in a:
        print(f"{k:6s} start {a[k]:.3e}  end {b[k]:.3e}  end/start {b[k] / a[k]:.3f}")


if __name__ == "__main__":
    main()
