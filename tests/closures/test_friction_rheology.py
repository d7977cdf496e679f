"""Dense rheology: μ(I) of Jop, Forterre & Pouliquen (2006), linear dilatancy, dense-inertial temperature."""

from __future__ import annotations

import math

import pytest

from ktgf.closures.friction import DenseInertialTemperature, LinearDilatancy, MuIRheology, inertial_number
from ktgf.errors import InputError

jax = pytest.importorskip("jax")


@pytest.mark.published
def test_published_glass_bead_constants():
    rheo = MuIRheology()
    # Jop et al. (2006): μ_s = tan 20.9°, μ_2 = tan 32.76°, I0 = 0.279; Basilisk's μ(I) examples
    # (an independent transcription) use mus = 0.383, dmu = 0.26, I0 = 0.279
    assert rheo.mu_s == pytest.approx(0.383, abs=0.0015)
    assert rheo.mu_2 - rheo.mu_s == pytest.approx(0.26, abs=0.002)
    assert rheo.I0 == 0.279


@pytest.mark.analytic
def test_mu_of_i_limits_and_inverse():
    rheo = MuIRheology()
    assert rheo.friction(0.0) == rheo.mu_s
    assert rheo.friction(1e12) == pytest.approx(rheo.mu_2, rel=1e-10)
    assert rheo.friction(rheo.I0) == pytest.approx(0.5 * (rheo.mu_s + rheo.mu_2), rel=1e-14)
    for i in (0.01, 0.3, 2.0):
        assert rheo.inertial_number_at(rheo.friction(i)) == pytest.approx(i, rel=1e-12)
    grad = jax.grad(lambda i: rheo.friction(i))
    for i in (0.0, 0.1, 1.0):
        assert float(grad(i)) == pytest.approx(float(rheo.dfriction(i)), rel=1e-12)


@pytest.mark.analytic
def test_inertial_number_definition():
    # I = γ̇ d/√(p/ρ_s): 10 1/s, 1 mm, 2500 kg/m³, 25 Pa -> 0.01/0.1
    assert inertial_number(10.0, 1e-3, 25.0, 2500.0) == pytest.approx(0.1, rel=1e-14)


@pytest.mark.analytic
def test_dilatancy_and_dense_temperature():
    dil = LinearDilatancy()
    assert dil.solid_fraction(0.0) == 0.6
    assert dil.inertial_number(dil.solid_fraction(0.37)) == pytest.approx(0.37, rel=1e-14)
    dense = DenseInertialTemperature()
    assert dense.temperature_ratio(0.5, 0.5 + 0.04) == pytest.approx(0.06 / 0.2, rel=1e-14)


@pytest.mark.contract
def test_bad_input_is_one_line():
    with pytest.raises(InputError, match="limiting friction coefficient mu_2 = 0.2"):
        MuIRheology(mu_2=0.2)
    with pytest.raises(InputError, match="I0 = 0"):
        MuIRheology(I0=0.0)
    with pytest.raises(InputError, match="solid fraction phi = 0.65"):
        LinearDilatancy().check(0.65)
    with pytest.raises(InputError, match="delta_phi = -0.1"):
        LinearDilatancy(delta_phi=-0.1)
    assert math.isfinite(MuIRheology().friction(0.5))
