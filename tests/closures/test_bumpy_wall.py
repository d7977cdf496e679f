"""Bumpy wall of fixed spheres (ktgf.closures.bumpy_wall): exact geometry, exact limits, a Monte Carlo of collisions.

Oracles: sphere-packing geometry (a sphere nested on three touching equal spheres sits √(2/3) d above their
centres; between two it touches at 30° from the normal; a touching hexagonal layer has 2/√3 spheres per d²),
the flat frictionless wall (S = 0, Q/(N√T) = −(1 − e_w)√(2/π) for a Maxwellian), and a direct Monte Carlo
average of single collisions that shares nothing with the quadrature but the collision rule.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf.closures.bumpy_wall import BumpyWall, wall_conditions, wall_fluxes
from ktgf.errors import InputError

SLIPS = np.array([0.0, 0.3, 1.0, 2.5])


@pytest.mark.analytic
def test_geometry_of_a_touching_layer_of_equal_spheres() -> None:
    wall = BumpyWall()
    assert math.degrees(wall.bumpiness) == pytest.approx(30.0, rel=1e-14)
    assert wall.resting_height == pytest.approx(math.sqrt(2.0 / 3.0), rel=1e-14)
    assert wall.spheres_per_area == pytest.approx(2.0 / math.sqrt(3.0), rel=1e-14)
    # toward a neighbour the cap ends at the bumpiness angle, over a hollow at arccos(h/σ)
    assert wall.theta_max(0.0) == pytest.approx(wall.bumpiness, rel=1e-14)
    assert wall.theta_max(math.pi / 6.0) == pytest.approx(math.acos(wall.resting_height / wall.sigma), rel=1e-12)


@pytest.mark.analytic
@pytest.mark.parametrize("wall", [BumpyWall(), BumpyWall(d_w=0.5, gap=0.2, row_angle=0.4), BumpyWall(d_w=2.0)])
def test_cap_boundary_agrees_with_the_distances_to_the_neighbours(wall) -> None:
    psi = np.linspace(-math.pi, math.pi, 181)
    for eps, expect in ((-1e-9, True), (1e-9, False)):
        t = wall.theta_max(psi) + eps
        k = np.stack([np.sin(t) * np.cos(psi), np.sin(t) * np.sin(psi), np.cos(t)], axis=-1)
        assert np.all(wall.accessible(k) == expect)


@pytest.mark.analytic
def test_no_slip_gives_no_shear_and_an_elastic_wall_no_energy_flux() -> None:
    f = wall_fluxes(BumpyWall(), 0.0, 0.9)
    assert abs(float(f.shear_over_normal)) < 1e-15
    assert float(f.energy_over_normal) == pytest.approx(-float(f.dissipation_over_normal), rel=1e-15)
    assert float(f.energy_over_normal) < 0.0
    assert float(wall_fluxes(BumpyWall(), 0.0, 1.0).energy_over_normal) == 0.0


@pytest.mark.analytic
def test_shear_is_odd_and_energy_even_in_the_slip() -> None:
    wall = BumpyWall()
    plus, minus = wall_fluxes(wall, SLIPS, 0.8), wall_fluxes(wall, -SLIPS, 0.8)
    assert plus.shear_over_normal == pytest.approx(-minus.shear_over_normal, abs=1e-14)
    assert plus.energy_over_normal == pytest.approx(minus.energy_over_normal, rel=1e-12)
    assert np.all(np.diff(plus.shear_over_normal) > 0)  # more slip, more drag


@pytest.mark.analytic
def test_tiny_bumps_are_a_flat_frictionless_wall() -> None:
    for e_w in (0.5, 0.9):
        f = wall_fluxes(BumpyWall(d_w=1e-4), SLIPS, e_w)
        assert np.max(np.abs(f.shear_over_normal)) < 1e-3
        assert f.energy_over_normal == pytest.approx(-(1.0 - e_w) * math.sqrt(2.0 / math.pi), rel=1e-3)


@pytest.mark.analytic
def test_quadrature_is_converged() -> None:
    wall = BumpyWall(d_w=1.0, gap=0.1, row_angle=0.2)
    a = wall_fluxes(wall, SLIPS, 0.9)
    b = wall_fluxes(wall, SLIPS, 0.9, n_psi=48, n_theta=48)
    for x, y in zip(a[:3], b[:3]):
        assert x == pytest.approx(y, rel=1e-10, abs=1e-13)


@pytest.mark.analytic
@pytest.mark.parametrize("slip, e_w, wall", [(0.5, 0.9, BumpyWall()), (1.5, 0.7, BumpyWall()),
                                             (1.0, 0.9, BumpyWall(d_w=0.6, gap=0.3, row_angle=0.5))])
def test_monte_carlo_of_single_collisions_reproduces_the_ratios(slip, e_w, wall) -> None:
    # normals uniform on a polar cap that contains the accessible one, kept if no wall sphere is overlapped
    rng = np.random.default_rng(12345)
    cap = float(np.max(wall.theta_max(np.linspace(-math.pi, math.pi, 721)))) + 0.02
    batches = []
    for _ in range(16):
        n = 150_000
        cos_t = 1.0 - rng.random(n) * (1.0 - math.cos(cap))
        sin_t, psi = np.sqrt(1.0 - cos_t**2), rng.random(n) * 2.0 * math.pi
        k = np.stack([sin_t * np.cos(psi), sin_t * np.sin(psi), cos_t], axis=1)
        k = k[wall.accessible(k)]
        g = rng.normal(size=k.shape)  # Maxwellian, T = 1, drifting at the slip along x
        g[:, 0] += slip
        w = np.sum(g * k, axis=1)
        rate = np.where(w < 0.0, -w, 0.0)  # collisions per unit solid angle ∝ approach speed
        dc = -(1.0 + e_w) * np.minimum(w, 0.0)[:, None] * k
        fluct = g - np.array([slip, 0.0, 0.0])
        d_energy = 0.5 * (np.sum((fluct + dc) ** 2, axis=1) - np.sum(fluct**2, axis=1))
        batches.append([np.mean(rate * dc[:, 2]), np.mean(rate * -dc[:, 0]), np.mean(rate * d_energy)])
    b = np.array(batches)
    ratios = np.stack([b[:, 1] / b[:, 0], b[:, 2] / b[:, 0]], axis=1)
    estimate = b[:, 1:].mean(axis=0) / b[:, 0].mean()
    error = ratios.std(axis=0, ddof=1) / math.sqrt(len(b))
    f = wall_fluxes(wall, slip, e_w)
    for mc, se, exact in zip(estimate, error, (f.shear_over_normal, f.energy_over_normal)):
        assert abs(mc - float(exact)) < 4.0 * se + 1e-12
        assert se < 0.05 * abs(float(exact))  # and the check is sharp


@pytest.mark.contract
@pytest.mark.parametrize("kwargs, text", [
    ({"d_w": 0.0}, "wall-sphere diameter d_w = 0 is out of range"),
    ({"gap": 0.8}, "wall-sphere gap = 0.8 is out of range"),
    ({"gap": -0.1}, "wall-sphere gap = -0.1 is out of range"),
])
def test_bad_walls_are_refused_in_one_line(kwargs, text) -> None:
    with pytest.raises(InputError) as err:
        BumpyWall(**kwargs)
    assert text in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(InputError, match="wall restitution coefficient restitution = 1.2 is out of range"):
        wall_fluxes(BumpyWall(), 0.5, 1.2)


@pytest.mark.analytic
def test_jax_values_and_slip_derivative() -> None:
    jax = pytest.importorskip("jax")
    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    wall = BumpyWall()
    f_np = wall_fluxes(wall, SLIPS, 0.9)
    f_jx = wall_fluxes(wall, jnp.asarray(SLIPS), 0.9)
    for a, b in zip(f_np, f_jx):
        assert np.asarray(b) == pytest.approx(a, rel=1e-13, abs=1e-15)
    dfds = jax.grad(lambda s: wall_fluxes(wall, s, 0.9).shear_over_normal)(jnp.asarray(1.2))
    h = 1e-5
    fd = (wall_fluxes(wall, 1.2 + h, 0.9).shear_over_normal
          - wall_fluxes(wall, 1.2 - h, 0.9).shear_over_normal) / (2 * h)
    assert float(dfds) == pytest.approx(float(fd), rel=1e-8)


@pytest.mark.analytic
def test_large_slip_tends_to_the_geometric_drag_of_the_upstream_faces() -> None:
    # v/√T → ∞: only faces with k_x < 0 are hit, at |w| ≈ v|k_x|, so S/N → ∫|k_x|³ dΩ / ∫ k_x² cos θ dΩ over them
    wall = BumpyWall()
    rng = np.random.default_rng(7)
    k = rng.normal(size=(2_000_000, 3))
    k /= np.linalg.norm(k, axis=1, keepdims=True)
    k[:, 2] = np.abs(k[:, 2])
    k = k[wall.accessible(k) & (k[:, 0] < 0.0)]
    limit = np.mean(-k[:, 0] ** 3) / np.mean(k[:, 0] ** 2 * k[:, 2])
    assert float(wall_fluxes(wall, 1e4, 0.9).shear_over_normal) == pytest.approx(limit, rel=5e-3)


@pytest.mark.analytic
def test_dimensional_conditions_scale_with_the_normal_stress_and_the_thermal_speed() -> None:
    wall = BumpyWall()
    f = wall_fluxes(wall, 1.5, 0.8)
    shear, flux = wall_conditions(wall, 250.0, 0.04, 0.3, 0.8)  # Pa, m²/s², m/s: v/√θ = 1.5
    assert shear == pytest.approx(250.0 * float(f.shear_over_normal), rel=1e-14)
    assert flux == pytest.approx(250.0 * 0.2 * float(f.energy_over_normal), rel=1e-14)
    back, _ = wall_conditions(wall, 250.0, 0.04, -0.3, 0.8)
    assert back == pytest.approx(-shear, rel=1e-14)
