"""Frictional collisions: effective restitution laws, their limits, derivatives and the rough-sphere
collision integrals checked against a direct Monte Carlo of the collision rule."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from ktgf.closures.friction import (
    ChialvoSundaresanRestitution,
    RoughSphereRestitution,
    WaltonRestitution,
    modified_cooling_rate,
)
from ktgf.closures.friction.collisions import _walton_moments
from ktgf.errors import InputError

jax = pytest.importorskip("jax")
jnp = jax.numpy


@pytest.mark.published
def test_chialvo_sundaresan_published_form_and_limits():
    law = ChialvoSundaresanRestitution()
    # e_eff = e − (3/2) μ exp(−3μ): at μ = 0.5, e = 0.7 this is 0.7 − 0.75 e^(−1.5).
    assert law.effective_restitution(0.7, 0.5) == pytest.approx(0.7 - 0.75 * math.exp(-1.5), rel=1e-14)
    e = np.linspace(0.1, 1.0, 7)
    np.testing.assert_array_equal(law.effective_restitution(e, 0.0), e)  # frictionless: exactly e
    assert law.effective_restitution(0.7, 50.0) == pytest.approx(0.7, abs=1e-50)  # the fit returns to e
    # largest reduction a/(b·exp 1) at μ = 1/b
    mus = np.linspace(0.0, 3.0, 30001)
    red = 0.7 - law.effective_restitution(0.7, mus)
    assert mus[np.argmax(red)] == pytest.approx(1.0 / 3.0, abs=1e-4)
    assert red.max() == pytest.approx(1.5 / (3.0 * math.e), rel=1e-8)


@pytest.mark.analytic
def test_chialvo_sundaresan_derivative_matches_autodiff():
    law = ChialvoSundaresanRestitution()
    grad = jax.grad(lambda mu: law.effective_restitution(0.7, mu))
    for mu in (0.0, 0.1, 0.5, 1.3):
        assert float(grad(mu)) == pytest.approx(float(law.d_effective_restitution_dmu(0.7, mu)), rel=1e-12, abs=1e-14)


@pytest.mark.analytic
def test_modified_cooling_rate_is_unchanged_without_friction():
    law = ChialvoSundaresanRestitution()
    z = np.array([0.2, 0.5])
    np.testing.assert_array_equal(modified_cooling_rate(z, 0.7, law.inelasticity(0.7, 0.0)), z)
    # friction only adds dissipation
    assert np.all(modified_cooling_rate(z, 0.7, law.inelasticity(0.7, 0.5)) > z)


def _monte_carlo(e, beta, T, R, n=400_000, seed=3, q=0.4, mu=None):
    """Mean translational and rotational energy change per collision (collision-rate weighted).

    With ``mu`` the tangential restitution is Walton's min(β0, −1 + μ(1 + e)(1 + 1/q)|g_n|/|g_ct|), β0 = ``beta``.
    """
    rng = np.random.default_rng(seed)
    m, a = 1.0, 0.5
    inertia = q * m * a**2
    v = rng.normal(0.0, math.sqrt(T / m), (2, n, 3))
    w = rng.normal(0.0, math.sqrt(R / inertia), (2, n, 3))
    nrm = rng.normal(size=(n, 3))
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    g = v[0] - v[1]
    rate = np.maximum((g * nrm).sum(1), 0.0)  # approaching pairs, weighted by |g·n|
    gc = g + np.cross(w[0] + w[1], a * nrm)  # relative velocity of the contact points
    gcn = (gc * nrm).sum(1)[:, None] * nrm
    if mu is not None:
        slip = np.linalg.norm(gc - gcn, axis=1) + 1e-300
        beta = np.minimum(beta, -1 + mu * (1 + e) * (1 + 1 / q) * np.abs((g * nrm).sum(1)) / slip)[:, None]
    impulse = -(m / 2) * (1 + e) * gcn - (1 + beta) * (gc - gcn) / ((2 / m) * (1 + 1 / q))
    v1, v2 = v[0] + impulse / m, v[1] - impulse / m
    w1, w2 = w[0] + np.cross(a * nrm, impulse) / inertia, w[1] + np.cross(a * nrm, impulse) / inertia
    d_tr = 0.5 * m * ((v1**2).sum(1) + (v2**2).sum(1) - (v[0] ** 2).sum(1) - (v[1] ** 2).sum(1))
    d_rot = 0.5 * inertia * ((w1**2).sum(1) + (w2**2).sum(1) - (w[0] ** 2).sum(1) - (w[1] ** 2).sum(1))
    # normalise by (m/4)<(g·n)^2>, which equals T for a Maxwellian: the smooth loss is then (1 − e²)T
    norm = (rate * (g * nrm).sum(1) ** 2).mean() * m / 4
    return (rate * d_tr).mean() / norm, (rate * d_rot).mean() / norm


@pytest.mark.analytic
@pytest.mark.parametrize("e, beta, R", [(0.7, 0.5, 0.0), (0.7, 0.5, 0.6), (0.9, 0.0, 0.3), (0.5, 0.9, 1.2)])
def test_rough_sphere_coefficients_match_monte_carlo(e, beta, R):
    law = RoughSphereRestitution(beta=beta)
    A, B, C = law.collision_coefficients(e, 1.0)
    tr, rot = _monte_carlo(e, beta, 1.0, R)
    # the formulas give per-collision changes 4(−A T + B R) and 4(B T − C R) in these units
    assert tr == pytest.approx(4 * (-A + B * R), rel=0.015, abs=0.01)
    assert rot == pytest.approx(4 * (B - C * R), rel=0.015, abs=0.01)


@pytest.mark.analytic
def test_rough_sphere_limits():
    smooth = RoughSphereRestitution(beta=-1.0)
    assert smooth.effective_restitution(0.7, 0.5) == pytest.approx(0.7, rel=1e-14)
    assert smooth.rotational_ratio(0.7, 0.5) == 0.0
    rough = RoughSphereRestitution(beta=1.0)
    assert rough.rotational_ratio(1.0, 0.5) == pytest.approx(1.0, rel=1e-14)  # equipartition
    assert rough.effective_restitution(1.0, 0.5) == pytest.approx(1.0, abs=1e-7)  # no dissipation
    # μ = 0 means no tangential impulse whatever β
    fitted = RoughSphereRestitution(beta=0.7)
    assert fitted.effective_restitution(0.7, 0.0) == pytest.approx(0.7, rel=1e-14)
    assert fitted.rotational_ratio(0.7, 0.0) == 0.0
    # the steady rotational ratio 2(1 + β)/(9 − 5β) for solid spheres (q = 2/5)
    for beta in (-0.5, 0.0, 0.7):
        law = RoughSphereRestitution(beta=beta)
        assert law.rotational_ratio(0.7, 0.5) == pytest.approx(2 * (1 + beta) / (9 - 5 * beta), rel=1e-13)
        assert law.inelasticity(0.7, 0.5) > 1 - 0.7**2


@pytest.mark.analytic
def test_rotational_ratio_is_the_steady_state_of_the_collision_integrals():
    law = RoughSphereRestitution(beta=0.4)
    A, B, C = law.collision_coefficients(0.8, 0.5)
    r = law.rotational_ratio(0.8, 0.5)
    assert B - C * r == pytest.approx(0.0, abs=1e-15)
    assert law.inelasticity(0.8, 0.5) == pytest.approx(4 * (A - B * r), rel=1e-13)


@pytest.mark.contract
def test_bad_input_is_one_line():
    with pytest.raises(InputError, match="friction coefficient mu = -0.1"):
        ChialvoSundaresanRestitution().check(0.7, -0.1)
    with pytest.raises(InputError, match="tangential restitution beta = 1.5"):
        RoughSphereRestitution(beta=1.5)
    with pytest.raises(InputError, match="moment of inertia q = 0"):
        RoughSphereRestitution(q=0.0)
    with pytest.raises(InputError) as err:
        RoughSphereRestitution().check(0.7, -1.0)
    assert "\n" not in str(err.value)


@pytest.mark.analytic
def test_hcs_rotational_ratio_is_the_attractor_of_the_cooling_equations():
    """With dT/dτ = −A T + B R and dR/dτ = B T − C R (τ the collision time), r = R/T obeys
    dr/dτ = B + (A − C) r − B r²; integrated from r = 0 it must settle on the closed-form root."""
    from scipy.integrate import solve_ivp

    for e, beta in ((0.9, 0.5), (0.7, -0.3), (0.8, 0.95)):
        law = RoughSphereRestitution(beta=beta)
        A, B, C = law.collision_coefficients(e, 1.0)
        sol = solve_ivp(lambda _t, r: B + (A - C) * r - B * r**2, (0.0, 5000.0), [0.0], method="LSODA",
                        rtol=1e-12, atol=1e-14)
        assert sol.y[0, -1] == pytest.approx(float(law.hcs_rotational_ratio(e, 1.0)), rel=1e-8)
    assert RoughSphereRestitution(beta=-1.0).hcs_rotational_ratio(0.7, 0.5) == 0.0
    assert RoughSphereRestitution(beta=0.7).hcs_rotational_ratio(0.7, 0.0) == 0.0  # frictionless


@pytest.mark.analytic
@pytest.mark.parametrize("e, mu, beta0, r", [(0.7, 0.5, 1.0, 0.5), (0.9, 0.2, 0.4, 0.2), (0.7, 1.5, 0.8, 1.0)])
def test_walton_averages_match_monte_carlo(e, mu, beta0, r):
    m1, m2 = _walton_moments(e, mu, beta0, 0.4, r)
    f = r / (0.4 + r)
    rot = m2 / 0.4 - f * m1
    tr = -(1 - e**2) - ((1 - f) * m1 - m2)
    mc_tr, mc_rot = _monte_carlo(e, beta0, 1.0, r, mu=mu)
    assert mc_rot == pytest.approx(rot, rel=0.015, abs=0.005)
    assert mc_tr == pytest.approx(tr, rel=0.015, abs=0.005)


#: (e, μ, β0) of the Monte Carlo checks of the sheared averages.
CASES = ((0.7, 0.5, 1.0), (0.9, 0.2, 0.4))


@functools.cache  # the two tests below share their samples
def _sheared_walton(e, mu, beta0, r, s, n=1_000_000, seed=5, q=0.4):
    """Monte Carlo of Walton's rule with the mean flow of uniform shear u_x = s y (d = m = T = 1): particle 2 at
    r1 + k, spins Ω + w with Ω = −(s/2) ẑ.  Rate-weighted means (Σ (g·k)⁺ X / n, J on particle 1) of the
    x-impulses' transfer J_x k_y (tangential, normal), the pair's translational energy change by the tangential
    impulse J_t·(c1 − c2) + |J_t|², its rotational energy change (spins about Ω) and the tangential work −J_t·m12."""
    rng = np.random.default_rng(seed)
    inertia = q / 4.0
    c = rng.normal(0.0, 1.0, (2, n, 3))
    w = rng.normal(0.0, math.sqrt(r / inertia), (2, n, 3))
    k = rng.normal(size=(n, 3))
    k /= np.linalg.norm(k, axis=1)[:, None]
    c12 = c[0] - c[1]
    v12 = c12.copy()
    v12[:, 0] -= s * k[:, 1]
    g = v12 + 0.5 * np.cross(w[0] + w[1] + np.array([0.0, 0.0, -s]), k)
    gn = (g * k).sum(1)
    gt = g - gn[:, None] * k
    slip = np.linalg.norm(gt, axis=1) + 1e-300
    beta = np.minimum(beta0, -1 + mu * (1 + e) * (1 + 1 / q) * gn / slip)
    rate = np.maximum(gn, 0.0)
    jn = -0.5 * (1 + e) * gn[:, None] * k
    jt = -(q * (1 + beta) / (2 * (1 + q)))[:, None] * gt
    dw = 0.5 * np.cross(k, jt) / inertia
    d_rot = 0.5 * inertia * (((w[0] + dw) ** 2).sum(1) + ((w[1] + dw) ** 2).sum(1) - (w[0] ** 2).sum(1) - (w[1] ** 2).sum(1))
    mean = lambda x: float((rate * x).sum() / n)
    return {"jt_xy": mean(jt[:, 0] * k[:, 1]), "jn_xy": mean(jn[:, 0] * k[:, 1]),
            "tr": mean((jt * c12).sum(1) + (jt**2).sum(1)), "rot": mean(d_rot), "work": mean(s * jt[:, 0] * k[:, 1])}


@pytest.mark.analytic
def test_walton_tangential_shear_share_matches_monte_carlo_and_its_limits():
    """The closed form (Stein's lemma on the Maxwellian average) against an independent Monte Carlo of the collision
    rule under shear (the same samples at ±s, differenced so that the isotropic noise cancels), and its limits: 0
    without friction, 3η0/(2(1 + e)) when every collision sticks."""
    law = WaltonRestitution(beta0=1.0)
    assert law.tangential_shear_share(0.7, 0.0) == 0.0
    for beta0 in (1.0, 0.4):
        eta0 = 0.4 * (1 + beta0) / (2 * 1.4)
        assert WaltonRestitution(beta0=beta0).tangential_shear_share(0.7, 1e4) == pytest.approx(1.5 * eta0 / 1.7,
                                                                                                rel=1e-6)
    for e, mu, beta0 in CASES:
        law = WaltonRestitution(beta0=beta0)
        plus, minus = (_sheared_walton(e, mu, beta0, law.rotational_ratio(e, mu), s) for s in (0.5, -0.5))
        mc = (plus["jt_xy"] - minus["jt_xy"]) / (plus["jn_xy"] - minus["jn_xy"])
        assert mc == pytest.approx(law.tangential_shear_share(e, mu), rel=0.02), (e, mu, beta0)


@pytest.mark.analytic
def test_walton_second_order_shear_balances_match_monte_carlo():
    """The s² coefficients behind ``tangential_work_fraction`` (rotational change, the tangential impulse's
    translational change and its work, rate-weighted, at the steady ratio) against the Monte Carlo at s = ±0.5
    (the O(s⁴) rest is ≈ 1 % there: measured at s = 0.3, 0.5 and 1 with 2·10⁶ samples), and the s = 0 moments
    against :func:`_walton_moments`."""
    from ktgf.closures.friction.collisions import _walton_shear_moments

    for e, mu, beta0 in CASES:
        law = WaltonRestitution(beta0=beta0)
        r = law.rotational_ratio(e, mu)
        mom = _walton_shear_moments(e, mu, beta0, 0.4, r)
        np.testing.assert_allclose(mom[:, 0] * math.sqrt(math.pi), _walton_moments(e, mu, beta0, 0.4, r), rtol=1e-9)
        closed = law._shear_balances(e, mu, r)
        zero = _sheared_walton(e, mu, beta0, r, 0.0)
        plus, minus = (_sheared_walton(e, mu, beta0, r, s) for s in (0.5, -0.5))
        for mc_key, key in (("rot", "rot2"), ("tr", "tr2"), ("work", "work2")):
            mc = (0.5 * (plus[mc_key] + minus[mc_key]) - zero[mc_key]) / 0.25
            assert mc == pytest.approx(closed[key], rel=0.03), (e, mu, key, mc, closed[key])


@pytest.mark.analytic
def test_walton_rotational_shear_shift_matches_the_monte_carlo_steady_ratio():
    """T_rot/T = r + c_r s² against the ratio at which the Monte Carlo's rotational energy change vanishes under
    shear (root of the line through two ratios ±0.02 about the prediction, same samples), at the DEM's s (1.5
    and 2.2, where the shift is 0.03–0.07); the Monte Carlo's root is good to ≈ 0.001 (its scatter at s = 1)."""
    for e, mu, beta0 in CASES:
        law = WaltonRestitution(beta0=beta0)
        r0, c = law.rotational_ratio(e, mu), law.rotational_shear_shift(e, mu)
        for s in (1.5, 2.2):
            pred = r0 + c * s**2
            low, high = (_sheared_walton(e, mu, beta0, pred + dr, s)["rot"] for dr in (-0.02, 0.02))
            root = pred - 0.02 - low * 0.04 / (high - low)
            assert root == pytest.approx(pred, abs=0.0025), (e, mu, s, root, pred)
        assert c * 2.2**2 > 0.025  # the shift is ten times the tolerance
    assert law.rotational_shear_shift(0.7, 0.0) == 0.0


@pytest.mark.analytic
def test_walton_tangential_work_fraction_limits():
    """β = 1 sticking collisions lose no tangential energy, so all the tangential work heats translation (μ → ∞
    with β0 = 1: 1); without friction there is no tangential work (NaN); between, below 1."""
    assert WaltonRestitution(beta0=1.0).tangential_work_fraction(0.7, 1e4) == pytest.approx(1.0, abs=1e-8)
    assert math.isnan(WaltonRestitution().tangential_work_fraction(0.7, 0.0))
    assert 0.0 < WaltonRestitution().tangential_work_fraction(0.7, 0.5) < 1.0


@pytest.mark.analytic
def test_walton_limits():
    law = WaltonRestitution(beta0=0.4)
    assert law.effective_restitution(0.7, 0.0) == 0.7 and law.rotational_ratio(0.7, 0.0) == 0.0
    rough = RoughSphereRestitution(beta=0.4)  # μ → ∞: every collision sticks
    assert law.rotational_ratio(0.7, 1e4) == pytest.approx(rough.rotational_ratio(0.7, 1.0), rel=1e-6)
    assert law.inelasticity(0.7, 1e4) == pytest.approx(rough.inelasticity(0.7, 1.0), rel=1e-6)
    # the steady state really balances the rotational energy
    r = law.rotational_ratio(0.7, 0.5)
    assert law._rotational_balance(0.7, 0.5, r) == pytest.approx(0.0, abs=1e-12)
    assert law.inelasticity(0.7, 0.5) > 1 - 0.7**2
    with pytest.raises(InputError, match="beta0 = -1"):
        WaltonRestitution(beta0=-1.0)


@pytest.mark.analytic
def test_walton_hcs_tends_to_the_rough_sphere_hcs_and_is_the_attractor():
    """μ → ∞ (always sticking): Huthmann & Zippelius's rough-sphere HCS ratio and cooling with β = β0; at finite μ the
    ratio is where the relative cooling rates of the two temperatures agree, reached from a rotation-free start."""
    from scipy.integrate import solve_ivp

    law, rough = WaltonRestitution(beta0=0.4), RoughSphereRestitution(beta=0.4)
    r_inf = float(rough.hcs_rotational_ratio(0.7, 1.0))
    assert law.hcs_rotational_ratio(0.7, 1e4) == pytest.approx(r_inf, rel=1e-8)
    A, B, _ = rough.collision_coefficients(0.7, 1.0)
    assert law.hcs_inelasticity(0.7, 1e4) == pytest.approx(4 * (A - B * r_inf), rel=1e-8)
    w = WaltonRestitution()
    assert w.hcs_rotational_ratio(0.7, 0.0) == 0.0 and w.hcs_inelasticity(0.7, 0.0) == pytest.approx(0.51)

    def drift(_, y):
        tr, rot = w._energy_changes(0.7, 0.5, y[0])
        return [rot - y[0] * tr]

    sol = solve_ivp(drift, (0.0, 60.0), [0.0], rtol=1e-10, atol=1e-12)
    assert sol.y[0, -1] == pytest.approx(w.hcs_rotational_ratio(0.7, 0.5), rel=1e-6)
    assert w.hcs_rotational_ratio(0.7, 0.5) > w.rotational_ratio(0.7, 0.5)  # the HCS keeps more rotation than shear
    assert math.isinf(w.hcs_rotational_ratio(0.7, 0.1))  # weak friction: T_rot/T grows without bound
