"""Cost per cell-step of every 3D case against the periodic cooling box, measured in one process (issue 34, item 1).

Run:  PYTHONPATH=src python benchmarks/bench_cases.py [--cells 64] [--steps 2] [--rounds 3] [--cases box,shear,...]
      [--scheme ssprk3|imex]

Each case is a ``ktgf run`` configuration (RET, e 0.8, φ 0.3, float64, SSP-RK3 with explicit acoustics and sink;
``--scheme imex``: ARS(2,2,2), whose explicit part is the inviscid kernel) on an n³ grid: ``box`` the periodic
cooling box, ``shear`` uniform shear (Lees–Edwards along y, flow x), ``couette`` (Johnson–Jackson walls on y), ``chute`` (base and lid on y, gravity
at 25°).  Per case: the marginal wall and CPU ms per step of ``advance`` (a call of 5 × ``--steps`` steps less
one of ``--steps``: what a run, which advances in chunks, sees), in ``--rounds`` rounds that visit the cases
in turn (the VM's speed drifts within minutes, so every round times every case); printed: the median per case,
its M cell-steps/s and its cost per cell-step over the box's (the goal: ≤ 1.5), with the path it took (the C++
kernel or the JAX path).  A case named ``NAME:jax`` is NAME on the JAX path (the kernel switched off while it
is compiled): the A/B of the kernel in the same process.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

CASES = ("box", "shear", "couette", "chute")

HEAD = """
[model]
name = "ret"
restitution = 0.8
[initial]
solid_fraction = 0.3
temperature = 1e-3
perturbation = "random"
amplitude = 0.05
max_mode = 2
[numerics]
precision = "float64"
[time]
end = 1.0
unit = "s"
scheme = "ssprk3"
[output]
png = false
vtk = false
"""


def config(case: str, n: int) -> str:
    """TOML of ``case`` on an n³ grid of 1 mm particles, n d per side."""
    grid = f"[grid]\ncells = [{n}, {n}, {n}]\nlength_d = {float(n)}\n"
    walls = '{ type = "johnson-jackson", specularity = 0.1, restitution = 0.9 }'
    body = {
        "box": '[case]\nkind = "cooling"\n',
        "shear": '[case]\nkind = "uniform-shear"\n[boundaries]\ny = { kind = "lees-edwards", shear_rate = 50.0, flow = "x" }\n',
        "couette": f'[case]\nkind = "couette"\n[boundaries]\ny = {{ kind = "wall", flow = "x", wall_speed = 1.0, walls = {walls} }}\n',
        "chute": f'[case]\nkind = "chute"\ninclination_deg = 25.0\n[boundaries]\ny = {{ kind = "wall", flow = "x", wall_speed = 0.0, walls = {walls} }}\n',
    }[case]
    head = HEAD.replace("perturbation", "shear_rate = 100.0\nperturbation") if case == "chute" else HEAD
    return body + head + grid


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=64)
    ap.add_argument("--steps", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--scheme", default="ssprk3", choices=("ssprk3", "imex"))
    args = ap.parse_args()

    import tomllib

    import jax

    from ktgf.solver import flux_kernel, fluxes
    from ktgf.solver.cell_program import for_physics
    from ktgf.solver.config import parse_config
    from ktgf.solver.run import Simulation
    from ktgf.solver.stepping import advance, cell_programs_apply, stage_kernel_applies

    cases = args.cases.split(",")
    n = args.cells
    runs = {}
    for case in cases:
        sim = Simulation(parse_config(tomllib.loads(config(case.split(":")[0], n).replace(
            'scheme = "ssprk3"', f'scheme = "{args.scheme}"'))))
        fluxes.FLUX_KERNEL = not case.endswith(":jax")
        with sim.precision():
            U = sim.initial_state()
            grid, phys, num = sim.grid, sim.phys, sim.num
            stage = stage_kernel_applies(grid, phys, num, U.dtype)
            flux = fluxes.FLUX_KERNEL and flux_kernel.applies(grid, U.dtype, "euler", num.limiter, num.riemann)
            if args.scheme == "imex":
                path = "C++ flux kernel (explicit part)" if flux else "JAX path"
            else:
                cells = stage and cell_programs_apply(grid) and for_physics(phys, U.dtype) is not None
                path = "C++ stages with cell programs" if cells else (
                    "C++ stage kernel" if stage else "C++ flux kernel" if flux else "JAX path")
            t0 = time.perf_counter()
            compiled = jax.jit(lambda *a: advance.__wrapped__(*a)).lower(U, 0.0, 1e30, args.steps, grid, phys,
                                                                         num).compile()
            jax.block_until_ready(compiled(U, 0.0, 1e30, args.steps, grid, phys, num))
            runs[case] = (sim, U, compiled, path, time.perf_counter() - t0)
        fluxes.FLUX_KERNEL = True
    times: dict[str, list[tuple[float, float]]] = {c: [] for c in cases}
    for _ in range(args.rounds):
        for case in cases:
            sim, U, compiled, _, _ = runs[case]
            with sim.precision():
                w, c = [], []
                for s in (args.steps, 5 * args.steps):
                    t0, c0 = time.perf_counter(), time.process_time()
                    out = compiled(U, 0.0, 1e30, s, sim.grid, sim.phys, sim.num)
                    jax.block_until_ready(out)
                    w.append(time.perf_counter() - t0)
                    c.append(time.process_time() - c0)
                    assert int(out[2]) == s and int(out[3]) == 0, (case, int(out[2]), int(out[3]))
                times[case].append(((w[1] - w[0]) / (4 * args.steps) * 1e3, (c[1] - c[0]) / (4 * args.steps) * 1e3))
    cells = n**3
    print(f"{n}^3 cells, float64 {args.scheme}, {args.rounds} rounds, cpu count {os.cpu_count()}, "
          f"load average {os.getloadavg()}")
    box = statistics.median(w for w, _ in times["box"]) if "box" in times else None
    for case in cases:
        w = statistics.median(x for x, _ in times[case])
        c = statistics.median(x for _, x in times[case])
        ratio = f"{w / box:5.2f}x the box" if box else ""
        print(f"{case:8s} {w:7.1f} ms/step wall {c:7.1f} CPU  {cells / w / 1e3:6.2f} M cell-steps/s  {ratio}  "
              f"[{runs[case][3]}; compile {runs[case][4]:.1f} s]")


if __name__ == "__main__":
    main()
