"""The elementwise cell terms of a step: the fields whose maxima give the step limits and a state's status,
and the stage-kernel inputs.  Elementwise in a cell's own state, so the JAX path and the C++ cell program
(:mod:`.cell_program`) evaluate the same functions."""

from __future__ import annotations

from typing import Any

import jax
import jax.numpy as jnp

from .physics import Physics
from .sources import cooling_source
from .state import primitive_fields

#: The cell fields whose maxima give the step limits (:func:`limit_terms`, :func:`limits_of_maxima`).
LIMIT_TERMS = ("wave", "viscous", "conductive", "zeta", "abs_zeta_u", "u_x", "u_y", "u_z", "-u_x", "-u_y", "-u_z")
#: What a step-start cell program reduces (:func:`.flux_kernel.cell_limits`): the limit terms, then the
#: state's :data:`STATUS_TERMS`.
START_TERMS = LIMIT_TERMS + ("nonfinite", "-theta", "rho", "-rho")

#: The cell fields whose maxima give a state's status code (:func:`status_of_maxima`): 0·Σ U (0, or NaN
#: where a conservative field is NaN or infinite), −θ, ρ and −ρ.
STATUS_TERMS = START_TERMS[len(LIMIT_TERMS):]


def limit_terms(W: Any, r: Any, phys: Physics, acoustics: str, spacing: Any) -> tuple:
    """The cell fields of :data:`LIMIT_TERMS`, whose maxima give the step limits (:func:`limits_of_maxima`).

    The wave rate Σ_a (|u_a| + c)/Δx_a (``acoustics`` implicit: c = 0, the flow speed only), the
    kinematic viscosity (4/3 η + λ_b)/ρ and thermal diffusivity κ/(3ρ/2), the cooling rate ζ at ∇·u = 0
    and |ζ_U| (ζ = ζ0 + ζ_U ∇·u), and ±u_a (their maxima bound the central ∇·u on a periodic grid).
    Elementwise in the cell's own state, so a step-start cell program (:mod:`.cell_program`) evaluates
    them in the stage kernel and the kernel reduces them (:func:`.flux_kernel.cell_limits`).
    """
    rho, u, theta = W[0], W[1:4], W[4]
    c = phys.sound_speed(theta, r) if acoustics == "explicit" else 0.0
    eta, lam, kap, _ = phys.transport(rho, theta, r)
    wave = sum((jnp.abs(u[a]) + c) / spacing[a] for a in range(len(spacing)))
    return (wave, (4.0 / 3.0 * eta + lam) / rho, kap / (1.5 * rho), phys.cooling_rate(rho, theta, 0.0, r),
            jnp.abs(r.zeta_u), *u, *(-v for v in u))


def kernel_stage_inputs(Uk: Any, r: Any, phys: Physics) -> tuple:
    """Primitive fields, (p*, g), (η, λ_b, κ, ω) and the energy source (s0, s1) of a state with cell coefficients r.

    The source −(3/2)ρθζ is linear in ∇·u (ζ = ζ0 + ζ_U∇·u, :func:`.sources.cooling_source`): s0 is
    its value at ∇·u = 0 and s1 its derivative, so the kernel adds s0 + s1∇·u with its own ∇·u.
    """
    W = primitive_fields(Uk)
    zero = jnp.zeros_like(W[0])
    source = jax.jvp(lambda divu: cooling_source(W, divu, phys, r)[0], (zero,), (jnp.ones_like(zero),))
    return W, phys.eos(W[0], W[4], r), phys.transport(W[0], W[4], r), source


def status_terms(U: Any, W: Any) -> tuple:
    """The cell fields of :data:`STATUS_TERMS` of a state U with primitive fields W.  Elementwise, so a
    step-start cell program evaluates them with the limit terms and the kernel reduces them
    (:func:`.flux_kernel.cell_limits`): the state check of a step is then part of the next step's first pass."""
    nonfinite = sum(0.0 * f for f in U)  # 0·x is 0 for finite x, NaN for NaN and ±inf
    return nonfinite, -W[4], W[0], -W[0]
