"""The frictional Couette test cell (20 d, JJ walls with wall friction) and its regularisation-halving measure."""

from __future__ import annotations

import numpy as np

from ktgf import get_model
from ktgf.couette import PlanarCell, Wall
from ktgf.couette.equations import Problem
from ktgf.couette.geometry import stretched_nodes
from ktgf.couette.solver import solve

#: The χ(φ) registered before 7 December 2026 (no sheared part; ``registry_fits.fit_frictionless``, then
#: ``fit_frictional``): the comparison the sheared χ's tests measure their gain against (docs/dense.md §4).
PREVIOUS_CHI = {"a": 0.1238, "exponent": 1.9102, "c": 0.8861, "shear_amplitude": 0.0, "mu_scale": 0.6220,
                "amplitude_growth": 5.899}
#: The earlier fit without the static states: no jamming term without shear (a = 0).  Its dense frictional cells
#: gather the shear in wall bands as thin as the grid allows, the hard cases the solver tests keep.
SHEARED_CHI_WITHOUT_STATIC = {"a": 0.0, "exponent": 2.1552, "c": 0.8852, "shear_amplitude": 0.386, "mu_scale": 0.5879,
                              "amplitude_growth": 1.203}

#: ρ_s V² [Pa] of the test cell (2500 kg/m³, V = 1 m/s): the Johnson–Jackson stress (Pa) in solver units.
SCALE = 2500.0


def frictional_wall_problem(mu, mean_phi, angle=0.0, stress="schaeffer", eps=1e-3, n=80, e=0.7, **options):
    """The map's cell: 20 d planar, JJ walls φ' = 0.2, e_w = 0.85 with wall friction angle δ_w = ``angle`` (degrees).

    ``eps`` is both the frictional viscosity's regularisation and the wall's slip regularisation ε_w; ``options``
    go to the model (``frictional``)."""
    model = get_model("frictional", mu=mu, stress=stress, regularisation=eps, **options)
    g = PlanarCell(20.0, 1.0)
    x0, x1 = g.bounds(1.0)
    w = Wall(specularity=0.2, restitution=0.85, friction_angle=angle, slip_regularisation=eps)
    return Problem(model, g, w, w, mean_phi, e, stretched_nodes(x0, x1, n, 1.5), v_scale=1.0, stress_scale=SCALE)


def halving_changes(mu, mean_phi, eps, angle=0.0, stress="schaeffer", start=None, res_tol=1e-8):
    """Profiles at ε and ε/2 (the second started from the first; ε also the wall's ε_w): their differences.

    Returns a dict: du (max |Δu|/U), dphi, dlnt (max |Δ ln θ|), dtau (|Δτ_w/τ_w|), dslip (|Δu_sl|/U at the bottom
    wall), min_rate (min γ̇/(U/H) at ε), and X (the solution at ε/2)."""
    a = frictional_wall_problem(mu, mean_phi, angle, stress, eps=eps)
    Xa, _ = solve(a, start)
    b = frictional_wall_problem(mu, mean_phi, angle, stress, eps=eps / 2)
    Xb, info = solve(b, Xa)
    assert info["residual"] < res_tol
    (ua, ta, pa), (ub, tb, pb) = a.unpack(Xa), b.unpack(Xb)
    tA, tB = a.terms(Xa), b.terms(Xb)
    return {"du": np.abs(ua - ub).max(), "dphi": np.abs(pa - pb).max(), "dlnt": np.abs(np.log(ta / tb)).max(),
            "dtau": abs(tB["F"].mean() / tA["F"].mean() - 1), "dslip": abs(tA["slip"][0] - tB["slip"][0]),
            "min_rate": float(np.abs(np.diff(ua) / a.dx).min() / a.reference_shear_rate), "X": Xb,
            "residual": info["residual"]}
