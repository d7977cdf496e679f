"""Benchmark: all RET coefficients for 10⁶ states, NumPy and jitted JAX (issue 2).

Prints states per second and the ratio to one NumPy pass over the same arrays (``phi * e``,
which reads two arrays and writes one) so the figure does not depend on the machine's speed.
Run: ``python benchmarks/bench_closures.py [--n 1000000] [--model ret]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def best_of(fn, repeat: int = 7) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--model", default="ret")
    args = ap.parse_args()

    import jax
    import jax.numpy as jnp

    jax.config.update("jax_enable_x64", True)
    from ktgf import get_model

    m = get_model(args.model)
    rng = np.random.default_rng(0)
    phi = rng.uniform(0.01, 0.6, args.n)
    e = rng.uniform(0.5, 1.0, args.n)

    t_pass = best_of(lambda: phi * e)
    t_np = best_of(lambda: m.reduced(phi, e, check=False))
    t_np_checked = best_of(lambda: m.reduced(phi, e))

    fn = jax.jit(lambda p, q: m.reduced(p, q, check=False))
    pj, ej = jnp.asarray(phi), jnp.asarray(e)
    t0 = time.perf_counter()
    jax.block_until_ready(fn(pj, ej))
    t_compile = time.perf_counter() - t0
    t_jax = best_of(lambda: jax.block_until_ready(fn(pj, ej)))
    fn32 = jax.jit(lambda p, q: m.reduced(p, q, check=False))
    p32, e32 = pj.astype(jnp.float32), ej.astype(jnp.float32)
    jax.block_until_ready(fn32(p32, e32))
    t_jax32 = best_of(lambda: jax.block_until_ready(fn32(p32, e32)))

    n = args.n
    print(f"model {m.name}: all reduced coefficients (p, eta, lambda_b, kappa, mu, zeta0, zeta_U, g, C) for {n:,} states")
    print(f"  one NumPy pass (phi*e)        {t_pass * 1e3:8.2f} ms  {n / t_pass / 1e6:8.1f} M states/s")
    print(f"  NumPy, unchecked              {t_np * 1e3:8.2f} ms  {n / t_np / 1e6:8.1f} M states/s  = {t_np / t_pass:5.1f} passes")
    print(f"  NumPy, with range checks      {t_np_checked * 1e3:8.2f} ms  {n / t_np_checked / 1e6:8.1f} M states/s")
    print(f"  JAX jit float64               {t_jax * 1e3:8.2f} ms  {n / t_jax / 1e6:8.1f} M states/s  = {t_jax / t_pass:5.1f} passes"
          f"  (compile {t_compile:.2f} s)")
    print(f"  JAX jit float32               {t_jax32 * 1e3:8.2f} ms  {n / t_jax32 / 1e6:8.1f} M states/s  = {t_jax32 / t_pass:5.1f} passes")
    print(f"  speed-up jit/NumPy            {t_np / t_jax:5.1f}x")


if __name__ == "__main__":
    main()
