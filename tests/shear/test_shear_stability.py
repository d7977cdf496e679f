"""Linear stability of uniform shear: limits, long-wave asymptotics, the nonlinear equations, time integration."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

from ktgf.closures import get_model, list_models
from ktgf.shear.steady import steady_shear
from ktgf.errors import InputError
from ktgf.shear import kelvin_evolution, shear_base_state, shear_matrix, shear_modes

# The analysis linearises the Navier–Stokes-order equations; models with a shear-dependent
# dissipation (the EKT correlation length: `dense` with that option, `frictional`) are refused
# (test_bad_inputs_name_the_field).
MODELS = [m.name for m in list_models() if m.dissipation.key == "none"]
D, RHO_S, GDOT, E = 1e-3, 2500.0, 100.0, 0.9


def _rates(name, phi, ky, kz=0.0, e=E):
    return shear_modes(name, phi, e, GDOT, ky, kz, d=D, rho_s=RHO_S)


@pytest.mark.analytic
@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("phi", [0.1, 0.5])
def test_long_waves_relax_temperature_at_the_cooling_rate(name, phi):
    """k → 0: four zero rates and σ = −ζ0 = −2ηγ̇²/(3ρθ), the linearised 0D energy balance."""
    m = _rates(name, phi, ky=1e-7 / D)
    c = get_model(name).coefficients(phi, E, m.base.theta, d=D, rho_s=RHO_S)
    zeta0 = float(c.zeta0)
    assert zeta0 == pytest.approx(2 * float(c.eta) * GDOT**2 / (3 * RHO_S * phi * m.base.theta), rel=1e-10)
    s = m.growth_rates
    assert s[-1].real == pytest.approx(-zeta0, rel=1e-8)
    assert np.abs(s[:4]).max() < 1e-5 * zeta0  # sound at c k ~ 1e-6 ζ0, the rest O(k²)
    v = m.vectors[:, -1]  # the mode is pure temperature at k = 0
    assert abs(v[4]) / m.base.theta == pytest.approx(1.0, abs=1e-6)


@pytest.mark.analytic
@pytest.mark.parametrize("name", MODELS)
def test_shear_waves_decay_at_the_viscous_rate(name):
    """k ∥ z: δu_x alone is a mode, σ = −ηk²/ρ; k ∥ y: δu_z alone, same rate (model.md §1 stress)."""
    phi, k = 0.3, 0.2 / D
    for ky, kz, comp in ((0.0, k, 1), (k, 0.0, 3)):
        m = _rates(name, phi, ky, kz)
        nu_k2 = m.base.c.eta * k**2 / m.base.rho
        A = shear_matrix(m.base, 0.0, ky, kz)
        unit = np.zeros(5)
        unit[comp] = 1.0
        np.testing.assert_allclose(A @ unit, -nu_k2 * unit, rtol=0, atol=1e-12 * nu_k2)
        assert np.min(np.abs(m.growth_rates + nu_k2)) < 1e-6 * nu_k2


def _stress_ratio_and_pressure(model, phi):
    """μ = |P_xy|/p and f_p = p/(ρ_s γ̇² d²) = φ p* T of the closed form (model.md §9)."""
    us = steady_shear(model, phi, E)
    return us.tau_over_p, phi * model.reduced(phi, E).p * us.T


@pytest.mark.analytic
@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("phi", [0.1, 0.3, 0.5])
def test_layering_mode_follows_the_slope_of_the_stress_ratio(name, phi):
    """k ∥ y, kd → 0: σ/γ̇ = (kd)² f_p μ'(φ)/(1 + (φ/2)(ln f_p)') from the closed form alone (docs derivation).

    Unstable (σ > 0) exactly where the uniform-shear stress ratio rises with φ.
    """
    model = get_model(name)
    h = 1e-5
    mu_p, f_p = _stress_ratio_and_pressure(model, phi + h)
    mu_m, f_m = _stress_ratio_and_pressure(model, phi - h)
    _, f0 = _stress_ratio_and_pressure(model, phi)
    dmu, dlnf = (mu_p - mu_m) / (2 * h), (math.log(f_p) - math.log(f_m)) / (2 * h)
    errors = []
    for kd in (2e-3, 1e-3):
        predicted = kd**2 * f0 * dmu / (1 + 0.5 * phi * dlnf)
        s = _rates(name, phi, ky=kd / D).growth_rates / GDOT
        nearest = s[np.argmin(np.abs(s - predicted))]
        assert abs(nearest.imag) < 1e-12
        errors.append(abs(nearest.real - predicted) / abs(predicted))
    assert errors[1] < 2e-3
    assert errors[0] / errors[1] > 3.0  # the O(k²) correction: the asymptote is approached at second order


@pytest.mark.analytic
def test_enskog_layering_instability_switches_on_with_density():
    """Stable dilute (φ = 0.1) and unstable dense (φ = 0.4) to long layering waves, as dμ/dφ changes sign."""
    assert _rates("enskog", 0.1, ky=0.01 / D).growth_rates[0].real < 0
    assert _rates("enskog", 0.4, ky=0.01 / D).growth_rates[0].real > 0


@pytest.mark.analytic
@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("phi", [0.3, 0.55])
def test_vorticity_direction_transport_terms_are_those_of_the_hcs_analysis(name, phi):
    """k ∥ z: the k-dependent part of the (δφ, δθ, δu_z) block, in the HCS variables and time ∫ν0 dt,
    is exactly −[M(k*) − M(0)] of the HCS analysis (model.md §8, :mod:`ktgf.hcs.stability`); only the
    homogeneous (k = 0) terms of the base states differ.
    """
    from ktgf.closures.coefficients import mean_free_path, nu0
    from ktgf.hcs.stability import longitudinal_matrix

    base = shear_base_state(name, phi, E, GDOT, d=D, rho_s=RHO_S)
    k = 0.2 / D
    block = [0, 4, 3]
    dA = (shear_matrix(base, 0.0, 0.0, k) - shear_matrix(base, 0.0, 0.0, 0.0))[np.ix_(block, block)]
    T = np.diag([1 / phi, 1 / base.theta, 1 / math.sqrt(2 * base.theta)])
    reduced = T @ dA @ np.linalg.inv(T) / nu0(phi, base.theta, D)
    r = get_model(name).reduced(phi, E)
    kstar = k * mean_free_path(phi, D)
    dM = longitudinal_matrix(r, kstar) - longitudinal_matrix(r, 0.0)
    np.testing.assert_allclose(reduced, -dM, rtol=0, atol=1e-12 * np.abs(dM).max())


# --- the linearisation against the nonlinear equations ------------------------------------------------


def _nonlinear_rhs(model, base, n_hat, length, fields):
    """Time derivatives of (φ, v_x, u_y, u_z, θ) for fields varying along s = n̂·r (period ``length``).

    Written directly from the balances of model.md §1 with u = γ̇ y e_x + v(s), pseudo-spectral
    derivatives and the model's nonlinear closures at every point.  The advection of the fields by
    the base flow, γ̇ y ∂_x, is left out: it is what shears the wavevector of a Kelvin mode, so the
    remainder is what A(k) holds at one instant.
    """
    phi, vx, uy, uz, theta = fields
    n = phi.size
    kk = 2 * np.pi * np.fft.fftfreq(n, d=length / n)

    def dds(f):
        return np.real(np.fft.ifft(1j * kk * np.fft.fft(f)))

    c = model.coefficients(phi, E, theta, d=D, rho_s=RHO_S)
    rho = RHO_S * phi
    v = np.stack([vx, uy, uz])
    dv = np.stack([dds(f) for f in v])
    G = np.einsum("i,js->ijs", n_hat, dv)  # G_ij = ∂_i u_j
    G[1, 0] += base.shear_rate
    div = np.einsum("iis->s", G)
    eye = np.eye(3)[:, :, None]
    P = c.p * eye - c.eta * (G + G.transpose(1, 0, 2) - (2 / 3) * div * eye) - c.lambda_b * div * eye
    divP = np.stack([sum(n_hat[i] * dds(P[i, j]) for i in range(3)) for j in range(3)])
    advect = np.einsum("is,ijs->js", v, G)
    dv_dt = -advect - divP / rho
    dphi_dt = -sum(n_hat[i] * dds(phi * v[i]) for i in range(3))
    dtheta = dds(theta)
    q = -(c.kappa * dtheta + c.omega * dds(phi))
    divq = sum(n_hat[i] * dds(n_hat[i] * q) for i in range(3))
    work = np.einsum("ijs,ijs->s", P, G)
    dtheta_dt = -(v.T @ n_hat) * dtheta + (-divq - work - 1.5 * rho * theta * (c.zeta0 + c.zeta_u * div)) / (1.5 * rho)
    return np.stack([dphi_dt, *dv_dt, dtheta_dt])


@pytest.mark.analytic
@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("k_hat", [(0.0, 1.0, 0.0), (0.0, 0.6, 0.8), (0.5, 0.5, math.sqrt(0.5))], ids=["y", "yz", "xyz"])
def test_matrix_is_the_derivative_of_the_nonlinear_equations(name, k_hat):
    """A(k)ŷ equals the central difference of the nonlinear balances along a plane wave Re(ŷ e^{iks})."""
    model = get_model(name)
    base = shear_base_state(name, 0.35, E, GDOT, d=D, rho_s=RHO_S)
    n_hat = np.array(k_hat)
    k = 0.3 / D
    length, n = 2 * np.pi / k, 16
    s = np.arange(n) * length / n
    scales = np.array([base.phi, *3 * [math.sqrt(base.theta)], base.theta])
    state = np.array([base.phi, 0.0, 0.0, 0.0, base.theta])[:, None] * np.ones(n)
    steady = _nonlinear_rhs(model, base, n_hat, length, state)
    assert np.abs(steady / scales[:, None]).max() < 1e-10 * GDOT  # the base state is steady
    rng = np.random.default_rng(7)
    y_hat = scales * (rng.standard_normal(5) + 1j * rng.standard_normal(5))
    wave = np.real(y_hat[:, None] * np.exp(1j * k * s)[None, :])
    eps = 1e-6
    fd = (_nonlinear_rhs(model, base, n_hat, length, state + eps * wave)
          - _nonlinear_rhs(model, base, n_hat, length, state - eps * wave)) / (2 * eps)
    A = shear_matrix(base, *(k * n_hat))
    expected = np.real((A @ y_hat)[:, None] * np.exp(1j * k * s)[None, :])
    np.testing.assert_allclose(fd / scales[:, None], expected / scales[:, None], rtol=0, atol=1e-6 * GDOT * 10)


# --- time integration -----------------------------------------------------------------------------------


@pytest.mark.analytic
@pytest.mark.parametrize("name", ["enskog", "proposed"])
def test_integrated_modes_evolve_as_their_eigenvalues(name):
    """k_x = 0: integrating dy/dt = Ay from each eigenvector gives exp(σt) times it (φ = 0.4, oblique k)."""
    k = (0.0, 0.01 / D, 0.001 / D)
    m = shear_modes(name, 0.4, E, GDOT, ky=k[1], kz=k[2], d=D, rho_s=RHO_S)
    assert m.growth_rates[0].real > 0  # the layering mode grows here
    times = np.linspace(0.0, 20.0 / GDOT, 5)
    for j in range(5):
        sigma, v = m.growth_rates[j], m.vectors[:, j]
        y = kelvin_evolution(m.base, k, v, times)
        exact = np.exp(sigma * times)[:, None] * v[None, :]
        scale = np.abs(v).max()  # errors relative to the initial amplitude: the fast modes decay by 1e-13
        assert np.abs(y - exact).max() / scale < 1e-8, j


@pytest.mark.analytic
def test_kelvin_spanwise_velocity_decays_with_the_sheared_wavenumber():
    """k_z = 0: δu_z decouples exactly, δu_z(t) = δu_z(0) exp(−(η/ρ) ∫ |k(t)|² dt) with k_y(t) = k_y0 − γ̇k_x t."""
    base = shear_base_state("proposed", 0.4, E, GDOT, d=D, rho_s=RHO_S)
    kx, ky0 = 0.2 / D, 0.5 / D
    times = np.linspace(0.0, 8.0 / GDOT, 9)
    y0 = np.array([0.0, 0.0, 0.0, 1e-3, 0.0])
    y = kelvin_evolution(base, (kx, ky0, 0.0), y0, times)
    b = GDOT * kx
    integral = kx**2 * times + (ky0**3 - (ky0 - b * times) ** 3) / (3 * b)
    exact = 1e-3 * np.exp(-base.c.eta / base.rho * integral)
    np.testing.assert_allclose(y[:, 3].real, exact, rtol=1e-7, atol=1e-15)
    assert np.abs(np.delete(y, 3, axis=1)).max() < 1e-15


@pytest.mark.analytic
def test_kelvin_mode_matches_a_product_of_matrix_exponentials():
    """k_x ≠ 0: the sheared wavevector; DOP853 against midpoint exponentials exp(A(k(t+h/2))h), error O(h²)."""
    base = shear_base_state("ret", 0.3, E, GDOT, d=D, rho_s=RHO_S)
    k0 = (0.1 / D, -0.3 / D, 0.05 / D)  # k_y passes through 0 at t = 3/γ̇
    scales = np.array([base.phi, *3 * [math.sqrt(base.theta)], base.theta])
    y0 = scales * np.array([1.0, 0.3, -0.2, 0.1, 0.5])
    t_end = 6.0 / GDOT
    y = kelvin_evolution(base, k0, y0, [0.0, t_end])[-1]

    def stepped(n):
        h, z = t_end / n, y0.astype(complex)
        for j in range(n):
            t = (j + 0.5) * h
            z = expm(shear_matrix(base, k0[0], k0[1] - GDOT * k0[0] * t, k0[2]) * h) @ z
        return z

    errs = [np.abs((stepped(n) - y) / scales).max() for n in (40, 80)]
    assert errs[1] < 1e-3 * np.abs(y / scales).max()
    assert 3.0 < errs[0] / errs[1] < 5.0  # second order of the midpoint product: the two integrators agree


@pytest.mark.contract
def test_bad_inputs_name_the_field():
    with pytest.raises(InputError, match="shear rate"):
        shear_base_state("ret", 0.3, E, 0.0, d=D, rho_s=RHO_S)
    with pytest.raises(InputError, match="restitution"):
        shear_base_state("ret", 0.3, 1.0, GDOT, d=D, rho_s=RHO_S)
    with pytest.raises(InputError, match="dissipation"):
        shear_base_state(get_model("dense", dissipation="jenkins-berzi-2010"), 0.3, E, GDOT, d=D, rho_s=RHO_S)
    for m in list_models():
        if m.dissipation.key != "none":
            with pytest.raises(InputError, match="shear-dependent dissipation"):
                shear_base_state(m, 0.3, 0.7, GDOT, d=D, rho_s=RHO_S)
