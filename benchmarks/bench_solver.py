"""Speed of the JAX HCS solver: cell-steps per second, as ratios to a NumPy reference pass (model.md §9).

Run:  PYTHONPATH=src python benchmarks/bench_solver.py [--cells 64] [--steps 3] [--phi 0.5]

For each (scheme, model, precision) it prints the compile time, the stepping rate (cell-steps/s,
wall and CPU time of this process) of one call of ``--steps`` steps, the steady-state rate (the
marginal time per step of a call of 5x as many steps: what a run, which advances in chunks of
hundreds of steps, sees) and the rates as ratios to a NumPy reference pass timed in the same run,
so the figures can be compared between runs on a loaded machine:

    reference pass = the cell closures (``Model.reduced`` on the φ field, NumPy) plus one 7-point
    stencil sweep of the five conservative fields, once per cell: the least work a stage does.

Precisions: ``float64``, ``float32`` (IMEX stage solves cast to float64) and ``mixed`` (IMEX only:
float32 Krylov vectors with float64 inner products; for SSP-RK3 it is the same as float32).

Also printed: the Proposed/RET, float32/float64 and mixed/float64 ratios, the step limits of the state (acoustic
CFL, viscous, conductive, cooling) and so the simulated time per CPU second of each scheme, and
for one explicit right-hand side the optimised HLO (``jit(f).lower(...).compile().as_text()``):
number of fusions (≈ kernels) and of ``power`` instructions (closure evaluations of the Proposed
RDF, whose β = 1.75 power XLA keeps as ``pow``) and XLA's estimate of the bytes accessed per cell.
The machine's 2 cores are shared with other users: the load average is printed; repeat and take
the best.

``--ab``: compile main's code path (the :mod:`ktgf.solver.fluxes` switches in ``REFERENCE``) and
a candidate (``CANDIDATE``) and time them interleaved in the same process, so a change of machine
load hits both; prints both times, their ratio and the largest difference of the two final
states (the other lines then describe the candidate).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import time

import numpy as np


def numpy_reference(model, U: np.ndarray, rho_s: float, e: float) -> float:
    """Seconds of one NumPy pass: closures at every cell plus a 7-point stencil of the 5 fields."""
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        phi = U[0] / rho_s
        r = model.reduced(phi, e, check=False)
        lap = -6.0 * U
        for ax in (1, 2, 3):
            lap += np.roll(U, 1, axis=ax) + np.roll(U, -1, axis=ax)
        _ = float(np.sum(r.p)) + float(np.sum(lap[0]))
        best = min(best, time.perf_counter() - t0)
    return best


#: ``--ab``: switches of :mod:`ktgf.solver.fluxes` of main's code path and of the candidate.
REFERENCE = {"FLUX_KERNEL": True, "STAGE_KERNEL": True, "CELL_PROGRAM": False}
CANDIDATE = {"FLUX_KERNEL": True, "STAGE_KERNEL": True, "CELL_PROGRAM": True}


@contextlib.contextmanager
def fluxes_switches(switches: dict):
    """The speed switches of :mod:`ktgf.solver.fluxes` set while tracing (restored after)."""
    from ktgf.solver import fluxes

    saved = {k: getattr(fluxes, k) for k in switches}
    try:
        for k, v in switches.items():
            setattr(fluxes, k, v)
        yield
    finally:
        for k, v in saved.items():
            setattr(fluxes, k, v)


def hlo_counts(fn, *args) -> dict[str, int]:
    import jax

    compiled = jax.jit(fn).lower(*args).compile()
    text = compiled.as_text()
    cost = compiled.cost_analysis()
    cost = cost[0] if isinstance(cost, list) else cost
    return {"fusions": len(re.findall(r"^\s*\S*fusion\S* = ", text, flags=re.M)),
            "power": len(re.findall(r" power\(", text)), "bytes": float((cost or {}).get("bytes accessed", 0.0))}


def steady_ms(compiled, U, steps: int, far: float, grid, phys, num) -> tuple[float, float]:
    """Marginal wall and CPU ms per step of ``compiled`` (``advance``): a call of 5 x ``steps`` steps less one of
    ``steps``, over 4 ``steps`` (what a run, which advances in chunks of hundreds of steps, sees)."""
    import jax

    w, c = [], []
    for s in (steps, 5 * steps):
        t0, c0 = time.perf_counter(), time.process_time()
        jax.block_until_ready(compiled(U, 0.0, far, s, grid, phys, num))
        w.append(time.perf_counter() - t0)
        c.append(time.process_time() - c0)
    return (w[1] - w[0]) / (4 * steps) * 1e3, (c[1] - c[0]) / (4 * steps) * 1e3


def pairs(n_pairs: int, steps: int, model_name: str, U64: np.ndarray, grid, phys, far: float) -> None:
    """SSP-RK3, float32 against float64, in ``n_pairs`` interleaved pairs (the order alternates), each with a
    NumPy reference pass: on a machine whose speed drifts by tens of per cent within minutes, the ratios of
    a pair are what one can compare; prints the median and the quartiles of each figure over the pairs."""
    import jax
    import jax.numpy as jnp

    from ktgf.solver.stepping import Numerics, advance

    num = Numerics(scheme="ssprk3")
    args = {p: jnp.asarray(U64, dtype=getattr(jnp, p)) for p in ("float64", "float32")}
    compiled = {p: jax.jit(lambda *a: advance.__wrapped__(*a)).lower(U, 0.0, far, steps, grid, phys, num).compile()
                for p, U in args.items()}
    for p, c in compiled.items():  # first calls: buffers, threads
        jax.block_until_ready(c(args[p], 0.0, far, steps, grid, phys, num))
    rows = []
    for k in range(n_pairs):
        order = ("float64", "float32") if k % 2 == 0 else ("float32", "float64")
        ms = {p: steady_ms(compiled[p], args[p], steps, far, grid, phys, num) for p in order}
        reference = numpy_reference(phys.model, U64, phys.material_density, phys.restitution)
        rows.append((ms["float64"][0], ms["float32"][0], ms["float64"][1], ms["float32"][1], reference * 1e3))
    a = np.array(rows)
    quart = lambda x: np.percentile(x, [25, 50, 75])  # noqa: E731
    for label, x in (("float64 ms/step wall", a[:, 0]), ("float32 ms/step wall", a[:, 1]),
                     ("float64 ms/step CPU", a[:, 2]), ("float32 ms/step CPU", a[:, 3]),
                     ("NumPy reference pass ms", a[:, 4]),
                     ("float64 M cell-steps/s", grid.size / a[:, 0] / 1e3),
                     ("float64 rate / NumPy reference", a[:, 4] / a[:, 0]),
                     ("float32 rate / NumPy reference", a[:, 4] / a[:, 1]),
                     ("float32/float64 rate, wall", a[:, 0] / a[:, 1]),
                     ("float32/float64 rate, CPU", a[:, 2] / a[:, 3])):
        q = quart(x)
        print(f"[{model_name}] pairs ({n_pairs}, steady state, {steps} -> {5 * steps} steps): {label}: "
              f"median {q[1]:.3f} (quartiles {q[0]:.3f}, {q[2]:.3f}; range {x.min():.3f} .. {x.max():.3f})",
              flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cells", type=int, default=64)
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--phi", type=float, default=0.5)
    ap.add_argument("--schemes", default="ssprk3,imex")
    ap.add_argument("--models", default="ret,proposed")
    ap.add_argument("--precisions", default="float64,float32,mixed")
    ap.add_argument("--pairs", type=int, default=0,
                    help="instead: SSP-RK3 float32 against float64 in this many interleaved pairs (median, quartiles)")
    ap.add_argument("--ab", action="store_true",
                    help="time main's code path (REFERENCE) and a candidate (CANDIDATE) in the same process, interleaved")
    args = ap.parse_args()

    import jax
    import jax.numpy as jnp

    # The package leaves jax_enable_x64 alone (Simulation turns it on per run): without this
    # line the "float64" runs would silently be float32.
    jax.config.update("jax_enable_x64", True)
    from ktgf.closures import get_model
    from ktgf.closures.coefficients import mean_free_path
    from ktgf.solver.grid import Grid
    from ktgf.solver.initial import random_velocity
    from ktgf.solver.physics import Physics
    from ktgf.solver.stepping import Numerics, advance, explicit_rhs, limits

    n, e, rho_s, d = args.cells, 0.7, 2500.0, 1e-3
    ell = mean_free_path(args.phi, d)
    grid = Grid((n, n, n), (n * ell,) * 3)  # one mean free path per cell
    print(f"grid {n}^3 = {grid.size} cells, phi = {args.phi}, e = {e}, dx = 1 mean free path; "
          f"devices {jax.device_count()}, cpu count {os.cpu_count()}, load average {os.getloadavg()} "
          "(machine shared with other users: figures are lower bounds)")
    far = 1e30
    rates, refs = {}, {}
    for model_name in args.models.split(","):
        model = get_model(model_name)
        phys = Physics(model, e, d, rho_s, 0.99 * model.phi_max)
        U64 = np.asarray(random_velocity(grid, phys, args.phi, 1e-4, 0.01, 0))
        refs[model_name] = numpy_reference(model, U64, rho_s, e)
        print(f"[{model_name}] NumPy reference pass {refs[model_name] * 1e3:.1f} ms = "
              f"{grid.size / refs[model_name] / 1e6:.2f} M cells/s")
        lim = np.asarray(limits(jnp.asarray(U64), grid, phys, Numerics()))
        print(f"[{model_name}] step limits [s]: cfl {lim[0]:.3g}, viscous {lim[1]:.3g}, conductive {lim[2]:.3g}, "
              f"cooling {lim[3]:.3g}")
        if args.pairs:
            pairs(args.pairs, args.steps, model_name, U64, grid, phys, far)
            continue
        Ut = tuple(jnp.asarray(U64))
        for name, switches in ((("new", CANDIDATE), ("reference", REFERENCE)) if args.ab else (("default", {}),)):
            with fluxes_switches(switches):
                counts = hlo_counts(lambda U: explicit_rhs(U, grid, phys, Numerics(), viscous=True), Ut)
            print(f"[{model_name}] optimised HLO of one full right-hand side ({name} path): {counts['fusions']} fusions, "
                  f"{counts['power']} power instructions, {counts['bytes'] / grid.size:.0f} bytes accessed per cell "
                  "(XLA cost analysis)")
        for scheme in args.schemes.split(","):
            for precision in args.precisions.split(","):
                if precision == "mixed" and scheme != "imex":
                    continue  # mixed differs from float32 only in the IMEX stage solves
                num = Numerics(scheme=scheme, mixed=precision == "mixed")
                dtype = jnp.float64 if precision == "float64" else jnp.float32
                U = jnp.asarray(U64, dtype=dtype)
                paths = {"new": CANDIDATE, "reference": REFERENCE} if args.ab else {"new": {}}
                compiled, t_jit = {}, {}
                for name, switches in paths.items():
                    with fluxes_switches(switches):  # traced afresh (new jit) with the switches set
                        t0 = time.perf_counter()
                        compiled[name] = jax.jit(lambda *a: advance.__wrapped__(*a)).lower(
                            U, 0.0, far, args.steps, grid, phys, num).compile()
                        t_jit[name] = time.perf_counter() - t0
                times = {name: (np.inf, np.inf) for name in paths}
                for _ in range(args.repeats):  # interleaved, so a change of machine load hits both
                    for name, c in compiled.items():
                        t0, c0 = time.perf_counter(), time.process_time()
                        out = c(U, 0.0, far, args.steps, grid, phys, num)
                        jax.block_until_ready(out)
                        w, cpu = time.perf_counter() - t0, time.process_time() - c0
                        times[name] = (min(times[name][0], w), min(times[name][1], cpu))
                        assert int(out[2]) == args.steps and int(out[3]) == 0, (int(out[2]), int(out[3]))
                        if name == "new":
                            out_new = out
                if args.ab:
                    (w0, c0), (w1, c1) = times["reference"], times["new"]
                    a, b = np.asarray(jnp.stack(out_new[0])), np.asarray(jnp.stack(out[0]))
                    diff = float(np.max(np.abs(a - b)) / np.max(np.abs(b)))
                    print(f"[{model_name}] {scheme:6s} {precision}: A/B reference (main's path) {w0 / args.steps * 1e3:.1f} ms/step "
                          f"wall, {c0 / args.steps * 1e3:.1f} CPU; new {w1 / args.steps * 1e3:.1f} wall, "
                          f"{c1 / args.steps * 1e3:.1f} CPU; speed-up {w0 / w1:.2f} wall, {c0 / c1:.2f} CPU; "
                          f"max |difference| / max |U| after {args.steps} steps {diff:.1e}", flush=True)
                out = out_new
                # Steady state: a run calls advance per output chunk (hundreds of steps), so the per-call
                # cost (buffer allocation and first touch, thread start) is spread; the marginal time of
                # the extra steps of a 5x longer call is the rate such a run sees.
                long_wall, long_cpu = np.inf, np.inf
                for _ in range(args.repeats):
                    t0, c0 = time.perf_counter(), time.process_time()
                    jax.block_until_ready(compiled["new"](U, 0.0, far, 5 * args.steps, grid, phys, num))
                    long_wall = min(long_wall, time.perf_counter() - t0)
                    long_cpu = min(long_cpu, time.process_time() - c0)
                best, best_cpu = times["new"]
                steady = (long_wall - best) / (4 * args.steps)
                steady_cpu = (long_cpu - best_cpu) / (4 * args.steps)
                rates["steady", scheme, model_name, precision] = grid.size / steady
                t_jit = t_jit["new"]
                dt = float(out[4])
                rate = grid.size * args.steps / best
                rate_cpu = grid.size * args.steps / best_cpu
                rates[scheme, model_name, precision] = rate
                rates["cpu", scheme, model_name, precision] = rate_cpu
                ratio = rate * refs[model_name] / grid.size
                print(f"[{model_name}] {scheme:6s} {precision}: jit {t_jit:5.1f} s; {best / args.steps * 1e3:7.1f} ms/step "
                      f"wall, {best_cpu / args.steps * 1e3:7.1f} ms/step CPU; {rate / 1e6:6.3f} M cell-steps/s "
                      f"= {ratio:.3f} x NumPy reference; {rate_cpu / 1e6:6.3f} M cell-steps per CPU s "
                      f"= {rate_cpu * refs[model_name] / grid.size:.3f} x NumPy reference; dt {dt:.3g} s, simulated s per CPU s "
                      f"{dt * args.steps / best_cpu:.3g}; load average {os.getloadavg()}", flush=True)
                print(f"[{model_name}] {scheme:6s} {precision}: steady state ({args.steps} -> {5 * args.steps} steps per "
                      f"call, marginal): {steady * 1e3:7.1f} ms/step wall, {steady_cpu * 1e3:7.1f} CPU; "
                      f"{grid.size / steady / 1e6:6.3f} M cell-steps/s = {refs[model_name] / steady:.3f} x NumPy reference",
                      flush=True)
    for scheme in args.schemes.split(","):
        for p in args.precisions.split(","):
            if (scheme, "proposed", p) in rates and (scheme, "ret", p) in rates:
                print(f"{scheme} {p}: Proposed/RET cell-step rate {rates[scheme, 'proposed', p] / rates[scheme, 'ret', p]:.2f}"
                      f" wall, {rates['cpu', scheme, 'proposed', p] / rates['cpu', scheme, 'ret', p]:.2f} CPU, "
                      f"{rates['steady', scheme, 'proposed', p] / rates['steady', scheme, 'ret', p]:.2f} steady"
                      f" (NumPy reference Proposed/RET {refs['ret'] / refs['proposed']:.2f})")
        for m in args.models.split(","):
            for p in ("float32", "mixed"):
                if (scheme, m, p) in rates and (scheme, m, "float64") in rates:
                    print(f"{scheme} {m}: {p}/float64 rate {rates[scheme, m, p] / rates[scheme, m, 'float64']:.2f}"
                          f" wall, {rates['cpu', scheme, m, p] / rates['cpu', scheme, m, 'float64']:.2f} CPU, "
                          f"{rates['steady', scheme, m, p] / rates['steady', scheme, m, 'float64']:.2f} steady")
    print(f"load average at the end {os.getloadavg()}")


if __name__ == "__main__":
    main()
