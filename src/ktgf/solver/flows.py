"""The flow cases of the solver as data: boundaries, initial state, diagnostics and reference.

==================  ======================================================================
``cooling``         periodic box cooling freely (the homogeneous cooling state, model.md §8)
``uniform-shear``   Lees–Edwards box sheared at rate γ̇ (:mod:`.boundaries`); its steady
                    homogeneous state is the closed form :func:`ktgf.couette.uniform_shear`
==================  ======================================================================

A case adds its own columns to the time series (:func:`case_diagnostics`) and, at the end of
a run, a comparison with its reference (:func:`verification`, written as ``verification.json``).

Box-averaged stress tensor.  P = pI − τ with p = ρθp*(φ) and τ = η(∇u + ∇uᵀ − (2/3)∇·u I) +
λ_b∇·u I (model.md §1), the velocity gradients by central differences across the (ghost-padded)
cells, averaged over the box: ``stress_<ij>`` [Pa].  In uniform shear along f with gradient a the
steady state has P_fa = −ηγ̇ and P_aa = p, so the run's viscosity is η = −⟨P_fa⟩/γ̇ and its
pressure p = ⟨tr P⟩/3.
"""

from __future__ import annotations

from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from ..closures.coefficients import eta0
from .boundaries import AXES, LEES_EDWARDS, PERIODIC, Boundaries, base_velocity
from .fluxes import cell_divergence, pad_fields, window
from .grid import Grid
from .physics import Physics
from .state import conservative, primitive_fields

#: Time-series columns added by each case.
STRESS_COMPONENTS = ("xx", "yy", "zz", "xy", "xz", "yz")
CASE_COLUMNS = {
    "cooling": (),
    "uniform-shear": (*(f"stress_{c}" for c in STRESS_COMPONENTS), "viscosity", "pressure", "peculiar_energy"),
}
CASE_UNITS = {**{f"stress_{c}": "Pa" for c in STRESS_COMPONENTS}, "viscosity": "Pa s", "pressure": "Pa",
              "peculiar_energy": "m2 s-2"}
VERIFICATION_FILE = "verification.json"


def boundaries(cfg: Any) -> Boundaries:
    """The :class:`Boundaries` of a config's ``[boundaries]`` section (grid axes only)."""
    ndim = len(cfg.grid.cells)
    sections = [getattr(cfg.boundaries, a) for a in AXES[:ndim]]
    kinds = tuple(s.kind for s in sections)
    le = next((s for s in sections if s.kind == LEES_EDWARDS), None)
    if le is None:
        return Boundaries(kinds)
    return Boundaries(kinds, shear_rate=float(le.shear_rate), flow=AXES.index(le.flow))


def shear_rate(grid: Grid) -> float:
    """The imposed shear rate γ̇ [1/s] of a sheared case (0 for a periodic box)."""
    bc = grid.boundaries
    return float(bc.shear_rate) if bc is not None and bc.shear_axis is not None else 0.0


def add_base_flow(U: Any, grid: Grid) -> Any:
    """A state plus the Lees–Edwards base flow u_f = γ̇(x_a − L_a/2) (kinetic energy included)."""
    bc = grid.boundaries
    if bc is None or bc.shear_axis is None:
        return U
    W = [np.asarray(f) for f in primitive_fields(tuple(jnp.asarray(U)))]
    x_a = grid.mesh()[bc.shear_axis]
    W[1 + bc.flow] = W[1 + bc.flow] + np.asarray(base_velocity(grid, x_a))
    return conservative(jnp.asarray(W[0]), jnp.asarray(np.stack(W[1:4])), jnp.asarray(W[4]))


def _gradients(u: tuple, grid: Grid, t: Any) -> list[list[Any]]:
    """∂u_j/∂x_b at the cells (central differences; 0 along missing axes), rows b, columns j."""
    Pu = pad_fields(u, grid, t, velocity=0)
    zero = jnp.zeros_like(u[0])
    return [[(window(Pu[j], grid.cells, b, 1, 0) - window(Pu[j], grid.cells, b, -1, 0)) * (0.5 / grid.spacing[b])
             if b < grid.ndim else zero for j in range(3)] for b in range(3)]


@jax.jit
def stress_tensor(U: Any, t: Any, grid: Grid, phys: Physics) -> Any:
    """Box average of P = pI − τ [Pa], as (xx, yy, zz, xy, xz, yz) (module docstring)."""
    W = primitive_fields(tuple(U))
    rho, u, theta = W[0], W[1:4], W[4]
    r = phys.reduced(rho)
    p = phys.pressure(rho, theta, r)
    eta, lam, _, _ = phys.transport(rho, theta, r)
    g = _gradients(u, grid, t)
    divu = cell_divergence(pad_fields(u, grid, t, velocity=0), grid)
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
    u[bc.flow] = u[bc.flow] - np.asarray(base_velocity(grid, grid.mesh()[bc.shear_axis]))
    return float(0.5 * np.sum(W[0] * np.sum(u * u, axis=0)) / np.sum(W[0]))


def case_diagnostics(kind: str, U: Any, t: float, grid: Grid, phys: Physics) -> dict[str, float]:
    """The case's own time-series columns (:data:`CASE_COLUMNS`) at one output."""
    if kind == "cooling":
        return {}
    P = np.asarray(stress_tensor(U, t, grid, phys))
    out = {f"stress_{c}": float(v) for c, v in zip(STRESS_COMPONENTS, P)}
    bc = grid.boundaries
    f, a = bc.flow, bc.shear_axis
    comp = {(0, 1): 3, (1, 0): 3, (0, 2): 4, (2, 0): 4, (1, 2): 5, (2, 1): 5}[(f, a)]
    out["viscosity"] = float(-P[comp] / shear_rate(grid))
    out["pressure"] = float(P[:3].mean())
    out["peculiar_energy"] = _peculiar_energy(U, grid)
    return out


def uniform_shear_reference(phys: Physics, phi: float, rate: float) -> dict[str, float]:
    """Steady θ [m²/s²], η [Pa s] and p [Pa] of uniform shear at φ and γ̇ from the closed form.

    θ = T(γ̇d)² with T = θ/(γ̇d)² of :func:`ktgf.couette.uniform_shear` (the energy balance
    ηγ̇² = (3/2)ρθζ0), then η = η0(θ)η*(φ) and p = ρ_sφθp*(φ) (model.md §1, §9).
    """
    from ..couette.uniform_shear import uniform_shear

    model, e, d, rho_s = phys.model, float(phys.restitution), float(phys.diameter), float(phys.material_density)
    state = uniform_shear(model, phi, e)
    theta = float(state.temperature_ratio) * (rate * d) ** 2
    r = model.reduced(phi, e)
    return {"theta": theta, "eta": float(eta0(theta, d, rho_s) * r.eta), "p": float(rho_s * phi * theta * r.p)}


def verification(kind: str, history: dict[str, list], phys: Physics, grid: Grid, phi0: float) -> dict[str, Any] | None:
    """The case's comparison with its reference at the last output (None for the cooling box)."""
    if kind != "uniform-shear":
        return None
    ref = uniform_shear_reference(phys, phi0, shear_rate(grid))
    got = {"theta": history["theta_mean"][-1], "eta": history["viscosity"][-1], "p": history["pressure"][-1]}
    err = {k: abs(got[k] - ref[k]) / abs(ref[k]) for k in ref}
    return {
        "reference": "closed-form uniform shear ktgf.couette.uniform_shear (model.md §9), same model",
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
        else:
            parts.append(f"{AXES[a]}: {k}")
    return ", ".join(parts)
