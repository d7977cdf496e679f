"""The frictional (enduring-contact) stress in the Couette balances, regularised (``docs/friction.md`` §8).

A model whose friction part has a frictional stress (option ``stress``) adds, in the solver units of
:mod:`ktgf.couette.equations` (stresses in ρ_s V², rates in V/d):

* to the pressure of the normal-momentum balance, w(φ) p_f(φ)/(ρ_s V²) at the nodes;
* to the viscosity of the tangential-momentum flux, the frictional viscosity on the faces,

      Schaeffer:               μ_f = w p_f sin φ_fr / (2 √(I2D + ε² γ̇_ref²)),        I2D = γ̇²/4,
      Srivastava–Sundaresan:   μ_f = √2 w p_f sin φ_fr / (2 √(S:S + 2ε² γ̇_ref² + θ/d²)),  S:S = γ̇²/2

  (simple shear, ∇·u = 0), with γ̇ the face shear rate and γ̇_ref = U/H the cell's mean shear rate.

The frictional law is rate independent (τ_f = w p_f sin φ_fr for any γ̇ ≠ 0), so its viscosity is
singular where γ̇ → 0 (a plug); ε (option ``regularisation``, default 10⁻³) bounds it there.  Halving
ε changes converged profiles by less than the tolerance measured in ``tests/couette/test_friction_couette.py``.

Energy: the frictional work w p_f sin φ_fr |γ̇| is taken to be dissipated at the contacts without
feeding the granular temperature (the choice of :func:`ktgf.shear.steady.steady_shear`);
it is returned so that the energy budget of the cell can count it.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def frictional_terms(problem: Any, phi: np.ndarray, phi_f: np.ndarray, theta_f: np.ndarray,
                     rate_f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(w p_f at the nodes, μ_f on the faces), both in solver units; zeros without a frictional stress."""
    friction = problem.model.friction
    if not friction.has_stress:
        return np.zeros_like(phi), np.zeros_like(phi_f)
    scale = problem.stress_scale
    p_node = np.asarray(friction.frictional_pressure(phi, problem.phi_max), dtype=float) / scale
    p_face = np.asarray(friction.frictional_pressure(phi_f, problem.phi_max), dtype=float) / scale
    reg2 = (friction.regularisation * problem.reference_shear_rate) ** 2
    mu_f = np.asarray(friction.frictional_viscosity(p_face, 0.5 * rate_f**2, theta_f, reg2), dtype=float)
    return p_node, mu_f
