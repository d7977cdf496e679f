"""Couette with the dense-regime parts: the EKT option in the solver, and cases the φ_f kink used to stall."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.couette import PlanarCell, Wall
from ktgf.couette.equations import Problem
from ktgf.couette.geometry import stretched_nodes
from ktgf.couette.solver import naive_start


def _problem(model, mean_phi=0.5, e=0.9, spec=0.13, n=40):
    w = Wall(specularity=spec, restitution=e)
    g = PlanarCell(19.0, 10.0)
    x0, x1 = g.bounds(1.0)
    return Problem(model, g, w, w, mean_phi, e, stretched_nodes(x0, x1, n, 1.5), v_scale=10.0)


@pytest.mark.analytic
def test_ekt_with_negligible_length_is_the_standard_residual():
    """c → 0 makes L = d everywhere: the residual is the standard theory's, bit for bit."""
    base = _problem(get_model("dense", dissipation="none"))
    tiny = _problem(get_model("dense", c=1e-12))
    X = naive_start(base) + 0.01 * np.random.default_rng(0).standard_normal(3 * base.n)
    np.testing.assert_array_equal(base.residual(X), tiny.residual(X))


@pytest.mark.analytic
def test_ekt_reduces_the_dissipation_source_by_d_over_l():
    """γ = (3/2)φθζ0 at the nodes is divided by L/d = max(1, Λ s), s = |du/dy|/√θ (planar cell); χ without its sheared
    part, so that Λ(φ, χ) is the one written here."""
    base = _problem(get_model("dense", dissipation="none", shear_amplitude=0.0), n=60)
    ekt = _problem(get_model("dense", c=3.0, shear_amplitude=0.0), n=60)
    X = naive_start(base)
    u, theta, phi = base.unpack(X)
    t0, t1 = base.terms(X), ekt.terms(X)
    rate_f = np.abs(np.diff(u) / np.diff(base.x))
    rate = np.concatenate([rate_f[:1], 0.5 * (rate_f[1:] + rate_f[:-1]), rate_f[-1:]])
    m = ekt.model
    lam = m.dissipation.coefficient(phi, 0.9, m.chi(phi))
    length = np.maximum(1.0, lam * rate / np.sqrt(theta))
    assert np.any(length > 1.0)
    np.testing.assert_allclose(t1["gamma"], t0["gamma"] / length, rtol=1e-12)


@pytest.mark.analytic
def test_ekt_jacobian_matches_directional_derivatives():
    pr = _problem(get_model("dense", c=2.0))
    rng = np.random.default_rng(2)
    X = naive_start(pr) + 0.05 * rng.standard_normal(3 * pr.n)
    J = pr.jacobian(X, pr.residual(X))
    for _ in range(3):
        v = rng.standard_normal(X.size)
        h = 1e-5
        fd = (pr.residual(X + h * v) - pr.residual(X - h * v)) / (2 * h)
        np.testing.assert_allclose(J @ v, fd, rtol=1e-4, atol=1e-6 * np.abs(fd).max())


# The DEM cell (H = 19 d, U = 10, ρ_s = 6/π, mean φ 0.5) at e = e_w = 0.7 with Visc.div.: natural-parameter
# continuation stalled for 5 of 12 specularities in 0.16–0.245 at a fold of the path (max φ ≈ 0.496 just past
# φ_f); the arclength fallback passes it (docs/dense.md §5.2, tests/couette/test_couette_arclength.py).  The solution
# it reaches is a jammed plug: below specularity ≈ 0.232 the model has no unjammed solution, and the run's
# validity flag says so.
@pytest.mark.contract
@pytest.mark.slow
def test_visc_div_dem_cell_at_e07_converges_to_a_flagged_jammed_plug():
    from ktgf.couette.run import Material, run

    w = Wall(specularity=0.16773, restitution=0.7)
    ds = run(get_model("visc-div"), PlanarCell(19.0, 10.0), w, w, 0.5, Material(1.0, 6 / math.pi, 0.7),
             n_cells=200, stretch=1.5)
    assert ds.attrs["solver_relative_residual"] < 1e-8
    assert ds.attrs["physically_valid"] == 0 and "jammed core" in ds.attrs["validity"]
