"""Frictional models in the 3D solver: the case's dissipation and the frictional stress at the cells
(docs/solver.md, "Frictional models"; docs/friction.md §7).

The closures are the friction part's own (:mod:`ktgf.closures.friction.model_slot`, the ones the
Couette solver calls in :mod:`ktgf.couette.frictional_stress`); this module only evaluates them at
the cells, once per stage:

* **Dissipation per case** (:meth:`ktgf.solver.cases.Case.physics`): the freely cooling box takes the
  homogeneous-cooling dissipation, the sheared cases the steady-shear one with the local shear measure
  dγ̇/√θ of a dissipation correction (extended kinetic theory), γ̇ = √(2 S:S), as in the Couette solver.
* **Frictional stress** (a model whose friction part has ``stress``): σ_f = −w p_f I + 2μ_f S with

      Schaeffer:               μ_f = w p_f sin φ_fr / (2 √(S:S/2 + ε² γ̇_ref²))
      Srivastava–Sundaresan:   μ_f = √2 w p_f sin φ_fr / (2 √(S:S + 2ε² γ̇_ref² + θ/d²))

  S = D − (1/3)(tr D) I the deviatoric strain rate of the full tensor (central differences at the
  cells), γ̇_ref the case's shear-rate scale (U/H, the Lees–Edwards γ̇), ε the option
  ``regularisation``; the Srivastava–Sundaresan dilatancy factor at ∇·u = 0 (p_f = p_c).  w p_f is added
  to the pressure (d(w p_f)/dρ to the sound speed² of the upwind flux), μ_f to the shear viscosity.
* **Frictional work**: dissipated at the contacts, not fed to θ: the energy gets the sink
  σ_f:∇u = 2μ_f S:S − w p_f ∇·u, as the cooling rates ζ_f = 2μ_f S:S/((3/2)ρθ) and −w p_f/((3/2)ρθ) added
  to ζ_U (so the step's cooling limit covers it).  SSP-RK3 takes ζ_f explicitly, the IMEX scheme in its
  energy stage solve with the implicit frictional heating (:func:`explicit_part`; explicitly, a stiff
  frictional work overshot and θ collapsed in homogeneous shear, measured).
"""

from __future__ import annotations

from collections import namedtuple
from typing import Any

import jax
import numpy as np
import jax.numpy as jnp

from ..closures.coefficients import Reduced
from .fluxes import pad_fields
from .grid import Grid
from .kinematics import velocity_gradients
from .physics import Physics


#: Cell coefficients of a model with a frictional stress: the :class:`~ktgf.closures.Reduced` fields
#: (ζ_U including the frictional pressure work) plus the frictional fields [SI]: ``p_f`` = w p_f [Pa],
#: ``c2_f`` = d(w p_f)/dρ [m²/s²], ``mu_f`` the frictional viscosity [Pa s], ``zeta_f`` = 2μ_f S:S/((3/2)ρθ) [1/s].
FrictionalReduced = namedtuple("FrictionalReduced", Reduced._fields + ("p_f", "c2_f", "mu_f", "zeta_f"))


def needs_rate(phys: Physics) -> bool:
    """Whether the cell coefficients depend on the velocity gradient (static)."""
    model = phys.model
    return model.friction.has_stress or (model.shear_dependent and not phys.hcs)


def strain_invariants(u: Any, grid: Grid, t: Any = 0.0) -> tuple[Any, Any]:
    """(S:S, ∇·u) at the cells, S the deviatoric strain rate, by central differences of the padded u
    (Lees–Edwards images at time t; extrapolated ghosts at walls)."""
    g = velocity_gradients(pad_fields(tuple(u), grid, t, velocity=0), grid)
    divu = g[0][0] + g[1][1] + g[2][2]
    dd = sum(0.25 * (g[b][j] + g[j][b]) ** 2 for b in range(3) for j in range(3))
    return dd - divu * divu / 3.0, divu


def cell_coefficients(W: Any, grid: Grid, phys: Physics, t: Any = 0.0) -> Any:
    """The closures at the cells of the primitive state W = (ρ, u, θ) at time t (once per stage).

    A plain :meth:`Physics.reduced` unless the model needs the velocity gradient: a shear-dependent cooling
    (dissipation correction or tangential stress) in a sheared case, or a frictional stress (then a
    :class:`FrictionalReduced`).
    """
    if not needs_rate(phys):
        return phys.reduced(W[0])
    rho, theta = W[0], W[4]
    ss = jnp.maximum(strain_invariants(W[1:4], grid, t)[0], 0.0)  # max: round-off
    model = phys.model
    shear = phys.diameter * jnp.sqrt(2.0 * ss / theta) if model.shear_dependent and not phys.hcs else None
    r = phys.reduced(rho, shear)
    if not model.friction.has_stress:
        return r
    friction = model.friction

    p_f, dp = jax.jvp(lambda rho_: friction.frictional_pressure(rho_ / phys.material_density, model.phi_max),
                      (rho,), (jnp.ones_like(rho),))  # w p_f and d(w p_f)/dρ
    reg2 = (friction.regularisation * phys.shear_rate_scale) ** 2
    mu_f = friction.frictional_viscosity(p_f, ss, theta / phys.diameter**2, reg2)
    heat = 1.5 * rho * theta
    return FrictionalReduced(*r[:6], r.zeta_u - p_f / heat, r.g, r.C, p_f, dp, mu_f, 2.0 * mu_f * ss / heat)


def explicit_part(r: Any) -> Any:
    """The cell coefficients of the IMEX scheme's explicit part: without the frictional work ζ_f, which
    its implicit stages take with the frictional heating (:func:`ktgf.solver.imex.implicit_stage`)."""
    return r._replace(zeta_f=jnp.zeros_like(r.zeta_f)) if isinstance(r, FrictionalReduced) else r


def frictional_shear_reference(phys: Physics, phi: float, rate: float) -> dict[str, float]:
    """Steady θ [m²/s²], η = τ/γ̇ [Pa s] and p [Pa] of uniform shear with a frictional stress: the closed
    form of ``ktgf shear --mu`` (:func:`ktgf.shear.steady.steady_shear`, unregularised)."""
    from ..shear.steady import steady_shear

    d, rho_s = float(phys.diameter), float(phys.material_density)
    scale = rho_s * (d * rate) ** 2
    s = steady_shear(phys.model, np.atleast_1d(np.asarray(phi, dtype=float)), float(phys.restitution), stress_scale=scale)
    p = float(s.p_star[0]) * scale
    return {"theta": float(s.T[0]) * (rate * d) ** 2, "eta": float(s.tau_over_p[0]) * p / rate, "p": p}
