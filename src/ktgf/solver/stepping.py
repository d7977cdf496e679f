"""Time integration: the right-hand side, the adaptive stable step and SSP-RK3.

``advance`` runs whole steps inside one compiled ``lax.while_loop`` until a target time, a
step budget, or the first step that leaves the physical state space — that step is not
accepted, so the returned state is the last good one and ``status`` says what went wrong:

====== =======================================
status meaning
====== =======================================
0      fine
1      NaN or infinity in a field
2      θ ≤ 0 somewhere
3      φ ≥ phi_stop (approaching packing) somewhere
4      ρ ≤ 0 somewhere
5      the stable time step collapsed (Δt ≤ 0 or NaN)
====== =======================================

Scheme: third-order strong-stability-preserving Runge–Kutta (Shu & Osher 1988),

    U1 = U + Δt L(U);   U2 = 3/4 U + 1/4 (U1 + Δt L(U1));   U' = 1/3 U + 2/3 (U2 + Δt L(U2)),

with one Δt per step from the acoustic CFL, diffusive and cooling limits at the step start.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import jax
import jax.numpy as jnp

from .fluxes import LIMITERS, RIEMANN_SOLVERS, flux_divergence, materialise
from .grid import Grid
from .physics import Physics
from .sources import cooling_source
from .state import primitive_fields

STATUS_MESSAGES = {
    0: "ok",
    1: "non-finite value (NaN or inf)",
    2: "granular temperature theta <= 0",
    3: "solid fraction reached phi_stop (near the packing limit)",
    4: "density <= 0",
    5: "stable time step collapsed",
}


@jax.tree_util.register_pytree_node_class
@dataclass(frozen=True)
class Numerics:
    """Numerical options: a pytree whose Courant numbers are traced and whose scheme choices are static.

    Parameters
    ----------
    cfl : float
        Acoustic Courant number: Δt ≤ cfl / max Σ_a (|u_a| + c)/Δx_a.
    cfl_diffusion : float
        Δt ≤ cfl_diffusion / (2 max D Σ_a Δx_a⁻²), D the largest of (4η/3 + λ_b)/ρ and κ/(3ρ/2).
    cfl_source : float
        Δt ≤ cfl_source / max|ζ| (must be < 1 for the positivity argument of :mod:`.sources`).
    limiter : str
        MUSCL slope limiter, one of ``minmod``, ``vanleer``, ``mc``, ``none``.
    riemann : str
        ``hll`` or ``rusanov``.
    dt_max : float
        Upper bound on Δt [s] (``inf``: none).
    """

    cfl: float = 0.4
    cfl_diffusion: float = 0.4
    cfl_source: float = 0.5
    limiter: str = "vanleer"
    riemann: str = "hll"
    dt_max: float = float("inf")

    def tree_flatten(self) -> tuple[tuple, tuple[str, str]]:
        return (self.cfl, self.cfl_diffusion, self.cfl_source, self.dt_max), (self.limiter, self.riemann)

    @classmethod
    def tree_unflatten(cls, aux: tuple[str, str], leaves: tuple) -> Numerics:
        obj = object.__new__(cls)
        for name, v in zip(("cfl", "cfl_diffusion", "cfl_source", "dt_max", "limiter", "riemann"), (*leaves, *aux)):
            object.__setattr__(obj, name, v)
        return obj

    def __post_init__(self) -> None:
        from ..errors import InputError

        if self.limiter not in LIMITERS:
            raise InputError(f"limiter {self.limiter!r} is not valid: choose one of {LIMITERS}")
        if self.riemann not in RIEMANN_SOLVERS:
            raise InputError(f"riemann solver {self.riemann!r} is not valid: choose one of {RIEMANN_SOLVERS}")


def rhs(U: Any, grid: Grid, phys: Physics, num: Numerics) -> Any:
    """dU/dt = −∇·F(U) + S(U)."""
    W = materialise(primitive_fields(U))
    dU, divu = flux_divergence(W, grid, phys, num.limiter, num.riemann)
    source, _ = cooling_source(W, divu, phys)
    dU[4] = dU[4] + source
    return tuple(dU)


def stable_dt(U: Any, grid: Grid, phys: Physics, num: Numerics) -> Any:
    """Largest step allowed by the acoustic, diffusive and cooling limits (see :class:`Numerics`)."""
    W = primitive_fields(U)
    rho, u, theta = W[0], W[1:4], W[4]
    r = phys.reduced(rho)
    c = phys.sound_speed(theta, r)
    wave = sum((jnp.abs(u[a]) + c) / grid.spacing[a] for a in range(grid.ndim))
    eta, lam, kap, _ = phys.transport(rho, theta, r)
    diff = jnp.maximum((4.0 / 3.0 * eta + lam) / rho, kap / (1.5 * rho))
    inv_dx2 = sum(1.0 / h**2 for h in grid.spacing)
    # max|ζ| ≤ max ζ0 + max|ζ_U| max|∇·u|, and the central ∇·u obeys
    # |∇·u| ≤ Σ_a (max u_a − min u_a)/(2Δx_a): plain reductions only, since a stencil inside
    # XLA's CPU reduction loop makes it an order of magnitude slower.
    divu_bound = sum((jnp.max(u[a]) - jnp.min(u[a])) * (0.5 / grid.spacing[a]) for a in range(grid.ndim))
    zeta = jnp.max(phys.cooling_rate(rho, theta, 0.0, r)) + jnp.max(jnp.abs(r.zeta_u)) * divu_bound
    dt = jnp.minimum(num.cfl / jnp.max(wave), num.cfl_diffusion / (2.0 * inv_dx2 * jnp.max(diff)))
    dt = jnp.minimum(dt, num.cfl_source / zeta)
    return jnp.minimum(dt, num.dt_max)


def ssprk3_step(U: Any, dt: Any, grid: Grid, phys: Physics, num: Numerics) -> Any:
    """One SSP-RK3 step of size dt.

    Written as three stages U_{k+1} = a_k U + (1 − a_k)(U_k + Δt L(U_k)), a = (0, 3/4, 1/3),
    in a ``fori_loop`` so the right-hand side is traced (and compiled) once, not three times.
    """
    coef = jnp.asarray([0.0, 0.75, 1.0 / 3.0], dtype=U[0].dtype)

    def stage(k: Any, Uk: tuple) -> tuple:
        a = coef[k]
        L = rhs(Uk, grid, phys, num)
        return tuple(a * u + (1.0 - a) * (uk + dt * l) for u, uk, l in zip(U, Uk, L))

    return jax.lax.fori_loop(0, 3, stage, tuple(U))


def state_status(U: Any, phys: Physics) -> Any:
    """Status code (0 fine, 1 non-finite, 2 θ ≤ 0, 3 φ ≥ phi_stop, 4 ρ ≤ 0) of a state."""
    W = primitive_fields(U)
    finite = jnp.all(jnp.stack([jnp.all(jnp.isfinite(f)) for f in U]))
    return jnp.where(
        ~finite, 1,
        jnp.where(jnp.min(W[4]) <= 0.0, 2,
                  jnp.where(jnp.max(W[0]) >= phys.phi_stop * phys.material_density, 3,
                            jnp.where(jnp.min(W[0]) <= 0.0, 4, 0))),
    ).astype(jnp.int32)


@jax.jit
def advance(U: Any, t: Any, t_end: Any, max_steps: Any, grid: Grid, phys: Physics, num: Numerics) -> tuple:
    """Step from time t towards t_end (the last step is shortened to land on it exactly).

    Returns ``(U, t, steps, status, dt)``: the last good state and its time, the number of
    accepted steps, the status code of the first rejected step (0 if none) and the Δt of the
    last attempted step (to reproduce a failure for its diagnosis).
    """

    def cond(carry: tuple) -> Any:
        _, t, n, status, _ = carry
        return (t < t_end) & (n < max_steps) & (status == 0)

    def body(carry: tuple) -> tuple:
        U, t, n, _, _ = carry
        # Time is kept in float64 whatever the state precision, so a float32 run still lands
        # exactly on t_end.
        dt_stable = stable_dt(U, grid, phys, num).astype(t.dtype)
        last = dt_stable >= t_end - t
        dt = jnp.where(last, t_end - t, dt_stable)
        U_new = ssprk3_step(U, dt.astype(U[0].dtype), grid, phys, num)
        bad_state = state_status(U_new, phys)
        status = jnp.where(bad_state != 0, bad_state, jnp.where(jnp.isfinite(dt_stable) & (dt > 0), 0, 5))
        good = status == 0
        U = tuple(jnp.where(good, a, b) for a, b in zip(U_new, U))
        t = jnp.where(good, jnp.where(last, t_end, t + dt), t)
        return U, t, n + good.astype(n.dtype), status, dt

    U = tuple(U)
    t = jnp.asarray(t, jnp.float64)
    t_end = jnp.asarray(t_end, jnp.float64)
    init = (U, t, jnp.zeros((), jnp.int32), jnp.zeros((), jnp.int32), jnp.zeros((), jnp.float64))
    U, t, n, status, dt = jax.lax.while_loop(cond, body, init)
    return jnp.stack(U), t, n, status, dt


@jax.jit
def step(U: Any, dt: Any, grid: Grid, phys: Physics, num: Numerics) -> Any:
    """One SSP-RK3 step (compiled), used to reproduce a failed step for its diagnosis."""
    return jnp.stack(ssprk3_step(tuple(U), dt, grid, phys, num))
