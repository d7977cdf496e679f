"""χ of the one family (``ktgf.closures.jamming.FrictionalPowerLaw``): limits, exponent, derivative, bad options.

Oracles: the contact-number law's printed end points (φ_J(0) = 6/(6 + 2√3) = 63.4 %, φ_J(∞) = 4/(4 + 2√3) =
53.6 %), Carnahan–Starling as φ → 0 and for a = 0, the exponent of the power law, central differences.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf.closures.jamming import FrictionalPowerLaw
from ktgf.closures.rdf import CarnahanStarling, JammingPowerLaw
from ktgf.errors import InputError

RDF = FrictionalPowerLaw(mu=0.5, a=0.12, exponent=1.9, mu_scale=0.62, amplitude_growth=5.8)


@pytest.mark.published
def test_frictionless_member_is_the_power_law_at_the_published_jamming_fraction():
    rdf = FrictionalPowerLaw(mu=0.0, a=0.12, exponent=1.9, mu_scale=0.62, amplitude_growth=5.8)
    assert rdf.phi_c == 6.0 / (6.0 + 2.0 * math.sqrt(3.0))
    assert rdf.amplitude == 0.12
    phi = np.linspace(0.0, 0.63, 50)
    ref = JammingPowerLaw(a=0.12, phi_c=6.0 / (6.0 + 2.0 * math.sqrt(3.0)), exponent=1.9)
    np.testing.assert_array_equal(rdf.chi(phi), ref.chi(phi))
    np.testing.assert_array_equal(rdf.dchi(phi), ref.dchi(phi))


@pytest.mark.published
def test_friction_moves_the_divergence_between_the_printed_end_points_and_grows_the_amplitude():
    lo, hi = 4.0 / (4.0 + 2.0 * math.sqrt(3.0)), 6.0 / (6.0 + 2.0 * math.sqrt(3.0))
    mus = [0.0, 0.1, 0.5, 2.0, 1e6]
    phis = [FrictionalPowerLaw(mu=m, mu_scale=0.62).phi_c for m in mus]
    assert phis[0] == hi and abs(phis[-1] - lo) < 1e-5 and np.all(np.diff(phis) < 0)
    amps = [FrictionalPowerLaw(mu=m, a=0.1, mu_scale=0.62, amplitude_growth=5.0).amplitude for m in mus]
    assert np.all(np.diff(amps) > 0) and amps[-1] == pytest.approx(0.6, rel=1e-5)  # a (1 + k) as μ → ∞
    assert RDF.phi_max == RDF.phi_c


@pytest.mark.analytic
def test_carnahan_starling_limits():
    phi = np.array([1e-4, 0.1, 0.3])
    cs = CarnahanStarling().chi(phi)
    np.testing.assert_allclose(FrictionalPowerLaw(mu=0.5, a=0.0).chi(phi), cs, rtol=1e-15)
    assert RDF.chi(1e-4) == pytest.approx(CarnahanStarling().chi(1e-4), rel=1e-6)  # CS + O(φ²)


@pytest.mark.analytic
def test_divergence_exponent_and_derivative():
    gap = np.array([1e-6, 1e-7])
    chi = RDF.chi(RDF.phi_c - gap)
    slope = -np.diff(np.log(chi)) / np.diff(np.log(gap))
    assert slope[0] == pytest.approx(1.9, rel=2e-3)  # χ ∝ (φ_J − φ)^(−b)
    phi = np.linspace(0.05, RDF.phi_c - 0.01, 30)
    h = 1e-6
    np.testing.assert_allclose(RDF.dchi(phi), (RDF.chi(phi + h) - RDF.chi(phi - h)) / (2 * h), rtol=1e-6)


@pytest.mark.contract
@pytest.mark.parametrize("options, name", [({"mu": -0.1}, "mu"), ({"a": -1.0}, "option a"),
                                           ({"exponent": 0.0}, "option exponent"), ({"mu_scale": 0.0}, "mu_scale"),
                                           ({"amplitude_growth": -1.0}, "option amplitude_growth")])
def test_bad_options_are_one_line_errors(options, name):
    with pytest.raises(InputError) as info:
        FrictionalPowerLaw(**options)
    assert name in str(info.value) and "\n" not in str(info.value)
