"""Shared by the growth-rate tests of the solver: the rate of a complex mode amplitude."""

from __future__ import annotations

import numpy as np


def fit_rate(times: np.ndarray, amplitudes: np.ndarray) -> complex:
    """Least-squares slope of log(a(t)/a(0)): the complex rate σ of a ∝ exp(σt) (imaginary part unwrapped)."""
    logp = np.log(np.asarray(amplitudes) / amplitudes[0])
    return complex(np.polyfit(times, logp.real, 1)[0] + 1j * np.polyfit(times, np.unwrap(logp.imag), 1)[0])


def temporal_orders(U0, grid, phys, t_end: float, n0: int, fields: list[int], theta0: float,
                    **numerics) -> tuple[list[float], np.ndarray]:
    """Errors of runs to t_end in n0, 2n0, 4n0 equal steps against 64n0 steps (max over the primitive
    ``fields`` scaled by mean ρ, 1, √θ0, 1, θ0) and the orders between them."""
    from ktgf.solver.state import primitive
    from ktgf.solver.stepping import Numerics, advance

    runs = {}
    for n in (n0, 2 * n0, 4 * n0, 64 * n0):
        num = Numerics(cfl=1.0, cfl_source=0.99, dt_max=t_end / n, implicit_tol=1e-10, **numerics)
        U, t, steps, status, _ = advance(U0, 0.0, t_end, 10**6, grid, phys, num)
        assert int(status) == 0 and float(t) == t_end and int(steps) in (n, n + 1)
        runs[n] = np.asarray(primitive(U))
    ref = runs.pop(64 * n0)
    scale = np.array([ref[0].mean(), 1.0, np.sqrt(theta0), 1.0, theta0])
    errors = [float(np.max(np.abs(W - ref)[fields] / scale[fields, None])) for W in runs.values()]
    return errors, np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
