"""Pseudo-arclength continuation (ktgf.couette.arclength) and the Couette cases it makes converge."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp

from ktgf.closures import get_model
from ktgf.couette import PlanarCell, Wall, arclength
from ktgf.couette.run import Material, build_problem, run
from ktgf.couette.solver import solve


class _Cubic:
    """x³ − 3x = μ(λ) in the first unknown (two trivial ones besides): an S-curve with folds at μ = ±2."""

    def __init__(self, mu):
        self.mu = mu

    def terms(self, X):
        return {}

    def residual(self, X, t=None):
        return np.array([X[0] ** 3 - 3.0 * X[0] - self.mu, X[1], X[2]])

    def residual_scales(self, t):
        return np.ones(3) * (1.0 + abs(self.mu))

    def jacobian(self, X, R):
        return sp.csc_matrix(np.diag([3.0 * X[0] ** 2 - 3.0, 1.0, 1.0]))


def _root(mu):
    """The real root of x³ − 3x − μ = 0 for |μ| > 2 (Cardano)."""
    s = math.sqrt(mu * mu / 4.0 - 1.0)
    cbrt = lambda v: math.copysign(abs(v) ** (1 / 3), v)  # noqa: E731
    return cbrt(mu / 2.0 + s) + cbrt(mu / 2.0 - s)


@pytest.mark.analytic
def test_follows_an_s_curve_through_both_folds():
    """μ = 8λ − 4: from the lower branch at λ = 0 to the upper one at λ = 1, through the folds at λ = 3/4 and 1/4."""
    family = lambda lam: _Cubic(8.0 * lam - 4.0)  # noqa: E731
    X0 = np.array([_root(-4.0), 0.0, 0.0])
    X, path = arclength.follow(family, X0, 0.0, 1.0, ds0=0.05)
    assert X[0] == pytest.approx(_root(4.0), rel=1e-9)  # 2.1958…, the only root at μ = 4
    assert len(path.folds) == 2
    assert path.folds[0] == pytest.approx(0.75, abs=0.02) and path.folds[1] == pytest.approx(0.25, abs=0.02)
    # it went along the middle branch (−1 < x < 1), which natural-parameter continuation never reaches
    assert any(-0.9 < X[0] < 0.9 for X in path.X)


@pytest.mark.analytic
def test_says_when_the_curve_turns_back():
    """x² = 1/2 − λ has no solution beyond the fold at λ = 1/2: the path comes back and says so."""

    class Parabola(_Cubic):
        def residual(self, X, t=None):
            return np.array([X[0] ** 2 - self.mu, X[1], X[2]])

        def jacobian(self, X, R):
            return sp.csc_matrix(np.diag([2.0 * X[0], 1.0, 1.0]))

    family = lambda lam: Parabola(0.5 - lam)  # noqa: E731
    with pytest.raises(arclength.ArclengthStall, match="turned back") as info:
        arclength.follow(family, np.array([math.sqrt(0.5), 0.0, 0.0]), 0.0, 1.0)
    assert info.value.path.folds == [pytest.approx(0.5, abs=0.01)]
    assert info.value.X[0] < 0  # it came back on the other branch, x = −√(1/2 − λ)


def _dem_cell(spec, n_cells):
    """The DEM Couette cell (H = 19 d, U = 10, ρ_s = 6/π, mean φ 0.5) at e = e_w = 0.7, Visc.div."""
    w = Wall(specularity=spec, restitution=0.7)
    return build_problem(get_model("visc-div"), PlanarCell(19.0, 10.0), w, w, 0.5,
                         Material(1.0, 6 / math.pi, 0.7), n_cells, 1.5)


@pytest.mark.contract
def test_dem_cell_e07_converges_and_its_continuation_passes_the_folds():
    """A case natural-parameter continuation stalled on (docs/dense.md §5.2).

    Which path ``solve`` takes here hangs on round-off: since the quarter-power closures (a few ulp
    from ``pow``) Newton from the naive start converges by itself; before them it needed the
    arclength fallback.  So the state is checked whatever the path, and the fallback is run along
    each homotopy path on its own: each passes two folds and lands on the same state.
    """
    from ktgf.couette.solver import _follow, homotopy_paths, relative_residual

    pr = _dem_cell(0.16773, 40)
    X, info = solve(pr)
    u, theta, phi = pr.unpack(X)
    assert info["residual"] < 1e-8
    assert np.all(theta > 0) and phi.max() < pr.phi_max
    assert pr.V @ phi / pr.V.sum() == pytest.approx(0.5, abs=1e-10)
    for stages in homotopy_paths(pr):
        Xc, _, _, folds, arclength_stages = _follow(pr, stages, [], tol=1e-10, max_iter=60, ptc_max_iter=400,
                                                           continuation="fallback")
        assert arclength_stages >= 1 and len(folds) >= 2, folds
        assert relative_residual(pr, Xc) < 1e-8
        assert np.abs(Xc - X).max() < 1e-9 * np.abs(X).max()


@pytest.mark.regression
def test_unjammed_branch_ends_at_a_fold_in_specularity():
    """At mean φ 0.5 the unjammed solution (spec 0.245) folds back near spec 0.232 onto a near-jammed branch.

    So at spec 0.245 there are (at least) two solutions, and below the fold no unjammed one: the
    e = 0.7 stalls had no physical solution to find (docs/dense.md §5.2).
    """
    s0, s1 = 0.245, 0.16
    pr0 = _dem_cell(s0, 200)
    X0, _ = solve(pr0)
    family = lambda lam: _dem_cell(math.exp(math.log(s0) + lam * math.log(s1 / s0)), 200)  # noqa: E731
    with pytest.raises(arclength.ArclengthStall, match="turned back") as info:
        arclength.follow(family, X0, 0.0, 1.0, lam_min=-0.05)
    (fold,) = info.value.path.folds
    assert 0.225 < math.exp(math.log(s0) + fold * math.log(s1 / s0)) < 0.24
    back = info.value.X  # the other solution at spec ≈ 0.245 (λ ≈ 0)
    assert pr0.unpack(X0)[2].max() < 0.99 * 0.64 < pr0.unpack(back)[2].max()


@pytest.mark.regression
@pytest.mark.slow(minutes=0.4)  # 51 s here 8 Dec (2.2x slower host), stacked Jacobian
def test_dem_cell_e07_every_specularity_converges():
    """All 12 specularities 0.16–0.245 at 200 cells converge; below the fold only a jammed plug exists.

    The validity flag of the run says so: jammed (invalid) below spec ≈ 0.232, valid above.
    """
    failures, verdicts = [], {}
    for spec in np.linspace(0.16, 0.245, 12):
        w = Wall(specularity=float(spec), restitution=0.7)
        try:
            ds = run(get_model("visc-div"), PlanarCell(19.0, 10.0), w, w, 0.5, Material(1.0, 6 / math.pi, 0.7),
                     n_cells=200, stretch=1.5)
        except Exception as exc:  # noqa: BLE001 - collect every failure
            failures.append((spec, str(exc)[:120]))
            continue
        assert ds.attrs["solver_relative_residual"] < 1e-8
        assert float(ds["theta"].min()) > 0 and ds.attrs["max_phi"] < 0.64
        verdicts[round(float(spec), 5)] = bool(ds.attrs["physically_valid"])
    assert not failures, failures
    assert all(v == (s > 0.232) for s, v in verdicts.items()), verdicts


@pytest.mark.analytic
@pytest.mark.slow(minutes=0.4)
def test_a_cell_whose_continuation_snakes_is_reached_from_its_coarse_grid():
    """``frictional`` with the sheared-χ fit without its static part (μ 0.5, Schaeffer, e 0.7), φ̄ 0.57, 10 d planar
    cell, JJ walls φ' 0.1,
    200 cells: continuation in φ̄ on this grid stalls among fold pairs (measured: 153 s, then the error; not rerun
    here), while mesh sequencing solves the cell on 50 cells and reaches 200 by Newton from the interpolated
    solution.  The state conserves what it must: inventory and energy budget."""
    from helpers.friction_couette import SHEARED_CHI_WITHOUT_STATIC

    from ktgf.couette.run import to_dataset
    from ktgf.couette.solver import _mesh_sequenced

    model = get_model("frictional", mu=0.5, stress="schaeffer", **SHEARED_CHI_WITHOUT_STATIC)
    w = Wall(specularity=0.1, restitution=0.9)
    material = Material(1e-3, 2500.0, 0.7)
    pr = build_problem(model, PlanarCell(0.01, 1.0), w, w, 0.57, material, 200, 1.5)
    X, info = _mesh_sequenced(pr, 1e-10, 60, 400, "natural")
    assert info["path"].startswith("mesh-sequencing (") and info["path"].endswith("on 50 cells)"), info["path"]
    assert info["residual"] < 1e-10
    phi = pr.unpack(X)[2]
    assert float(np.sum(pr.V * phi) / pr.V.sum()) == pytest.approx(0.57, rel=1e-10)
    assert to_dataset(pr, X, material).attrs["energy_budget_relative_error"] < 1e-8


@pytest.mark.contract
def test_mesh_sequencing_is_the_last_fallback(monkeypatch):
    """Where Newton from the start, pseudo-transient continuation and every homotopy path fail on the grid (made to
    fail here), ``solve`` returns the mesh-sequenced state (RET cell, 100 cells, from 50); where sequencing fails
    too, the error names both."""
    from ktgf.couette import solver as sv

    real_newton, calls = sv.newton, []

    def newton_failing_first(problem, X, **kw):  # the Newton from the start fails; later ones are real
        calls.append(problem.n)
        if len(calls) == 1:
            return X, sv.NewtonReport(False, 0, message="made to fail")
        return real_newton(problem, X, **kw)

    def fail_on_fine_grids(real):
        def wrapped(problem, *args, **kw):
            if problem.n > sv.COARSEST_NODES:
                raise sv.CouetteConvergenceError("made to fail", [], np.zeros(1), problem)
            return real(problem, *args, **kw)
        return wrapped

    def ptc_failing(problem, X, **kw):
        return X, sv.NewtonReport(False, 0, message="made to fail")

    monkeypatch.setattr(sv, "newton", newton_failing_first)
    monkeypatch.setattr(sv, "pseudo_transient", ptc_failing)
    monkeypatch.setattr(sv, "_follow", fail_on_fine_grids(sv._follow))
    w = Wall(specularity=0.2, restitution=0.85)
    pr = build_problem(get_model("ret"), PlanarCell(0.02, 1.0), w, w, 0.45, Material(1e-3, 2500.0, 0.8), 100, 1.5)
    X, info = solve(pr)
    assert info["path"] == "mesh-sequencing (newton on 50 cells)" and info["residual"] < 1e-10
    assert calls == [101, 51, 101]  # the failed start, the coarse grid, Newton back on the fine grid
    direct, _ = real_newton(pr, X, tol=1e-10, max_iter=5)
    np.testing.assert_allclose(direct, X, atol=1e-9)  # a steady state of the fine grid itself

    def follow_failing(problem, *args, **kw):
        where = "fine" if problem.n > sv.COARSEST_NODES else "coarse"
        raise sv.CouetteConvergenceError(f"{where} made to fail", [], np.zeros(1), problem)

    monkeypatch.setattr(sv, "newton", ptc_failing)
    monkeypatch.setattr(sv, "_follow", follow_failing)
    both = "^fine made to fail; then mesh sequencing failed: coarse made to fail$"
    with pytest.raises(sv.CouetteConvergenceError, match=both):
        solve(pr)
