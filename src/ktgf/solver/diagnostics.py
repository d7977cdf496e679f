"""Per-output diagnostics of an HCS run (model.md §§8–9).

All are scalars (or one value per grid axis) computed in one compiled function:

============== ==========================================================================
theta_mean     mass-averaged granular temperature Σρθ/Σρ [m²/s²] (compare with Haff's law)
kinetic_energy mean-flow kinetic energy per unit mass Σ½ρ|u|²/Σρ [m²/s²]
ke_transverse  ½⟨|u⊥|²⟩, the solenoidal (vortex) part of u from its Fourier transform, without
               the k = 0 (uniform drift) mode [m²/s²]
ke_longitudinal ½⟨|u∥|²⟩, the compressive part [m²/s²]
density_variance ⟨(φ − ⟨φ⟩)²⟩/⟨φ⟩² (cluster growth)
phi_max, theta_min largest solid fraction, smallest temperature
mode_density   |ρ_k| of the lowest mode along each axis (ρ_k = δn/n as in the linear theory)
mode_velocity  |w_k| = |û_k|/√(2θ_mean) of the lowest mode along each axis
============== ==========================================================================
"""

from __future__ import annotations

from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from .grid import Grid
from .state import primitive

SCALARS = (
    "theta_mean", "kinetic_energy", "ke_transverse", "ke_longitudinal", "density_variance", "phi_max", "theta_min",
)
PER_AXIS = ("mode_density", "mode_velocity")


def velocity_split(u: Any, grid: Grid) -> tuple[Any, Any]:
    """Fourier transforms (û∥, û⊥) of the compressive and solenoidal parts of u (Helmholtz split)."""
    axes = tuple(range(1, grid.ndim + 1))
    uh = jnp.fft.fftn(u, axes=axes)
    ks = jnp.meshgrid(*(2.0 * np.pi * jnp.fft.fftfreq(n, d=h) for n, h in zip(grid.cells, grid.spacing)), indexing="ij")
    k = ks + [jnp.zeros(grid.cells)] * (3 - grid.ndim)
    k2 = sum(ki * ki for ki in k)
    proj = sum(k[j] * uh[j] for j in range(3)) / jnp.where(k2 > 0, k2, 1.0)  # k·û/|k|²
    upar = jnp.stack([k[j] * proj for j in range(3)])
    return upar, (uh - upar) * (k2 > 0)


@jax.jit
def diagnostics(U: Any, grid: Grid, rho_s: float) -> dict[str, Any]:
    """The diagnostics of the module docstring for state U."""
    W = primitive(U)
    rho, u, theta = W[0], W[1:4], W[4]
    mass = jnp.sum(rho)
    phi = rho / rho_s
    phim = jnp.mean(phi)
    upar, uperp = velocity_split(u, grid)
    norm = float(grid.size) ** 2
    theta_mean = jnp.sum(rho * theta) / mass
    rho_h = jnp.fft.fftn(rho)
    modes_rho, modes_u = [], []
    for a in range(grid.ndim):
        idx = tuple(1 if b == a else 0 for b in range(grid.ndim))
        modes_rho.append(2.0 * jnp.abs(rho_h[idx]) / (grid.size * jnp.mean(rho)))
        uh = jnp.stack([upar[j][idx] + uperp[j][idx] for j in range(3)])
        modes_u.append(2.0 * jnp.sqrt(jnp.sum(jnp.abs(uh) ** 2)) / grid.size / jnp.sqrt(2.0 * theta_mean))
    return {
        "theta_mean": theta_mean,
        "kinetic_energy": 0.5 * jnp.sum(rho * jnp.sum(u * u, axis=0)) / mass,
        "ke_transverse": 0.5 * jnp.sum(jnp.abs(uperp) ** 2) / norm,
        "ke_longitudinal": 0.5 * jnp.sum(jnp.abs(upar) ** 2) / norm,
        "density_variance": jnp.mean((phi - phim) ** 2) / phim**2,
        "phi_max": jnp.max(phi),
        "theta_min": jnp.min(theta),
        "mode_density": jnp.stack(modes_rho),
        "mode_velocity": jnp.stack(modes_u),
    }
