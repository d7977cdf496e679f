"""Initial states of the solver's cases (model.md §§8–9).

Uniform φ0, θ0, u = 0, plus either a single Fourier mode shaped as an eigenvector of the
linear stability problem of the HCS (:mod:`ktgf.hcs.stability`), or one of uniform shear
(:func:`shear_mode`, :mod:`ktgf.shear.stability`), or a seeded random velocity field
built from the lowest Fourier modes (so that it does not depend on the resolution).

Linear-theory variables: ρ_k = δn/n, θ_k = δθ/θ_H, w = δu/√(2θ_H), τ = ∫ν0 dt, k* = kℓ.
"""

from __future__ import annotations

import math
from typing import Any

import jax.numpy as jnp
import numpy as np

from ..closures.coefficients import mean_free_path, nu0
from ..errors import InputError
from ..hcs.stability import longitudinal_growth_rates, longitudinal_matrix, transverse_growth_rate
from ..shear.stability import ShearModes, shear_modes
from .grid import Grid
from .physics import Physics
from .state import conservative, conservative_fields


def uniform_fields(grid: Grid, phys: Physics, phi0: float, theta0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ρ, u, θ) NumPy fields of the unperturbed HCS."""
    rho = np.full(grid.cells, phys.material_density * phi0)
    return rho, np.zeros((3, *grid.cells)), np.full(grid.cells, float(theta0))


def haff_time(phys: Physics, phi0: float, theta0: float) -> float:
    """Haff time t0 = 2/ζ0(θ0) [s]: θ_H(t) = θ0/(1 + t/t0)²."""
    r = phys.model.reduced(phi0, phys.restitution, hcs=phys.hcs)
    return float(2.0 / (nu0(phi0, theta0, phys.diameter) * r.zeta0))


def tau_of_t(t: Any, phys: Physics, phi0: float, theta0: float) -> Any:
    """Collision time τ = ∫ν0(θ_H) dt = ν0(θ0) t0 ln(1 + t/t0) along Haff's law."""
    t0 = haff_time(phys, phi0, theta0)
    return nu0(phi0, theta0, phys.diameter) * t0 * np.log1p(np.asarray(t) / t0)


def t_of_tau(tau: Any, phys: Physics, phi0: float, theta0: float) -> Any:
    """Inverse of :func:`tau_of_t`."""
    t0 = haff_time(phys, phi0, theta0)
    return t0 * np.expm1(np.asarray(tau) / (nu0(phi0, theta0, phys.diameter) * t0))


def _plane_wave(grid: Grid, mode: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The wavevector k = 2πn/L of integer ``mode`` and e^{ik·x} at the cell centres."""
    if len(mode) != grid.ndim or not any(mode):
        raise InputError(f"mode {tuple(mode)} must have {grid.ndim} integer entries, not all zero")
    k, x = grid.wavevector(tuple(mode)), grid.mesh()
    return k, np.exp(1j * sum(k[a] * x[a] for a in range(grid.ndim)))


def single_mode(grid: Grid, phys: Physics, phi0: float, theta0: float, mode: tuple[int, ...], kind: str,
                amplitude: float, branch: int = 0) -> tuple[Any, complex, np.ndarray]:
    """HCS plus one eigenmode of wave vector 2π n/L (``kind`` ``transverse`` or ``longitudinal``).

    Returns the conservative state, the linear growth rate s (units of ν0, per τ) and the
    eigenvector (ρ_k, θ_k, w) used (transverse: (0, 0, 1) for w⊥).  ``branch`` picks the
    longitudinal eigenvalue by decreasing real part.
    """
    k, phase = _plane_wave(grid, mode)
    kstar = float(np.linalg.norm(k)) * mean_free_path(phi0, phys.diameter)
    khat = k / np.linalg.norm(k)
    perp = np.cross(np.array([0.0, 0.0, 1.0]) if abs(khat[2]) < 0.9 else np.array([1.0, 0.0, 0.0]), khat)
    perp = perp / np.linalg.norm(perp)
    r = phys.model.reduced(phi0, phys.restitution, hcs=phys.hcs)
    rho, u, theta = uniform_fields(grid, phys, phi0, theta0)
    w_scale = math.sqrt(2.0 * theta0)
    if kind == "transverse":
        s = complex(transverse_growth_rate(r, kstar))
        vec = np.array([0.0, 0.0, 1.0 + 0j])
        u = u + (amplitude * w_scale * np.real(phase))[None] * perp[:, None].reshape((3,) + (1,) * grid.ndim)
    elif kind == "longitudinal":
        m = -np.asarray(longitudinal_matrix(r, kstar))
        vals, vecs = np.linalg.eig(m)
        order = np.argsort(-vals.real)
        s, vec = complex(vals[order[branch]]), vecs[:, order[branch]]
        vec = vec / vec[np.argmax(np.abs(vec))]
        s_check = complex(np.asarray(longitudinal_growth_rates(r, kstar))[branch])
        assert abs(s - s_check) <= 1e-12 * max(1.0, abs(s))
        rho = rho * (1.0 + amplitude * np.real(vec[0] * phase))
        theta = theta * (1.0 + amplitude * np.real(vec[1] * phase))
        u = u + (amplitude * w_scale * np.real(vec[2] * phase))[None] * khat.reshape((3,) + (1,) * grid.ndim)
    else:
        raise InputError(f"mode kind {kind!r} is not valid: choose 'transverse' or 'longitudinal'")
    return conservative(jnp.asarray(rho), jnp.asarray(u), jnp.asarray(theta)), s, vec


def shear_axes(grid: Grid) -> tuple[int, int, int]:
    """Velocity components (flow, gradient, vorticity) of a Lees–Edwards grid: the x, y, z of
    :mod:`ktgf.shear.stability`."""
    bc = grid.boundaries
    if bc is None or bc.shear_axis is None:
        raise InputError("a uniform-shear mode needs a grid with a Lees-Edwards axis")
    f, a = bc.flow, bc.shear_axis
    return f, a, 3 - f - a


def shear_mode(grid: Grid, phys: Physics, phi0: float, mode: tuple[int, ...], amplitude: float,
               branch: int = 0) -> tuple[Any, ShearModes]:
    """Steady uniform shear (without its base flow) plus one normal mode of :func:`ktgf.shear.stability.shear_modes`.

    The wave vector k = 2πn/L must have no component along the flow direction (k_x = 0 of the
    analysis: normal modes exp(σt); a sheared k_x ≠ 0 wave is a Kelvin mode).  θ is the steady θ
    of the closed form at the box's γ̇ (the base state of the analysis, not a configured θ0).
    The fields are f = f_0 + ``amplitude``·Re(v e^{ik·r}) with v = ``vectors[:, branch]`` (SI
    amplitudes, unit norm in (δφ/φ, δu/√θ, δθ/θ)), the velocity components mapped by
    :func:`shear_axes`.  ``branch`` orders the modes by decreasing Re σ.  The base flow is added
    by :func:`ktgf.solver.flows.add_base_flow`.  Returns the conservative state and the modes
    (σ of the seeded one: ``growth_rates[branch]``).
    """
    k, wave = _plane_wave(grid, mode)
    f, a, v = shear_axes(grid)
    if k[f] != 0.0:
        raise InputError(f"mode {tuple(mode)} varies along the flow direction (axis {'xyz'[f]}): a uniform-shear "
                         "normal mode needs k_flow = 0")
    if not 0 <= branch <= 4:
        raise InputError(f"branch = {branch} is out of range: valid 0 <= branch <= 4 (five uniform-shear modes)")
    rate = float(grid.boundaries.shear_rate)
    modes = shear_modes(phys.model, phi0, float(phys.restitution), rate, ky=k[a], kz=k[v],
                        d=float(phys.diameter), rho_s=float(phys.material_density))
    vec = modes.vectors[:, branch]
    rho, u, theta = uniform_fields(grid, phys, phi0, modes.base.theta)
    rho = rho + phys.material_density * amplitude * np.real(vec[0] * wave)
    for j, comp in enumerate((f, a, v)):
        u[comp] = u[comp] + amplitude * np.real(vec[1 + j] * wave)
    theta = theta + amplitude * np.real(vec[4] * wave)
    return conservative(jnp.asarray(rho), jnp.asarray(u), jnp.asarray(theta)), modes


def _random_modes(grid: Grid, seed: int, max_mode: int, amplitude: float, theta: float) -> tuple:
    """Seeded random fields of the Fourier modes |n_a| ≤ ``max_mode``: a velocity of rms ``amplitude``·√θ per
    component and δρ/ρ of rms ``amplitude``."""
    rng = np.random.default_rng(seed)
    x = grid.mesh()
    ranges = [range(-max_mode, max_mode + 1)] * grid.ndim
    f = np.zeros((4, *grid.cells))
    for n in np.array(np.meshgrid(*ranges, indexing="ij")).reshape(grid.ndim, -1).T:
        if not any(n):
            continue
        k = grid.wavevector(tuple(int(v) for v in n))
        arg = sum(k[a] * x[a] for a in range(grid.ndim))
        amp = rng.normal(size=4) + 1j * rng.normal(size=4)
        f += np.real(amp.reshape((4,) + (1,) * grid.ndim) * np.exp(1j * arg)[None])
    return (f[:3] * (amplitude * math.sqrt(theta) / np.sqrt(np.mean(f[:3] ** 2))),
            f[3] * (amplitude / np.sqrt(np.mean(f[3] ** 2))))


def random_velocity(grid: Grid, phys: Physics, phi0: float, theta0: float, amplitude: float, seed: int,
                    max_mode: int = 2) -> Any:
    """HCS plus seeded random velocity and density fields of the Fourier modes |n_a| ≤ ``max_mode``.

    The velocity has zero mean and root-mean-square amplitude ``amplitude``·√θ0 per
    component, δφ/φ0 has rms ``amplitude``; both are the same physical fields on every grid
    that resolves those modes.
    """
    u, drho = _random_modes(grid, seed, max_mode, amplitude, theta0)
    rho, _, theta = uniform_fields(grid, phys, phi0, theta0)
    rho = rho * (1.0 + drho)
    # Zero total momentum: the box frame is the centre-of-mass frame (no uniform drift).
    u -= (np.sum(rho * u, axis=tuple(range(1, grid.ndim + 1))) / np.sum(rho)).reshape((3,) + (1,) * grid.ndim)
    return conservative(jnp.asarray(rho), jnp.asarray(u), jnp.asarray(theta))


def perturb(U: np.ndarray, grid: Grid, amplitude: float, seed: int, max_mode: int = 2) -> np.ndarray:
    """A state (NumPy, conservative) plus the random fields of :func:`random_velocity`, keeping its mass and momentum.

    δρ/ρ has rms ``amplitude`` (less its mass-weighted mean: the mass is unchanged), the velocity
    perturbation rms ``amplitude``·√θ̄ per component (θ̄ the mass-weighted mean θ; less a uniform
    part that restores the total momentum); θ is kept cell by cell, so the energy grows by the
    kinetic energy of the perturbation.  A started-from-earlier-run state (:mod:`.sequencing`)
    is perturbed with it so that instabilities the earlier grid could not hold (a 3D mode in a
    tiled quasi-2D state) are seeded.
    """
    rho, m = U[0], U[1:4]
    u = m / rho
    theta = (U[4] / rho - 0.5 * np.sum(u * u, axis=0)) / 1.5
    axes = tuple(range(1, grid.ndim + 1))
    du, drho = _random_modes(grid, seed, max_mode, amplitude, float(np.sum(rho * theta) / np.sum(rho)))
    drho -= np.sum(rho * drho) / np.sum(rho)
    new_rho = rho * (1.0 + drho)
    new_u = u + du
    new_u += ((np.sum(m, axis=axes) - np.sum(new_rho * new_u, axis=axes)) / np.sum(new_rho)).reshape(
        (3,) + (1,) * grid.ndim)
    return np.stack(conservative_fields((new_rho, *new_u, theta)))
