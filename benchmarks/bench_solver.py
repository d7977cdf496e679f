"""Speed of the JAX HCS solver: cell-steps per second on a 64³ RET box (model.md §9).

Run:  python benchmarks/bench_solver.py [--cells 64] [--steps 10] [--precision float64]

Prints the compile (jit) time separately from the stepping rate, and the ratio of the rate
to a memory-bandwidth bound measured in the same run: one NumPy copy of the conservative
state (5 fields) per Runge–Kutta stage, i.e. bound = cells / (3 × t_copy) cell-steps/s.
A real stage reads and writes the state many times (MUSCL faces, fluxes per axis, closure
evaluations), so the ratio says how far the kernel is from the cheapest possible sweep.
The machine's 2 cores are shared with other users: repeat and take the best.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cells", type=int, default=64)
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--precision", default="float64", choices=("float64", "float32"))
    ap.add_argument("--model", default="ret")
    ap.add_argument("--profile", default="", help="write a jax.profiler trace to this folder")
    args = ap.parse_args()

    import jax
    import jax.numpy as jnp

    from ktgf.closures import get_model
    from ktgf.solver.grid import Grid
    from ktgf.solver.initial import random_velocity
    from ktgf.solver.physics import Physics
    from ktgf.solver.stepping import Numerics, advance

    n = args.cells
    model = get_model(args.model)
    phys = Physics(model, 0.8, 1e-3, 2500.0, 0.99 * model.phi_max)
    grid = Grid((n, n, n), (20e-3,) * 3)
    num = Numerics()
    dtype = jnp.float64 if args.precision == "float64" else jnp.float32
    U = jnp.asarray(random_velocity(grid, phys, 0.25, 1e-4, 0.05, 0), dtype=dtype)
    far = 1e30

    t0 = time.perf_counter()
    out = advance(U, 0.0, far, 1, grid, phys, num)
    jax.block_until_ready(out)
    t_jit = time.perf_counter() - t0

    best = np.inf
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        out = advance(U, 0.0, far, args.steps, grid, phys, num)
        jax.block_until_ready(out)
        best = min(best, time.perf_counter() - t0)
        assert int(out[2]) == args.steps and int(out[3]) == 0
    rate = grid.size * args.steps / best

    host = np.asarray(U)
    dst = np.empty_like(host)
    t_copy = np.inf
    for _ in range(20):
        t0 = time.perf_counter()
        np.copyto(dst, host)
        t_copy = min(t_copy, time.perf_counter() - t0)
    bound = grid.size / (3 * t_copy)

    # Where the time goes: each part of one right-hand-side evaluation compiled on its own.
    from ktgf.solver.fluxes import convective_flux, pad_periodic, viscous_flux
    from ktgf.solver.sources import cooling_source
    from ktgf.solver.state import primitive_fields
    from ktgf.solver.stepping import rhs, stable_dt

    Ut = tuple(U)
    W = primitive_fields(Ut)
    P = pad_periodic(W, 3)
    parts = {
        "rhs (one RK stage)": (jax.jit(lambda U: rhs(U, grid, phys, num)), Ut),
        "  pad + primitive": (jax.jit(lambda U: pad_periodic(primitive_fields(U), 3)), Ut),
        "  convective flux, 3 axes": (jax.jit(lambda P: [convective_flux(P, grid.cells, a, phys, num.limiter, num.riemann)
                                                           for a in range(3)]), P),
        "  viscous + heat flux, 3 axes": (jax.jit(lambda P: [viscous_flux(P, a, grid, phys)[1:] for a in range(3)]), P),
        "  cooling source": (jax.jit(lambda W: cooling_source(W, W[1], phys)[0]), W),
        "stable dt (once per step)": (jax.jit(lambda U: stable_dt(U, grid, phys, num)), Ut),
    }
    timings = {}
    for name, (fn, arg) in parts.items():
        jax.block_until_ready(fn(arg))
        best_part = np.inf
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            jax.block_until_ready(fn(arg))
            best_part = min(best_part, time.perf_counter() - t0)
        timings[name] = best_part

    if args.profile:
        jax.profiler.start_trace(args.profile)
        jax.block_until_ready(advance(U, 0.0, far, 2, grid, phys, num))
        jax.profiler.stop_trace()

    print(f"grid {n}^3 = {grid.size} cells, model {args.model}, {args.precision}, "
          f"devices {jax.device_count()}, cpu count {os.cpu_count()} (shared with other users: noisy)")
    print(f"jit (trace + compile + 1 step): {t_jit:.2f} s")
    print(f"stepping: {args.steps} steps in {best:.3f} s (best of {args.repeats}) = {args.steps / best:.2f} steps/s")
    print(f"rate: {rate / 1e6:.3f} M cell-steps/s   (aim 2 M on 2 cores)")
    print(f"bandwidth bound (one state copy of {host.nbytes / 1e6:.1f} MB per RK stage, {t_copy * 1e3:.2f} ms): "
          f"{bound / 1e6:.1f} M cell-steps/s;  ratio rate/bound = {rate / bound:.4f}")
    step_time = best / args.steps
    print(f"time per step {step_time * 1e3:.1f} ms; parts (compiled separately, best of {args.repeats}):")
    for name, t in timings.items():
        print(f"  {name:32s} {t * 1e3:8.1f} ms  ({t / grid.size * 1e9:6.1f} ns/cell)")


if __name__ == "__main__":
    main()
