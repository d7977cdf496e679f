"""What the flow cases share (:mod:`ktgf.solver.cases`): boundaries, base flow, stress, wall columns.

Box-averaged stress tensor.  P = pI − τ with p = ρθp*(φ) and τ = η(∇u + ∇uᵀ − (2/3)∇·u I) +
λ_b∇·u I (model.md §1), the velocity gradients by central differences across the (ghost-padded)
cells, averaged over the box: ``stress_<ij>`` [Pa].
"""

from __future__ import annotations

from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from .boundaries import AXES, LEES_EDWARDS, PERIODIC, WALL, Boundaries, WallSide, wall_terms
from .fluxes import cell_divergence, has_walls, pad_fields, pad_viscous
from .friction import cell_coefficients
from .grid import Grid
from .kinematics import gradient_axis, shear_rate, velocity_gradients
from .physics import Physics
from .state import conservative, primitive_fields

#: Time-series columns of the cases (:attr:`ktgf.solver.cases.Case.columns`) and their units.
STRESS_COMPONENTS = ("xx", "yy", "zz", "xy", "xz", "yz")
WALL_COLUMNS = ("wall_shear_stress_lower", "wall_shear_stress_upper", "wall_slip_lower", "wall_slip_upper")
PROFILES = ("u_profile", "phi_profile", "theta_profile")
WALL_CASE_COLUMNS = (*(f"stress_{c}" for c in STRESS_COMPONENTS), *WALL_COLUMNS, *PROFILES)
CASE_UNITS = {**{f"stress_{c}": "Pa" for c in STRESS_COMPONENTS}, "viscosity": "Pa s", "pressure": "Pa",
              "peculiar_energy": "m2 s-2", "wall_shear_stress_lower": "Pa", "wall_shear_stress_upper": "Pa",
              "wall_slip_lower": "m s-1", "wall_slip_upper": "m s-1", "u_profile": "m s-1", "phi_profile": "1",
              "theta_profile": "m2 s-2"}
VERIFICATION_FILE = "verification.json"


def boundaries(cfg: Any) -> Boundaries:
    """The :class:`Boundaries` of a config's ``[boundaries]`` section (grid axes only)."""
    sections = [getattr(cfg.boundaries, a) for a in AXES[:len(cfg.grid.cells)]]
    kinds = tuple(s.kind for s in sections)
    le = next((s for s in sections if s.kind == LEES_EDWARDS), None)
    wall = next((s for s in sections if s.kind == WALL), None)
    if le is not None:
        return Boundaries(kinds, shear_rate=float(le.shear_rate), flow=AXES.index(le.flow))
    if wall is not None:
        f = AXES.index(wall.flow)
        sides = tuple(WallSide(w, tuple(sign * 0.5 * float(wall.wall_speed) if j == f else 0.0 for j in range(3)))
                      for w, sign in zip(wall.walls.build_pair(), (-1.0, 1.0)))  # lower, upper
        return Boundaries(kinds, flow=f, walls=tuple(sides if s.kind == WALL else None for s in sections))
    return Boundaries(kinds)


def linear_profile(grid: Grid) -> np.ndarray:
    """u_f = γ̇(x_a − L_a/2) at the cells (the Lees–Edwards base flow; the Couette start)."""
    a = gradient_axis(grid)
    return shear_rate(grid) * (grid.mesh()[a] - 0.5 * grid.lengths[a])


def add_base_flow(U: Any, grid: Grid, base_shear: float | None = None) -> Any:
    """A state plus the linear shear profile of :func:`linear_profile` (kinetic energy included);
    ``base_shear``: instead, u_f = base_shear · x_a (a chute's start, zero at the base)."""
    bc = grid.boundaries
    if gradient_axis(grid) is None:
        return U
    W = [np.asarray(f) for f in primitive_fields(tuple(jnp.asarray(U)))]
    profile = linear_profile(grid) if base_shear is None else base_shear * grid.mesh()[gradient_axis(grid)]
    W[1 + bc.flow] = W[1 + bc.flow] + profile
    return conservative(jnp.asarray(W[0]), jnp.asarray(np.stack(W[1:4])), jnp.asarray(W[4]))


@jax.jit
def stress_tensor(U: Any, t: Any, grid: Grid, phys: Physics) -> Any:
    """Box average of P = pI − τ [Pa], as (xx, yy, zz, xy, xz, yz) (module docstring)."""
    W = primitive_fields(tuple(U))
    rho, theta = W[0], W[4]
    r = cell_coefficients(W, grid, phys, t)  # with a frictional stress: p_f and μ_f too
    p = phys.pressure(rho, theta, r)
    eta, lam, _, _ = transport = phys.transport(rho, theta, r)
    # the velocities padded as the viscous fluxes see them (with walls: their ghost cells)
    Pu = pad_viscous(W, transport, grid, phys, t)[1:4] if has_walls(grid) else pad_fields(W[1:4], grid, t, velocity=0)
    g = velocity_gradients(Pu, grid)
    divu = cell_divergence(Pu, grid)
    out = []
    for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
        tau = eta * (g[i][j] + g[j][i])
        if i == j:
            tau = tau + (lam - (2.0 / 3.0) * eta) * divu
        out.append(jnp.mean((p if i == j else 0.0) - tau))
    return jnp.stack(out)


def wall_case_diagnostics(U: Any, t: float, grid: Grid, phys: Physics) -> dict[str, Any]:
    """The columns of a case between walls (:data:`WALL_CASE_COLUMNS`) at one output."""
    out = {f"stress_{c}": float(v) for c, v in zip(STRESS_COMPONENTS, np.asarray(stress_tensor(U, t, grid, phys)))}
    out.update({k: float(v) for k, v in zip(WALL_COLUMNS, np.asarray(wall_diagnostics(U, grid, phys)))})
    return {**out, **profiles(U, grid, phys.material_density)}


@jax.jit
def wall_diagnostics(U: Any, grid: Grid, phys: Physics) -> Any:
    """Mean over each wall of the shear stress η∂u_f/∂x_a [Pa] (lower, upper) and the slip u_f − U_w [m/s]."""
    W = primitive_fields(tuple(U))
    r = cell_coefficients(W, grid, phys)
    transport = phys.transport(W[0], W[4], r)
    terms = wall_terms(W[0], W[1:4], W[4], transport, grid, phys)
    a, f = gradient_axis(grid), grid.boundaries.flow
    # the stress is η∂u/∂n with n into the medium: +x_a at the lower wall, −x_a at the upper one
    stress = [jnp.mean(terms[a, 0]["stress"][f]), -jnp.mean(terms[a, 1]["stress"][f])]
    slip = [jnp.mean(terms[a, side]["slip"][f]) for side in (0, 1)]
    return jnp.stack([*stress, *slip])


def profiles(U: Any, grid: Grid, rho_s: float) -> dict[str, list[float]]:
    """u_f, φ and θ averaged over the planes parallel to the walls (mass-weighted u and θ)."""
    W = [np.asarray(f) for f in primitive_fields(tuple(jnp.asarray(U)))]
    a, f = gradient_axis(grid), grid.boundaries.flow
    others = tuple(b for b in range(grid.ndim) if b != a)
    rho = W[0]
    mass = rho.sum(axis=others)
    return {"u_profile": list((rho * W[1 + f]).sum(axis=others) / mass),
            "phi_profile": list(rho.mean(axis=others) / rho_s),
            "theta_profile": list((rho * W[4]).sum(axis=others) / mass)}


def profile_errors(history: dict[str, list], ref: Any, y: np.ndarray, u_scale: float | None = None) -> dict[str, float]:
    """Max relative deviation of the last u, φ, θ profiles from a 1D steady ``ref`` interpolated at ``y``:
    u relative to ``u_scale`` (None: the reference's max |u|), φ and θ pointwise."""
    ref_at = {k: np.interp(y, np.asarray(ref["y"].values), np.asarray(ref[k].values)) for k in ("u", "phi", "theta")}
    got = {k: np.asarray(history[f"{k}_profile"][-1]) for k in ("u", "phi", "theta")}
    scale = np.max(np.abs(ref_at["u"])) if u_scale is None else u_scale
    return {"u": float(np.max(np.abs(got["u"] - ref_at["u"])) / scale),
            **{k: float(np.max(np.abs(got[k] / ref_at[k] - 1.0))) for k in ("phi", "theta")}}


def describe(grid: Grid) -> str:
    """One-line description of the boundaries (run metadata)."""
    bc = grid.boundaries
    parts = []
    for a, k in enumerate(bc.kinds if bc is not None else (PERIODIC,) * grid.ndim):
        if k == LEES_EDWARDS:
            parts.append(f"{AXES[a]}: lees-edwards (shear rate {float(bc.shear_rate):g}/s, flow {AXES[bc.flow]})")
        elif k == WALL:
            lo, hi = bc.walls[a]
            parts.append(f"{AXES[a]}: walls moving along {AXES[bc.flow]} at {lo.velocity[bc.flow]:g} and "
                         f"{hi.velocity[bc.flow]:g} m/s ({lo.wall.describe()}; {hi.wall.describe()})")
        else:
            parts.append(f"{AXES[a]}: {k}")
    return ", ".join(parts)
