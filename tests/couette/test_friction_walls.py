"""Frictional walls in the Couette cell: the Johnson–Jackson frictional wall traction p_f tan δ_w (docs/friction.md §8)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf import get_model
from ktgf.couette import PlanarCell, Wall
from ktgf.couette.equations import Problem
from ktgf.couette.geometry import stretched_nodes
from ktgf.couette.run import Material, to_dataset
from ktgf.couette.solver import naive_start, solve
from ktgf.couette.walls import jj_friction, jj_frictional_wall_stress
from ktgf.errors import InputError

SCALE = 2500.0  # ρ_s V² [Pa] of the test cell


#: the frictional stress switched on from φ = 0.45 (MFiX/OpenFOAM: 0.5), so that it acts at the walls of a φ̄ = 0.5 cell
OPTIONS = {"mu": 0.5, "stress": "schaeffer", "jj_phi_min": 0.45}


def _problem(wall, mean_phi=0.5, n=80, **options):
    model = get_model("frictional", **{**OPTIONS, **options})
    g = PlanarCell(20.0, 1.0)
    x0, x1 = g.bounds(1.0)
    return Problem(model, g, wall, wall, mean_phi, 0.7, stretched_nodes(x0, x1, n, 1.5), v_scale=1.0, stress_scale=SCALE)


@pytest.mark.analytic
def test_frictional_wall_stress_formula_and_limits():
    wall = Wall(friction_angle=30.0)
    slip = np.array([-2.0, -1e-9, 0.0, 1e-9, 2.0])
    tau = jj_frictional_wall_stress(wall, 3.0, slip, 1e-4)
    np.testing.assert_allclose(tau[[0, -1]], [-3.0 * math.tan(math.pi / 6), 3.0 * math.tan(math.pi / 6)], rtol=2e-9)
    assert tau[2] == 0.0 and abs(tau[1]) < 1e-4 and tau[1] == -tau[3]  # regularised, odd in the slip
    assert np.all(jj_frictional_wall_stress(Wall(), 3.0, slip, 1e-4) == 0.0)  # δ_w = 0: nothing


@pytest.mark.contract
@pytest.mark.parametrize("angle", [-1.0, 90.0, 120.0, float("nan")])
def test_wall_friction_angle_out_of_range_is_a_one_line_error(angle):
    with pytest.raises(InputError, match="friction_angle") as info:
        Wall(friction_angle=angle)
    assert "\n" not in str(info.value)


@pytest.mark.contract
def test_wall_friction_needs_a_frictional_stress():
    with pytest.raises(InputError, match="bottom wall friction_angle = 20"):
        _problem(Wall(friction_angle=20.0), stress="none", jj_phi_min=0.5)


@pytest.mark.analytic
def test_zero_wall_friction_is_the_present_wall_exactly():
    base = _problem(Wall(specularity=0.2, restitution=0.85))
    zero = _problem(Wall(specularity=0.2, restitution=0.85, friction_angle=0.0))
    X = naive_start(base) + 0.02 * np.random.default_rng(5).standard_normal(3 * base.n)
    assert np.array_equal(base.residual(X), zero.residual(X))


@pytest.mark.analytic
def test_converged_wall_traction_is_collisional_plus_frictional_and_slip_drops():
    """μ = 0.5, φ̄ = 0.55 (p_f > 0 at the walls): the shear flux at the wall face equals c u_sl + p_f tan δ_w.

    δ_w = 20° is started from the δ_w = 0 solution (0.5 s; from the naive start it converges too, through the
    solver's continuation, in ~30 s: docs/friction.md §8)."""
    results, X = {}, None
    for angle in (0.0, 20.0):
        pr = _problem(Wall(specularity=0.2, restitution=0.85, friction_angle=angle), mean_phi=0.55, jj_phi_min=0.5)
        X, info = solve(pr, X)
        assert info["residual"] < 1e-8
        t = pr.terms(X)
        u, theta, phi = pr.unpack(X)
        slip = u[0] - pr.u_wall[0]
        cf = jj_friction(pr.walls[0], phi[0], pr.model.chi(phi[0]), theta[0])
        expected = cf * slip + t["p_frictional"][0] * math.tan(math.radians(angle)) * np.sign(slip)
        assert t["F"][0] == pytest.approx(expected, rel=1e-6)  # half-cell balance: face flux = wall traction
        results[angle] = (abs(slip), t["p_frictional"][0])
        # the frictional wall work p_f tan δ_w |u_sl| is dissipated at the wall contacts (not fed to θ): budget closes
        assert to_dataset(pr, X, Material(1.0, SCALE, 0.7)).attrs["energy_budget_relative_error"] < 1e-8
    assert results[20.0][1] > 0.0
    assert results[20.0][0] < results[0.0][0]  # wall friction holds the medium back
