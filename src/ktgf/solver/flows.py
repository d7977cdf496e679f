"""The flow cases of the solver as data: boundaries, initial state, diagnostics and reference.

==================  ======================================================================
``cooling``         periodic box cooling freely (the homogeneous cooling state, model.md §8)
``uniform-shear``   Lees–Edwards box sheared at rate γ̇ (:mod:`.boundaries`); its steady
                    homogeneous state is the closed form :func:`ktgf.shear.steady.steady_shear`
``couette``         planar Couette cell: Johnson–Jackson walls on one axis moving at ∓U/2
                    along the flow direction; its steady state is the 1D Couette solver's
                    (:func:`ktgf.couette.run.run`, same model, same walls, same inventory)
``chute``           gravity-driven layer: a base wall at rest (bumpy Johnson–Jackson) at
                    x_a = 0, a lid at x_a = H (default zero-flux: free slip, adiabatic), and
                    g = g(sin ζ e_f − cos ζ e_a); its steady state is the 1D inclined-layer
                    solver's (:func:`ktgf.couette.chute.solve_chute`, same column and walls)
==================  ======================================================================

Both sheared cases start from the linear profile u_f = γ̇(x_a − L_a/2) (γ̇ = U/L_a in the
Couette cell) plus the configured perturbation.

A case adds its own columns to the time series (:func:`case_diagnostics`) and, at the end of
a run, a comparison with its reference (:func:`verification`, written as ``verification.json``).

Steady state.  With ``time.steady_tol`` a sheared run stops at the first output at which every
steady monitor changed by less than the tolerance since the previous output (:func:`steady_change`):
θ, η and p of uniform shear (relative change), the u, φ and θ profiles of Couette and chute
(φ, θ pointwise relative, u relative to max|u|).  For a transient relaxing as e^{−λt} the change
per output interval Δt is ≈ (1 − e^{−λΔt}) times the remaining deviation, so with outputs about
1/λ apart the remaining deviation is about the tolerance (it is larger for denser outputs).

Box-averaged stress tensor.  P = pI − τ with p = ρθp*(φ) and τ = η(∇u + ∇uᵀ − (2/3)∇·u I) +
λ_b∇·u I (model.md §1), the velocity gradients by central differences across the (ghost-padded)
cells, averaged over the box: ``stress_<ij>`` [Pa].  In uniform shear along f with gradient a the
steady state has P_fa = −ηγ̇ and P_aa = p, so the run's viscosity is η = −⟨P_fa⟩/γ̇ and its
pressure p = ⟨tr P⟩/3.
"""

from __future__ import annotations

import math
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from ..closures.coefficients import eta0
from .boundaries import AXES, LEES_EDWARDS, PERIODIC, WALL, Boundaries, WallSide, wall_terms
from .fluxes import cell_divergence, has_walls, pad_fields, pad_viscous
from .friction import cell_coefficients, frictional_shear_reference
from .grid import Grid
from .kinematics import gradient_axis, shear_rate, velocity_gradients
from .physics import Physics
from .state import conservative, primitive_fields

#: Time-series columns added by each case.
STRESS_COMPONENTS = ("xx", "yy", "zz", "xy", "xz", "yz")
WALL_COLUMNS = ("wall_shear_stress_lower", "wall_shear_stress_upper", "wall_slip_lower", "wall_slip_upper")
PROFILES = ("u_profile", "phi_profile", "theta_profile")
CASE_COLUMNS = {
    "cooling": (),
    "uniform-shear": (*(f"stress_{c}" for c in STRESS_COMPONENTS), "viscosity", "pressure", "peculiar_energy"),
    "couette": (*(f"stress_{c}" for c in STRESS_COMPONENTS), *WALL_COLUMNS, *PROFILES),
    "chute": (*(f"stress_{c}" for c in STRESS_COMPONENTS), *WALL_COLUMNS, *PROFILES),
}
CASE_UNITS = {**{f"stress_{c}": "Pa" for c in STRESS_COMPONENTS}, "viscosity": "Pa s", "pressure": "Pa",
              "peculiar_energy": "m2 s-2", "wall_shear_stress_lower": "Pa", "wall_shear_stress_upper": "Pa",
              "wall_slip_lower": "m s-1", "wall_slip_upper": "m s-1", "u_profile": "m s-1", "phi_profile": "1",
              "theta_profile": "m2 s-2"}
VERIFICATION_FILE = "verification.json"


def boundaries(cfg: Any) -> Boundaries:
    """The :class:`Boundaries` of a config's ``[boundaries]`` section (grid axes only)."""
    ndim = len(cfg.grid.cells)
    sections = [getattr(cfg.boundaries, a) for a in AXES[:ndim]]
    kinds = tuple(s.kind for s in sections)
    le = next((s for s in sections if s.kind == LEES_EDWARDS), None)
    wall = next((s for s in sections if s.kind == WALL), None)
    if le is not None:
        return Boundaries(kinds, shear_rate=float(le.shear_rate), flow=AXES.index(le.flow))
    if wall is not None:
        f = AXES.index(wall.flow)
        lower, upper = wall.walls.build_pair()
        sides = []
        for w, sign in ((lower, -1.0), (upper, 1.0)):
            v = [0.0, 0.0, 0.0]
            v[f] = sign * 0.5 * float(wall.wall_speed)
            sides.append(WallSide(w, tuple(v)))
        return Boundaries(kinds, flow=f, walls=tuple(tuple(sides) if s.kind == WALL else None for s in sections))
    return Boundaries(kinds)


def gravity(cfg: Any) -> tuple[float, float, float] | None:
    """The body force per unit mass of a chute, g(sin ζ e_flow − cos ζ e_normal) [m/s²] (None otherwise)."""
    if cfg.case.kind != "chute":
        return None
    axis = cfg.boundaries.wall_axis()
    a, f = AXES.index(axis), AXES.index(getattr(cfg.boundaries, axis).flow)
    z = math.radians(cfg.case.inclination_deg)
    g = [0.0, 0.0, 0.0]
    g[f] = cfg.case.gravity * math.sin(z)
    g[a] = -cfg.case.gravity * math.cos(z)
    return tuple(g)


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


def _velocity_pad(W: Any, transport: Any, grid: Grid, phys: Physics, t: Any) -> tuple:
    """Velocities padded as the viscous fluxes see them (with walls: their ghost cells)."""
    if has_walls(grid):
        return pad_viscous(W, transport, grid, phys, t)[1:4]
    return pad_fields(W[1:4], grid, t, velocity=0)


@jax.jit
def stress_tensor(U: Any, t: Any, grid: Grid, phys: Physics) -> Any:
    """Box average of P = pI − τ [Pa], as (xx, yy, zz, xy, xz, yz) (module docstring)."""
    W = primitive_fields(tuple(U))
    rho, u, theta = W[0], W[1:4], W[4]

    r = cell_coefficients(W, grid, phys, t)  # with a frictional stress: p_f and μ_f too
    p = phys.pressure(rho, theta, r)
    transport = phys.transport(rho, theta, r)
    eta, lam, _, _ = transport
    Pu = _velocity_pad(W, transport, grid, phys, t)
    g = velocity_gradients(Pu, grid)
    divu = cell_divergence(Pu, grid)
    out = []
    for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
        tau = eta * (g[i][j] + g[j][i])
        if i == j:
            tau = tau + (lam - (2.0 / 3.0) * eta) * divu
        out.append(jnp.mean((p if i == j else 0.0) - tau))
    return jnp.stack(out)


def _peculiar_energy(U: Any, grid: Grid) -> float:
    """½⟨|u − u_base|²⟩ mass-averaged [m²/s²]: the flow beyond the imposed shear (a growing instability)."""
    bc = grid.boundaries
    W = [np.asarray(f) for f in primitive_fields(tuple(jnp.asarray(U)))]
    u = np.stack(W[1:4])
    u[bc.flow] = u[bc.flow] - linear_profile(grid)
    return float(0.5 * np.sum(W[0] * np.sum(u * u, axis=0)) / np.sum(W[0]))


def case_diagnostics(kind: str, U: Any, t: float, grid: Grid, phys: Physics) -> dict[str, float]:
    """The case's own time-series columns (:data:`CASE_COLUMNS`) at one output."""
    if kind == "cooling":
        return {}
    P = np.asarray(stress_tensor(U, t, grid, phys))
    out = {f"stress_{c}": float(v) for c, v in zip(STRESS_COMPONENTS, P)}
    if kind in ("couette", "chute"):
        out.update({k: float(v) for k, v in zip(WALL_COLUMNS, np.asarray(wall_diagnostics(U, grid, phys)))})
        out.update(profiles(U, grid, phys.material_density))
        return out
    bc = grid.boundaries
    f, a = bc.flow, bc.shear_axis
    comp = {(0, 1): 3, (1, 0): 3, (0, 2): 4, (2, 0): 4, (1, 2): 5, (2, 1): 5}[(f, a)]
    out["viscosity"] = float(-P[comp] / shear_rate(grid))
    out["pressure"] = float(P[:3].mean())
    out["peculiar_energy"] = _peculiar_energy(U, grid)
    return out


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


#: Time-series columns whose change between outputs decides steadiness (:func:`steady_change`).
STEADY_MONITORS = {"uniform-shear": ("theta_mean", "viscosity", "pressure"),
                   "couette": PROFILES, "chute": PROFILES}


def steady_change(kind: str, history: dict[str, list]) -> float | None:
    """Max relative change of the case's steady monitors between the last two outputs (module
    docstring; None for the cooling box or before two outputs)."""
    names = STEADY_MONITORS.get(kind)
    if names is None or len(history["time"]) < 2:
        return None
    change = 0.0
    for name in names:
        new, old = (np.asarray(history[name][i], dtype=float) for i in (-1, -2))
        scale = np.max(np.abs(new)) if name == "u_profile" else np.abs(new)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.abs(new - old) / scale
        change = max(change, float(np.max(np.where(np.isfinite(rel), rel, np.inf))))
    return change


def uniform_shear_reference(phys: Physics, phi: float, rate: float) -> dict[str, float]:
    """Steady θ [m²/s²], η [Pa s] and p [Pa] of uniform shear at φ and γ̇ from the closed form.

    θ = T(γ̇d)² with T = θ/(γ̇d)² of :func:`ktgf.shear.steady.steady_shear` (the energy balance
    ηγ̇² = (3/2)ρθζ0), then η = η0(θ)η*(φ) and p = ρ_sφθp*(φ) (model.md §1, §9).
    """
    from ..shear.steady import steady_temperature

    model, e, d, rho_s = phys.model, float(phys.restitution), float(phys.diameter), float(phys.material_density)
    if model.friction.has_stress:  # the frictional stress too: ``ktgf shear --mu`` (ktgf.solver.friction)

        return frictional_shear_reference(phys, phi, rate)
    theta = float(steady_temperature(model, phi, e)) * (rate * d) ** 2
    r = model.reduced(phi, e)
    return {"theta": theta, "eta": float(eta0(theta, d, rho_s) * r.eta), "p": float(rho_s * phi * theta * r.p)}


def couette_reference(phys: Physics, grid: Grid, phi0: float, n_cells: int = 400) -> Any:
    """Steady planar Couette profile of the 1D solver for the 3D cell (same model, walls, inventory, gap)."""
    from ..couette.geometry import PlanarCell
    from ..couette.run import Material, run

    a, f = gradient_axis(grid), grid.boundaries.flow
    lower, upper = grid.boundaries.walls[a]
    U = upper.velocity[f] - lower.velocity[f]
    material = Material(float(phys.diameter), float(phys.material_density), float(phys.restitution))
    return run(phys.model, PlanarCell(grid.lengths[a], U), lower.wall, upper.wall, phi0, material,
               n_cells=n_cells, stretch=1.5)


def compare_couette(history: dict[str, list], phys: Physics, grid: Grid, phi0: float) -> dict[str, Any]:
    """Max relative deviation of the last profiles from the 1D steady solution at the cell centres.

    u relative to the wall speed U/2 (u changes sign mid-gap), φ and θ pointwise.
    """
    ref = couette_reference(phys, grid, phi0)
    a, f = gradient_axis(grid), grid.boundaries.flow
    y = grid.centres(a) - 0.5 * grid.lengths[a]  # the 1D cell spans −H/2 … H/2
    yr = np.asarray(ref["y"].values)
    lower, upper = grid.boundaries.walls[a]
    half_u = 0.5 * (upper.velocity[f] - lower.velocity[f])
    interp = {k: np.interp(y, yr, np.asarray(ref[k].values)) for k in ("u", "phi", "theta")}
    got = {"u": np.asarray(history["u_profile"][-1]), "phi": np.asarray(history["phi_profile"][-1]),
           "theta": np.asarray(history["theta_profile"][-1])}
    err = {"u": float(np.max(np.abs(got["u"] - interp["u"])) / half_u),
           "phi": float(np.max(np.abs(got["phi"] / interp["phi"] - 1.0))),
           "theta": float(np.max(np.abs(got["theta"] / interp["theta"] - 1.0)))}
    tau_ref = np.asarray(ref["wall_shear_stress"].values)
    slip_ref = np.asarray(ref["wall_slip"].values)
    return {
        "reference": "1D steady planar Couette solver ktgf.couette (same model, walls, inventory and gap; 400 cells)",
        "max_rel_error": err,
        "wall_shear_stress_Pa": {"run": [history["wall_shear_stress_lower"][-1], history["wall_shear_stress_upper"][-1]],
                                 "reference": tau_ref.tolist()},
        "wall_slip_m_per_s": {"run": [history["wall_slip_lower"][-1], history["wall_slip_upper"][-1]],
                              "reference": slip_ref.tolist()},
        "cells_across_gap": grid.cells[a],
    }


def chute_reference(phys: Physics, grid: Grid, phi0: float, n_cells: int = 256) -> Any:
    """Steady inclined layer of the 1D solver for the 3D column (same model, base, lid, inventory, depth)."""
    from ..couette.chute import solve_chute
    from ..couette.run import Material

    a, f = gradient_axis(grid), grid.boundaries.flow
    g = phys.gravity
    gmag = math.hypot(g[a], g[f])
    angle = math.degrees(math.atan2(g[f], -g[a]))
    base, lid = grid.boundaries.walls[a]
    material = Material(float(phys.diameter), float(phys.material_density), float(phys.restitution))
    return solve_chute(phys.model, depth=grid.lengths[a], angle_deg=angle, mean_phi=phi0, material=material,
                       base=base.wall, top=lid.wall, gravity=gmag, n_cells=n_cells)


def compare_chute(history: dict[str, list], phys: Physics, grid: Grid, phi0: float,
                  n_cells: int = 256) -> dict[str, Any]:
    """Max relative deviation of the last profiles from the 1D steady layer on ``n_cells`` (u relative to its maximum)."""
    ref = chute_reference(phys, grid, phi0, n_cells=n_cells)
    a = gradient_axis(grid)
    y = grid.centres(a)
    yr = np.asarray(ref["y"].values)
    interp = {k: np.interp(y, yr, np.asarray(ref[k].values)) for k in ("u", "phi", "theta")}
    got = {"u": np.asarray(history["u_profile"][-1]), "phi": np.asarray(history["phi_profile"][-1]),
           "theta": np.asarray(history["theta_profile"][-1])}
    err = {"u": float(np.max(np.abs(got["u"] - interp["u"])) / np.max(np.abs(interp["u"]))),
           "phi": float(np.max(np.abs(got["phi"] / interp["phi"] - 1.0))),
           "theta": float(np.max(np.abs(got["theta"] / interp["theta"] - 1.0)))}
    return {
        "reference": "1D steady inclined layer ktgf.couette.chute.solve_chute (same model, base, lid, inventory "
                     f"and depth; {n_cells} cells)",
        "max_rel_error": err,
        "base_shear_stress_Pa": {"run": history["wall_shear_stress_lower"][-1],
                                 "reference": float(ref["wall_shear_stress"].values[0])},
        "base_slip_m_per_s": {"run": history["wall_slip_lower"][-1], "reference": float(ref["wall_slip"].values[0])},
        "cells_across_depth": grid.cells[a],
    }


def verification(kind: str, history: dict[str, list], phys: Physics, grid: Grid, phi0: float) -> dict[str, Any] | None:
    """The case's comparison with its reference at the last output (None for the cooling box)."""
    if kind == "chute":
        return {"case": kind, "model": phys.model.name, "solid_fraction": phi0,
                "restitution": float(phys.restitution), **compare_chute(history, phys, grid, phi0)}
    if kind == "couette":
        return {"case": kind, "model": phys.model.name, "solid_fraction": phi0,
                "restitution": float(phys.restitution), **compare_couette(history, phys, grid, phi0)}
    if kind != "uniform-shear":
        return None
    ref = uniform_shear_reference(phys, phi0, shear_rate(grid))
    got = {"theta": history["theta_mean"][-1], "eta": history["viscosity"][-1], "p": history["pressure"][-1]}
    err = {k: abs(got[k] - ref[k]) / abs(ref[k]) for k in ref}
    return {
        "reference": "closed-form uniform shear ktgf.shear.steady (model.md §9), same model",
        "case": kind,
        "model": phys.model.name,
        "solid_fraction": phi0,
        "restitution": float(phys.restitution),
        "shear_rate_per_s": shear_rate(grid),
        "reference_values": ref,
        "run_values": got,
        "max_rel_error": err,
    }


def describe(grid: Grid) -> str:
    """One-line description of the boundaries (run metadata)."""
    bc = grid.boundaries
    if bc is None:
        return ", ".join(f"{AXES[a]}: {PERIODIC}" for a in range(grid.ndim))
    parts = []
    for a, k in enumerate(bc.kinds):
        if k == LEES_EDWARDS:
            parts.append(f"{AXES[a]}: lees-edwards (shear rate {float(bc.shear_rate):g}/s, flow {AXES[bc.flow]})")
        elif k == WALL:
            lo, hi = bc.walls[a]
            parts.append(f"{AXES[a]}: walls moving along {AXES[bc.flow]} at {lo.velocity[bc.flow]:g} and "
                         f"{hi.velocity[bc.flow]:g} m/s ({lo.wall.describe()}; {hi.wall.describe()})")
        else:
            parts.append(f"{AXES[a]}: {k}")
    return ", ".join(parts)
