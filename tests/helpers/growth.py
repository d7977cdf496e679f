"""Shared by the growth-rate tests of the solver: the rate of a complex mode amplitude, one eigenmode's
measured and theoretical rate (the HCS case of test_solver_linear), temporal orders."""

from __future__ import annotations

import math

import numpy as np

#: The HCS of the growth-rate tests: φ0, e, d [m], ρ_s [kg/m³], θ0 [m²/s²].
PHI0, E, D, RHO_S, THETA0 = 0.25, 0.8, 1e-3, 2500.0, 1e-4


def fit_rate(times: np.ndarray, amplitudes: np.ndarray) -> complex:
    """Least-squares slope of log(a(t)/a(0)): the complex rate σ of a ∝ exp(σt) (imaginary part unwrapped)."""
    logp = np.log(np.asarray(amplitudes) / amplitudes[0])
    return complex(np.polyfit(times, logp.real, 1)[0] + 1j * np.polyfit(times, np.unwrap(logp.imag), 1)[0])


def fourier_coefficient(field, grid, mode: tuple[int, ...]) -> complex:
    """Complex amplitude c of c·e^{ik·x} + c.c. in a real field (k = 2πn/L)."""
    f = np.fft.fftn(np.asarray(field))
    return complex(2.0 * f[tuple(int(n) % c for n, c in zip(mode, grid.cells))] / grid.size)


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


def measure_rate(model: str, cells: tuple[int, ...], mode: tuple[int, ...], kstar: float, kind: str,
                 branch: int = 0, tau_end: float | None = None, scheme: str = "imex", mixed: bool = False,
                 amplitude: float = 1e-6) -> tuple[complex, complex]:
    """(measured, theoretical) growth rate in units of ν0 of one eigenmode (``mixed``: float32 state,
    ``numerics.precision = "mixed"``)."""
    from ktgf.closures import get_model
    from ktgf.closures.coefficients import mean_free_path
    from ktgf.solver.grid import Grid
    from ktgf.solver.initial import single_mode, t_of_tau
    from ktgf.solver.physics import Physics
    from ktgf.solver.state import primitive
    from ktgf.solver.stepping import Numerics, advance, limits

    m = get_model(model)
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max)
    kmode = math.sqrt(sum(n * n for n in mode))
    L = 2.0 * math.pi * kmode * mean_free_path(PHI0, D) / kstar  # |k| = 2π|n|/L gives k*
    grid = Grid(cells, (L,) * len(cells))
    U, s, vec = single_mode(grid, phys, PHI0, THETA0, mode, kind, amplitude, branch)
    if mixed:
        U = U.astype(np.float32)
    khat = np.array(mode + (0,) * (3 - len(mode)), float) / kmode
    perp = np.cross([0.0, 0.0, 1.0], khat)
    taus = np.linspace(0.0, tau_end or min(3.0 / abs(s.real), 30.0), 9)
    t, proj = 0.0, []
    num = Numerics(scheme=scheme, mixed=mixed)
    lim = np.asarray(limits(U, grid, phys, num))
    print(f"{model} {cells} {kind} k*={kstar}: acoustic/diffusive step limit {lim[0] / min(lim[1], lim[2]):.2f}")
    for target in t_of_tau(taus, phys, PHI0, THETA0):
        U, t, _, status, _ = advance(U, t, float(target), 10**6, grid, phys, num)
        assert int(status) == 0
        W = np.asarray(primitive(U.astype(np.float64)))
        th = W[4].mean()
        u_dir = np.tensordot(perp if kind == "transverse" else khat, W[1:4], axes=1)
        y = np.array([
            fourier_coefficient(W[0] / W[0].mean(), grid, mode),
            fourier_coefficient(W[4] / th, grid, mode),
            fourier_coefficient(u_dir / math.sqrt(2.0 * th), grid, mode),
        ])
        proj.append(np.vdot(vec, y) / np.vdot(vec, vec))
    return fit_rate(taus, np.array(proj)), s
