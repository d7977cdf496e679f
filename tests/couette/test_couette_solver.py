"""Couette solver internals and robustness: Jacobian, convergence from a naive start over the practical range."""

from __future__ import annotations

import numpy as np
import pytest

from ktgf.closures import PAPER_MODELS, get_model
from ktgf.couette import AnnularCell, PlanarCell, Wall
from ktgf.couette.equations import Problem, phi_from_psi, psi_from_phi
from ktgf.couette.geometry import stretched_nodes
from ktgf.couette.solver import naive_start, solve


def _problem(name="ret", mean_phi=0.45, e=0.8, spec=0.2, geometry=None, n=40, walls=None, heat_flux="total"):
    w = Wall(specularity=spec, restitution=0.85, heat_flux=heat_flux)
    g = geometry or PlanarCell(20.0, 1.0)
    x0, x1 = g.bounds(1.0)
    bottom, top = walls or (w, w)
    return Problem(get_model(name), g, bottom, top, mean_phi, e, stretched_nodes(x0, x1, n, 1.5), v_scale=1.0)


@pytest.mark.analytic
@pytest.mark.parametrize("heat_flux", ["total", "conductive"])
@pytest.mark.parametrize("geometry", [PlanarCell(20.0, 1.0), AnnularCell(30.0, 50.0, 1 / 30.0)], ids=["planar", "annular"])
@pytest.mark.parametrize("name", PAPER_MODELS)
def test_coloured_jacobian_matches_directional_derivatives(name, geometry, heat_flux):
    """J·v from the coloured sparse Jacobian equals a central difference of the residual along random v."""
    pr = _problem(name, geometry=geometry, heat_flux=heat_flux)
    rng = np.random.default_rng(1)
    X = naive_start(pr) + 0.05 * rng.standard_normal(3 * pr.n)
    R = pr.residual(X)
    J = pr.jacobian(X, R)
    for _ in range(3):
        v = rng.standard_normal(X.size)
        h = 1e-5
        fd = (pr.residual(X + h * v) - pr.residual(X - h * v)) / (2 * h)
        np.testing.assert_allclose(J @ v, fd, rtol=1e-4, atol=1e-6 * np.abs(fd).max())


@pytest.mark.analytic
def test_phi_transform_round_trip_and_bounds():
    phi = np.array([1e-6, 0.1, 0.5, 0.6399999])
    np.testing.assert_allclose(phi_from_psi(psi_from_phi(phi, 0.64), 0.64), phi, rtol=1e-9)
    assert np.all(phi_from_psi(np.array([-800.0, 800.0]), 0.64) <= 0.64)


@pytest.mark.analytic
def test_independent_walls_mixed_conditions():
    """Bottom JJ wall, top wall with prescribed no-slip and temperature: conditions hold where imposed."""
    top = Wall(momentum="prescribed", energy="prescribed", temperature=0.001)
    bottom = Wall(specularity=0.3, restitution=0.8)
    pr = _problem("proposed", walls=(bottom, top), n=80)
    X, info = solve(pr)
    u, theta, phi = pr.unpack(X)
    assert u[-1] == pytest.approx(0.5, abs=1e-12)
    assert theta[-1] == pytest.approx(0.001, rel=1e-10)
    assert u[0] > -0.5  # JJ bottom wall slips


CORNERS = [
    ("enskog", 0.1, 0.5, 1e-3), ("ret", 0.62, 0.9, 1e-3), ("ret", 0.3, 0.5, 1e-3), ("visc-div", 0.62, 0.99, 1e-3),
    ("visc-div", 0.62, 0.9, 1.0), ("proposed", 0.62, 0.5, 1.0), ("proposed", 0.62, 0.9, 1e-3), ("enskog", 0.62, 0.99, 1.0),
]


@pytest.mark.contract
@pytest.mark.parametrize("name,mean_phi,e,spec", CORNERS)
def test_converges_from_naive_start_at_corners(name, mean_phi, e, spec):
    pr = _problem(name, mean_phi, e, spec, n=200)
    X, info = solve(pr)
    u, theta, phi = pr.unpack(X)
    assert info["residual"] < 1e-8
    assert np.all(theta > 0) and np.all(phi < pr.phi_max)
    assert pr.V @ phi / pr.V.sum() == pytest.approx(mean_phi, abs=1e-10)


@pytest.mark.contract
@pytest.mark.slow
@pytest.mark.parametrize("name", PAPER_MODELS)
@pytest.mark.parametrize("e", [0.7, 0.9, 0.99])
def test_converges_over_the_practical_range(name, e):
    """Mean φ 0.1 … 0.62 (φ_max − 0.02 for the φ_c = 0.64 RDFs), φ' 1e-3 … 1, 20 d cell, 200 cells."""
    failures = []
    for mean_phi in (0.1, 0.3, 0.5, 0.62):
        for spec in (1e-3, 1e-2, 0.1, 1.0):
            pr = _problem(name, mean_phi, e, spec, n=200)
            try:
                solve(pr)
            except Exception as exc:  # noqa: BLE001 - collect every failure for the message
                failures.append((mean_phi, spec, str(exc)[:80]))
    assert not failures, failures


# Known limits of the current solver, kept visible here (strict xfail: a fix shows up as XPASS).
# Strongly inelastic (e = 0.5) Visc.div. cells at mean φ 0.62: the only solution on the continuation path
# is a plug jammed to φ_c − φ < 1e-9 with θ ~ 1e-14 U²; φ_c − φ is then resolved to only ~1e-6 relative in
# double precision, so the residual cannot fall below ~1e-6 (docs/dense.md §5.2).  Such a state would be
# flagged invalid anyway (jammed core, collapsed temperature).  The case (visc-div, 0.3, 1.0), where the
# densest node crosses φ_f, had a fold on its continuation path: it converges with the arclength fallback.
KNOWN_FAILURES_E05 = {("visc-div", 0.62, 1e-3), ("visc-div", 0.62, 0.1)}


@pytest.mark.contract
@pytest.mark.slow
@pytest.mark.parametrize("name", PAPER_MODELS)
@pytest.mark.parametrize("mean_phi", [0.1, 0.3, 0.5, 0.62])
@pytest.mark.parametrize("spec", [1e-3, 0.1, 1.0])
def test_converges_at_strong_inelasticity(name, mean_phi, spec, request):
    if (name, mean_phi, spec) in KNOWN_FAILURES_E05:
        request.applymarker(pytest.mark.xfail(strict=True, reason="plug jammed to round-off, phi_c - phi < 1e-9"))
    pr = _problem(name, mean_phi, 0.5, spec, n=200)
    X, info = solve(pr)
    assert info["residual"] < 1e-8


@pytest.mark.analytic
@pytest.mark.parametrize("name", ["enskog", "ret"])
def test_literal_jj_heat_flux_option(name):
    """heat_flux="conductive" imposes JJ on κ∂θ/∂n literally; identical to "total" when ω = 0 (Enskog)."""
    sols = {}
    for form in ("total", "conductive"):
        pr = _problem(name, 0.45, 0.8, 0.2, n=200, heat_flux=form)
        X, _ = solve(pr)
        sols[form] = (pr, X)
    th_t = sols["total"][0].unpack(sols["total"][1])[1]
    th_c = sols["conductive"][0].unpack(sols["conductive"][1])[1]
    if name == "enskog":
        np.testing.assert_allclose(th_c, th_t, rtol=1e-9)
    else:
        assert np.max(np.abs(th_c / th_t - 1)) > 1e-3  # RET's ω∇φ matters at the wall
    # the literal condition κ_w ∂θ/∂n = D − G holds at the bottom wall to discretisation accuracy
    # (the scheme imposes it on the half-cell flux; compared here with a one-sided O(h²) gradient)
    from ktgf.couette.walls import jj_dissipation, jj_friction

    pr, X = sols["conductive"]
    u, theta, phi = pr.unpack(X)
    c = pr.model.coefficients(phi[:1], pr.e, theta[:1], d=1.0, rho_s=1.0, check=False)
    chi = pr.model.chi(phi[:1])
    w = pr.walls[0]
    slip = u[0] - pr.u_wall[0]
    D = jj_dissipation(w, phi[0], chi[0], theta[0])
    G = jj_friction(w, phi[0], chi[0], theta[0]) * slip**2
    dtheta = pr._wall_gradient(theta, 0)
    assert float(c.kappa[0]) * dtheta == pytest.approx(D - G, rel=1e-3)


def _stacked_cases():
    """Problems whose residual rows reach one node (paper models, JJ, bumpy and prescribed walls, the chute) and two
    (the sheared χ of ``dense``), with and without a frictional stress and wall friction."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from helpers.friction_couette import frictional_wall_problem

    from ktgf.couette.chute import InclinedLayer, build_chute
    from ktgf.couette.run import Material

    bumpy = Wall.of_type("bumpy", restitution=0.9)
    hot = Wall(momentum="prescribed", energy="prescribed", slip=0.0, temperature=0.02)
    return {
        "ret-jj": _problem("ret", n=24),
        "dense-sheared-chi": _problem("dense", mean_phi=0.5, n=24),
        "dense-bumpy": _problem("dense", mean_phi=0.45, n=24, walls=(bumpy, bumpy)),
        "enskog-prescribed": _problem("enskog", n=24, walls=(hot, Wall(specularity=0.3, restitution=0.9))),
        "annular-proposed": _problem("proposed", geometry=AnnularCell(30.0, 50.0, 1 / 30.0), n=24),
        "frictional-wall-friction": frictional_wall_problem(0.5, 0.55, 25.0, n=24),
        "chute": build_chute("ret", InclinedLayer(0.03, 20.0), 0.3, Material(d=1e-3, rho_s=2500.0, e=0.9),
                             n_cells=24),
    }


@pytest.mark.analytic
@pytest.mark.parametrize("case", ["ret-jj", "dense-sheared-chi", "dense-bumpy", "enskog-prescribed", "annular-proposed",
                                  "frictional-wall-friction", "chute"])
def test_stacked_coloured_jacobian_is_the_column_by_column_difference(case):
    """The Jacobian perturbs several nodes per colour and evaluates every perturbed state in one stacked residual
    call: each entry equals the central difference of the plain (one state) residual in that unknown alone, with the
    same step, to round-off; entries outside the colouring's stencil are zero there too (no coupling missed).  A stack
    of states gives each state's own residual."""
    from ktgf.couette.chute import bagnold_start

    pr = _stacked_cases()[case]
    rng = np.random.default_rng(3)
    X = (bagnold_start(pr) if case == "chute" else naive_start(pr)) + 0.02 * rng.standard_normal(3 * pr.n)
    J = pr.jacobian(X, pr.residual(X)).toarray()
    ref = np.empty_like(J)
    for c in range(X.size):
        h = pr.fd_step * (1.0 + abs(X[c]))
        up, down = X.copy(), X.copy()
        up[c] += h
        down[c] -= h
        ref[:, c] = (pr.residual(up) - pr.residual(down)) / (2.0 * h)
    inventory = (pr.n - 1) * 3 + 2  # the exact row: compare its pattern only
    scale = np.abs(ref).max(axis=1, keepdims=True) + 1e-300
    off = np.abs(np.delete(J - ref, inventory, axis=0)) / np.delete(scale, inventory, axis=0)
    assert off.max() < 1e-6, (np.unravel_index(off.argmax(), off.shape), off.max())
    stack = X + 1e-3 * rng.standard_normal((3, X.size))
    each = np.stack([pr.residual(x) for x in stack])
    np.testing.assert_allclose(pr.residual(stack), each, rtol=1e-12, atol=1e-14 * np.abs(each).max())
