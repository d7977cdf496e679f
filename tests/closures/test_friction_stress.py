"""Frictional stress: Johnson–Jackson pressure, Schaeffer and Srivastava–Sundaresan viscosities, MFiX blends."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf.closures.friction import (
    JohnsonJacksonPressure,
    SchaefferViscosity,
    SigmoidBlend,
    SrivastavaSundaresanViscosity,
    TanhBlend,
)
from ktgf.errors import InputError

jax = pytest.importorskip("jax")


@pytest.mark.analytic
def test_johnson_jackson_zero_below_threshold_and_divergence_exponent():
    jj = JohnsonJacksonPressure(delta_min=0.0)
    np.testing.assert_array_equal(jj.pressure(np.linspace(0.0, 0.5, 11)), 0.0)  # no friction at φ ≤ φ_min
    gap = np.array([1e-6, 1e-7])  # close enough that (φ − φ_min)^n is constant to 1e-5
    p = jj.pressure(jj.phi_max - gap)
    assert np.diff(np.log(p))[0] / np.diff(np.log(gap))[0] == pytest.approx(-5.0, abs=1e-4)  # ∝ (φ_max − φ)^(−p)
    # onset ∝ (φ − φ_min)^n
    ex = np.array([1e-7, 1e-8])
    p = jj.pressure(jj.phi_min + ex)
    assert np.diff(np.log(p))[0] / np.diff(np.log(ex))[0] == pytest.approx(2.0, abs=1e-4)


@pytest.mark.analytic
def test_johnson_jackson_openfoam_floor_is_continuous():
    jj = JohnsonJacksonPressure()  # δ_min = 0.05: the denominator stops at 0.05^5
    edge = jj.phi_max - jj.delta_min
    assert jj.pressure(edge - 1e-12) == pytest.approx(jj.pressure(edge + 1e-12), rel=1e-9)
    assert jj.pressure(0.60) == pytest.approx(jj.Fr * (0.60 - 0.5) ** 2 / 0.05**5, rel=1e-13)
    assert np.isfinite(jj.pressure(0.7))


@pytest.mark.analytic
@pytest.mark.parametrize("delta_min", [0.0, 0.05])
def test_johnson_jackson_derivative_matches_autodiff(delta_min):
    jj = JohnsonJacksonPressure(delta_min=delta_min)
    grad = jax.grad(lambda p: jj.pressure(p))
    for phi in (0.45, 0.52, 0.56, 0.6):
        if delta_min == 0.0 or phi < jj.phi_max - delta_min or phi > jj.phi_max - delta_min:
            assert float(grad(phi)) == pytest.approx(float(jj.dpressure(phi)), rel=1e-12, abs=1e-12)


def _simple_shear_invariants(rate):
    grad_u = np.zeros((3, 3))
    grad_u[0, 1] = rate  # u_x = γ̇ y
    d = 0.5 * (grad_u + grad_u.T)
    s = d - np.trace(d) / 3 * np.eye(3)
    return float(np.sum(s * s)), np.trace(d)


@pytest.mark.analytic
def test_schaeffer_gives_coulomb_stress_in_simple_shear():
    visc = SchaefferViscosity()
    ss, _ = _simple_shear_invariants(3.0)
    i2d = 0.5 * ss
    p_f = 120.0
    tau = visc.viscosity(p_f, i2d) * 3.0  # τ_xy = 2 μ D_xy = μ γ̇
    assert tau / p_f == pytest.approx(math.sin(math.radians(28.5)), rel=1e-13)
    assert visc.shear_stress_ratio() == pytest.approx(0.47715876, rel=1e-7)


@pytest.mark.analytic
def test_srivastava_sundaresan_limits():
    ss_visc = SrivastavaSundaresanViscosity()
    assert ss_visc.n_dilation == pytest.approx(math.sqrt(3) / (2 * math.sin(math.radians(28.5))), rel=1e-14)
    rate = 2.0
    ss, div = _simple_shear_invariants(rate)
    p_c = 50.0
    # no fluctuations: Schaeffer's τ = p_c sin φ_fr
    tau0 = ss_visc.viscosity(p_c, div, ss, 0.0) * rate
    assert tau0 / p_c == pytest.approx(math.sin(math.radians(28.5)), rel=1e-13)
    assert ss_visc.pressure_ratio(div, ss, 0.0) == 1.0
    # fluctuations lower the stress as 1/√(1 + 2θ/(γ̇d)²)
    theta_d2 = 0.3 * rate**2
    tau = ss_visc.viscosity(p_c, div, ss, theta_d2) * rate
    assert tau / p_c == pytest.approx(float(ss_visc.simple_shear_stress_ratio(0.3)), rel=1e-13)
    # compression raises, dilation lowers the frictional pressure
    assert ss_visc.pressure_ratio(-0.5, ss, 0.0) > 1.0
    assert ss_visc.pressure_ratio(0.5, ss, 0.0) < 1.0


@pytest.mark.published
def test_tanh_blend_matches_mfix_definition():
    blend = TanhBlend(phi_star=0.58)
    assert blend.width == pytest.approx(0.02 * 0.42)
    assert blend.weight(0.58) == pytest.approx(0.5, abs=1e-15)
    # MFiX truncates where tanh has reached ±tanh(π): a 0.19 % step at both band edges
    half = blend.width / 2
    assert 1.0 - blend.weight(0.58 + half * (1 - 1e-9)) == pytest.approx((1 - math.tanh(math.pi)) / 2, rel=1e-6)
    assert blend.weight(0.58 + half * (1 + 1e-9)) == 1.0 and blend.weight(0.58 - half * (1 + 1e-9)) == 0.0
    smooth = TanhBlend(phi_star=0.58, truncate=False)
    grad = jax.grad(lambda p: smooth.weight(p))
    for phi in (0.575, 0.58, 0.584):
        assert float(grad(phi)) == pytest.approx(float(smooth.dweight(phi)), rel=1e-10)


@pytest.mark.analytic
def test_sigmoid_blend_is_continuous_unlike_mfix():
    blend = SigmoidBlend(phi_star=0.58)
    end = blend.phi_end
    assert end == pytest.approx(0.58 - 0.01 * 0.42)
    assert blend.weight(end + 1e-12) == pytest.approx(0.0, abs=1e-9)
    # MFiX's scale 1/((b + 1)/2) leaves the kinetic weight at 0.863 just inside the band
    b = 1.0 / (1.0 + 0.01**0.25)
    assert b / ((b + 1) / 2) == pytest.approx(0.8635, abs=1e-4)
    assert blend.weight(0.7) > 0.99
    grad = jax.grad(lambda p: blend.weight(p))
    for phi in (0.578, 0.58, 0.6):
        assert float(grad(phi)) == pytest.approx(float(blend.dweight(phi)), rel=1e-10)


@pytest.mark.contract
def test_bad_input_is_one_line():
    with pytest.raises(InputError, match="friction threshold phi_min = 0.65 .*packing limit phi_max = 0.62"):
        JohnsonJacksonPressure(phi_min=0.65)
    with pytest.raises(InputError, match="delta_min"):
        JohnsonJacksonPressure(delta_min=0.2)
    with pytest.raises(InputError, match="coefficient Fr = -1"):
        JohnsonJacksonPressure(Fr=-1.0)
    with pytest.raises(InputError, match="angle of internal friction phi_fr = 90"):
        SchaefferViscosity(phi_fr_deg=90.0)
    with pytest.raises(InputError, match="zero width"):
        TanhBlend(phi_star=0.58, relative_width=0.0)
    with pytest.raises(InputError, match="zero width"):
        SigmoidBlend(phi_star=0.58, relative_width=0.0)
