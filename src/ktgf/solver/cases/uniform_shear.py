"""``uniform-shear``: a Lees–Edwards box sheared at γ̇ (:mod:`ktgf.solver.boundaries`); reference: the closed
form :func:`ktgf.shear.steady.steady_shear`.  With P the box-averaged stress (:func:`~ktgf.solver.flows.stress_tensor`;
steady: P_fa = −ηγ̇, P_aa = p) the run's viscosity is η = −⟨P_fa⟩/γ̇ and its pressure p = ⟨tr P⟩/3."""

from __future__ import annotations

from typing import Any

import jax.numpy as jnp
import numpy as np

from ...closures.coefficients import eta0
from ..boundaries import LEES_EDWARDS
from ..flows import STRESS_COMPONENTS, linear_profile, stress_tensor
from ..friction import frictional_shear_reference
from ..grid import Grid
from ..kinematics import shear_rate
from ..physics import Physics
from ..state import primitive_fields
from .registry import Case, register


def uniform_shear_reference(phys: Physics, phi: float, rate: float) -> dict[str, float]:
    """Steady θ [m²/s²], η [Pa s] and p [Pa] of uniform shear at φ and γ̇ from the closed form.

    θ = T(γ̇d)² with T = θ/(γ̇d)² of :func:`ktgf.shear.steady.steady_shear` (the energy balance
    ηγ̇² = (3/2)ρθζ0), then η = η0(θ)η*(φ) and p = ρ_sφθp*(φ) (model.md §1, §9).
    """
    from ...shear.steady import steady_temperature

    model, e, d, rho_s = phys.model, float(phys.restitution), float(phys.diameter), float(phys.material_density)
    if model.friction.has_stress:  # the frictional stress too: ``ktgf shear --mu`` (ktgf.solver.friction)
        return frictional_shear_reference(phys, phi, rate)
    theta = float(steady_temperature(model, phi, e)) * (rate * d) ** 2
    r = model.reduced(phi, e)
    return {"theta": theta, "eta": float(eta0(theta, d, rho_s) * r.eta), "p": float(rho_s * phi * theta * r.p)}


def peculiar_energy(U: Any, grid: Grid) -> float:
    """½⟨|u − u_base|²⟩ mass-averaged [m²/s²]: the flow beyond the imposed shear (a growing instability)."""
    W = [np.asarray(f) for f in primitive_fields(tuple(jnp.asarray(U)))]
    u = np.stack(W[1:4])
    u[grid.boundaries.flow] = u[grid.boundaries.flow] - linear_profile(grid)
    return float(0.5 * np.sum(W[0] * np.sum(u * u, axis=0)) / np.sum(W[0]))


@register
class UniformShear(Case):
    name, label, boundary, imposed_shear = "uniform-shear", "uniform shear", LEES_EDWARDS, True
    panels = ((("theta_mean",), "θ"), (("pressure",), "p"), (("viscosity",), "η = −⟨P_fa⟩/γ̇"))
    columns = (*(f"stress_{c}" for c in STRESS_COMPONENTS), "viscosity", "pressure", "peculiar_energy")
    steady_monitors = ("theta_mean", "viscosity", "pressure")

    def diagnostics(self, U: Any, t: float, grid: Grid, phys: Physics) -> dict[str, Any]:
        P = np.asarray(stress_tensor(U, t, grid, phys))
        out = {f"stress_{c}": float(v) for c, v in zip(STRESS_COMPONENTS, P)}
        f, a = grid.boundaries.flow, grid.boundaries.shear_axis
        comp = {(0, 1): 3, (1, 0): 3, (0, 2): 4, (2, 0): 4, (1, 2): 5, (2, 1): 5}[(f, a)]
        return {**out, "viscosity": float(-P[comp] / shear_rate(grid)), "pressure": float(P[:3].mean()),
                "peculiar_energy": peculiar_energy(U, grid)}

    def verification(self, history: dict[str, list], phys: Physics, grid: Grid, phi0: float) -> dict[str, Any]:
        ref = uniform_shear_reference(phys, phi0, shear_rate(grid))
        got = {"theta": history["theta_mean"][-1], "eta": history["viscosity"][-1], "p": history["pressure"][-1]}
        return {"reference": "closed-form uniform shear ktgf.shear.steady (model.md §9), same model",
                **self.about(phys, phi0), "shear_rate_per_s": shear_rate(grid), "reference_values": ref,
                "run_values": got, "max_rel_error": {k: abs(got[k] - ref[k]) / abs(ref[k]) for k in ref}}
