"""Frictional jamming fraction φ_c(μ) and the RDFs that diverge there."""

from __future__ import annotations

import numpy as np
import pytest

from ktgf.closures.friction import (
    FrictionalChialvoSundaresan,
    JammingFraction,
    d_jamming_fraction_dmu,
    jamming_fraction,
    with_jamming_fraction,
)
from ktgf.closures.rdf import CarnahanStarling, ChialvoSundaresan, Torquato, ViscosityDivergence
from ktgf.errors import InputError

jax = pytest.importorskip("jax")


@pytest.mark.published
def test_end_points_and_monotonic():
    jam = JammingFraction()
    assert jam.phi_c(0.0) == 0.64  # frictionless: random close packing, exactly
    assert jam.phi_c(1e9) == pytest.approx(0.55, abs=1e-9)  # random loose packing (Jerkins et al. 2008)
    mus = np.logspace(-4, 3, 200)
    assert np.all(np.diff(jam.phi_c(mus)) < 0)
    # the documented default values
    assert jam.phi_c(0.1) == pytest.approx(0.595, abs=1e-12)
    assert jam.phi_c(0.5) == pytest.approx(0.565, abs=1e-12)
    assert 0.55 <= jam.phi_c(0.5) <= 0.59


@pytest.mark.analytic
def test_jamming_derivative_matches_autodiff():
    grad = jax.grad(jamming_fraction)
    for mu in (0.0, 0.05, 0.5, 2.0):
        assert float(grad(mu)) == pytest.approx(float(d_jamming_fraction_dmu(mu)), rel=1e-12)


@pytest.mark.analytic
def test_frictional_rdf_reduces_to_chialvo_sundaresan_at_zero_friction():
    phi = np.linspace(0.0, 0.62, 40)
    np.testing.assert_array_equal(FrictionalChialvoSundaresan(mu=0.0).chi(phi), ChialvoSundaresan().chi(phi))
    np.testing.assert_array_equal(FrictionalChialvoSundaresan(mu=0.0).dchi(phi), ChialvoSundaresan().dchi(phi))


@pytest.mark.analytic
def test_frictional_rdf_diverges_at_the_jamming_fraction():
    rdf = FrictionalChialvoSundaresan(mu=0.5)
    assert rdf.phi_max == pytest.approx(0.565, abs=1e-12)
    gap = np.array([1e-2, 1e-3, 1e-4])
    chi = rdf.chi(rdf.phi_max - gap)
    slope = np.diff(np.log(chi)) / np.diff(np.log(gap))
    assert slope[-1] == pytest.approx(-1.5, abs=0.01)  # χ ∝ (φ_c − φ)^(−3/2)
    # friction raises χ at fixed φ (the divergence moved closer)
    assert np.all(rdf.chi(np.array([0.3, 0.5])) > ChialvoSundaresan().chi(np.array([0.3, 0.5])))


@pytest.mark.analytic
def test_frictional_rdf_derivative_matches_autodiff():
    rdf = FrictionalChialvoSundaresan(mu=0.5)
    grad = jax.grad(lambda p: rdf.chi(p))
    for phi in (0.1, 0.4, 0.55):
        assert float(grad(phi)) == pytest.approx(float(rdf.dchi(phi)), rel=1e-12)


@pytest.mark.analytic
def test_with_jamming_fraction_moves_other_families():
    for base in (Torquato(), ViscosityDivergence(), ChialvoSundaresan()):
        assert with_jamming_fraction(base, 0.0) == base  # φ_rcp = 0.64 = their default φ_c
        moved = with_jamming_fraction(base, 0.2)
        assert moved.phi_max == pytest.approx(JammingFraction().phi_c(0.2))


@pytest.mark.contract
def test_bad_input_is_one_line():
    with pytest.raises(InputError, match="friction coefficient mu = -0.5"):
        FrictionalChialvoSundaresan(mu=-0.5)
    with pytest.raises(InputError, match="random loose packing phi_rlp = 0.7"):
        JammingFraction(phi_rlp=0.7)
    with pytest.raises(InputError, match="mu_J = 0"):
        JammingFraction(mu_scale=0.0)
    with pytest.raises(InputError, match="no divergence point"):
        with_jamming_fraction(CarnahanStarling(), 0.5)
    with pytest.raises(InputError, match="freezing point phi_f = 0.58"):
        with_jamming_fraction(Torquato(phi_f=0.58), 0.5)


@pytest.mark.contract
def test_frictional_rdf_fits_the_model_registry():
    """Flat, JSON-serialisable options; ``mu`` is routed to the RDF by Model.with_options."""
    import json

    from ktgf import get_model

    model = get_model("ret").replace(rdf=FrictionalChialvoSundaresan(), name="frictional-check")
    moved = model.with_options(mu=0.5)
    assert moved.phi_max == pytest.approx(0.565)
    assert json.loads(moved.metadata()["model_options"])["rdf"]["mu"] == 0.5
    with pytest.raises(InputError, match="friction coefficient mu = -1"):
        model.with_options(mu=-1.0)
