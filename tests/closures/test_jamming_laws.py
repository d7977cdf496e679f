"""φ_J(μ) laws (ktgf.closures.jamming): printed end points, Maxwell-counting limits, and parts moved to φ_J.

Oracles from outside the code: the mean-field volume function φ = Z/(Z + 2√3) of Song, Wang & Makse
(Nature 453, 629 (2008)) gives random close and random loose packing 63.4 % and 53.6 % (printed so in
the abstract of their "Jamming II") at the isostatic contact numbers 2D = 6 and D + 1 = 4 (Maxwell
counting, D = 3); Silbert (Soft Matter 6, 2918
(2010), abstract) has z_c^μ "from approximately six to four" and φ_c^μ decreasing with μ; every RDF
family keeps its published divergence exponent when moved to φ_J(μ) and stays Carnahan–Starling
below freezing.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf.closures.friction.jamming import JammingFraction
from ktgf.closures.jamming import (
    JAMMING_LAWS,
    CoordinationJamming,
    TabulatedJamming,
    at_jamming,
    check_below_jamming,
    coordination_of_packing_fraction,
    get_jamming_law,
    mu_scale_for,
    packing_fraction_of_coordination,
)
from ktgf.closures.rdf import ChialvoSundaresan, LunSavage, MaAhmadi, Torquato, ViscosityDivergence, _cs_chi
from ktgf.closures.viscosity_divergence import ViscosityDivergenceLaw
from ktgf.errors import InputError

MUS = np.array([0.0, 1e-3, 0.01, 0.1, 0.3, 0.5, 1.0, 10.0, 1e3])


@pytest.mark.published
def test_song_wang_makse_end_points_are_their_printed_rcp_and_rlp() -> None:
    # "4/(4 + 2√3) or 53.6% and 6/(6 + 2√3) or 63.4%, defining RLP and RCP" (abstract of "Jamming II:
    # Edwards' statistical mechanics of random packings of hard spheres", Makse group, arXiv)
    assert packing_fraction_of_coordination(6.0) == pytest.approx(0.634, abs=5e-4)
    assert packing_fraction_of_coordination(4.0) == pytest.approx(0.536, abs=5e-4)
    law = CoordinationJamming()
    assert law.phi_c(0.0) == pytest.approx(6.0 / (6.0 + 2.0 * math.sqrt(3.0)), rel=1e-15)
    assert law.phi_c(1e12) == pytest.approx(4.0 / (4.0 + 2.0 * math.sqrt(3.0)), rel=1e-10)


@pytest.mark.analytic
def test_contact_number_goes_from_isostatic_frictionless_to_isostatic_frictional() -> None:
    dim = 3
    law = CoordinationJamming()
    assert law.coordination(0.0) == 2 * dim  # Maxwell: d·N translational constraints, 2 per contact
    assert law.coordination(1e12) == pytest.approx(dim + 1, rel=1e-10)  # with torques: Z = D + 1
    z = law.coordination(MUS)
    assert np.all(np.diff(z) < 0) and np.all((z > 4.0 - 1e-9) & (z <= 6.0))


@pytest.mark.analytic
def test_volume_function_and_its_inverse() -> None:
    z = np.linspace(3.0, 7.0, 9)
    assert coordination_of_packing_fraction(packing_fraction_of_coordination(z)) == pytest.approx(z, rel=1e-14)


@pytest.mark.analytic
@pytest.mark.parametrize("law", [JammingFraction(), CoordinationJamming(), CoordinationJamming(mu_scale=0.3),
                                 TabulatedJamming(mu=(0.0, 0.1, 1.0), phi=(0.64, 0.6, 0.56))])
def test_every_law_decreases_with_friction_and_its_derivative_is_the_slope(law) -> None:
    phi = law.phi_c(MUS)
    assert np.all(np.diff(phi) <= 0.0) and phi[0] > phi[-1]
    mu = np.array([0.02, 0.2, 0.45, 0.7])
    h = 1e-6
    fd = (law.phi_c(mu + h) - law.phi_c(mu - h)) / (2 * h)
    assert law.dphi_c(mu) == pytest.approx(fd, rel=1e-6, abs=1e-12)


@pytest.mark.analytic
def test_derivatives_agree_with_jax_grad() -> None:
    jax = pytest.importorskip("jax")
    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    for law in (CoordinationJamming(), JammingFraction(), TabulatedJamming(mu=(0.0, 0.1, 1.0), phi=(0.64, 0.6, 0.56))):
        for mu in (0.05, 0.3, 2.0):
            assert float(jax.grad(law.phi_c)(jnp.asarray(mu))) == pytest.approx(float(law.dphi_c(mu)), rel=1e-12)


@pytest.mark.analytic
def test_tabulated_law_returns_its_nodes_and_is_flat_outside() -> None:
    law = TabulatedJamming(mu=(0.0, 0.1, 0.5, 1.0), phi=(0.636, 0.61, 0.585, 0.58))
    assert law.phi_c(np.array([0.0, 0.1, 0.5, 1.0])) == pytest.approx([0.636, 0.61, 0.585, 0.58], abs=0)
    assert law.phi_c(5.0) == 0.58 and law.dphi_c(5.0) == 0.0
    assert law.phi_c(0.3) == pytest.approx(0.5975, rel=1e-14)


@pytest.mark.contract
@pytest.mark.parametrize("kwargs, text", [
    ({"mu": (0.0, 0.5, 0.4), "phi": (0.64, 0.6, 0.58)}, "must increase strictly"),
    ({"mu": (0.0, 0.5), "phi": (0.6, 0.62)}, "must not increase"),
    ({"mu": (0.1, 0.5), "phi": (0.64, 0.6)}, "mu[0] = 0.1 is out of range"),
    ({"mu": (0.0,), "phi": (0.64,)}, "at least 2"),
    ({"mu": (0.0, 0.5), "phi": (0.8, 0.6)}, "phi = 0.8 is out of range"),
])
def test_tabulated_law_refuses_bad_tables_in_one_line(kwargs, text) -> None:
    with pytest.raises(InputError, match=None) as err:
        TabulatedJamming(**kwargs)
    assert text in str(err.value) and "\n" not in str(err.value)


@pytest.mark.contract
def test_registry_builds_each_law_and_refuses_unknown_names() -> None:
    assert set(JAMMING_LAWS) == {"interpolation", "coordination", "tabulated"}
    assert isinstance(get_jamming_law("coordination", mu_scale=0.2), CoordinationJamming)
    assert get_jamming_law("interpolation").phi_c(0.0) == 0.64
    with pytest.raises(InputError, match="unknown jamming law 'silbert'; choose one of interpolation, coordination"):
        get_jamming_law("silbert")
    with pytest.raises(InputError, match="z_infinite = 7 is out of range"):
        CoordinationJamming(z_infinite=7.0)


@pytest.mark.analytic
@pytest.mark.parametrize("law", [JammingFraction(), CoordinationJamming()])
def test_mu_scale_for_puts_the_law_through_a_given_point(law) -> None:
    import dataclasses

    scale = mu_scale_for(law, 0.5, 0.58)
    assert dataclasses.replace(law, mu_scale=scale).phi_c(0.5) == pytest.approx(0.58, rel=1e-13)
    with pytest.raises(InputError, match="target jamming fraction phi_j = 0.7 is out of range"):
        mu_scale_for(law, 0.5, 0.7)


# --- parts moved to φ_J(μ): each family keeps its published divergence exponent -------------------

FAMILIES = [  # (part, exponent of χ at φ_c) — Torquato 1995 Eq. 13: 1; Chialvo–Sundaresan 2013: 3/2;
    (Torquato(), 1.0),  # Lun–Savage 1986: 2.5 φ_c; Ma–Ahmadi 1986: 0.678021; viscosity-divergence RDF: β
    (ChialvoSundaresan(), 1.5),
    (LunSavage(), None),
    (MaAhmadi(), 0.678021),
    (ViscosityDivergence(), 1.75),
]


def _log_slope(chi, phi_j: float, gap: float) -> float:
    """d ln χ/d ln(φ_J − φ) at φ = φ_J − gap (central difference in ln gap)."""
    h = 1e-3
    lo, hi = gap * math.exp(-h), gap * math.exp(h)
    return float((math.log(chi(phi_j - hi)) - math.log(chi(phi_j - lo))) / (2 * h))


@pytest.mark.analytic
@pytest.mark.parametrize("rdf, exponent", FAMILIES, ids=lambda x: getattr(x, "key", str(x)))
@pytest.mark.parametrize("law", [JammingFraction(), CoordinationJamming(mu_scale=0.3)],
                         ids=["interpolation", "coordination"])
def test_rdf_moved_to_phi_j_diverges_there_with_its_published_exponent(rdf, exponent, law) -> None:
    mu = 0.5
    moved = at_jamming(rdf, mu, law)
    phi_j = float(law.phi_c(mu))
    assert moved.phi_max == phi_j
    b = 2.5 * phi_j if exponent is None else exponent
    # the CS background and the φ² prefactor fade as the gap closes: slope → −b
    slope = _log_slope(moved.chi, phi_j, 1e-7)
    assert slope == pytest.approx(-b, rel=2e-3)


@pytest.mark.analytic
@pytest.mark.parametrize("rdf", [Torquato(), ViscosityDivergence()], ids=["torquato", "viscosity-divergence"])
def test_moved_piecewise_rdfs_are_carnahan_starling_below_freezing(rdf) -> None:
    moved = at_jamming(rdf, 0.5, CoordinationJamming(mu_scale=0.3))
    phi = np.linspace(0.0, moved.phi_f, 50)
    assert moved.chi(phi) == pytest.approx(_cs_chi(phi), rel=1e-15)


@pytest.mark.analytic
def test_chialvo_sundaresan_is_carnahan_starling_plus_order_phi_squared_at_low_density() -> None:
    moved = at_jamming(ChialvoSundaresan(), 0.5, CoordinationJamming(mu_scale=0.3))
    phi = np.array([1e-5, 1e-4, 1e-3])
    excess = (moved.chi(phi) - _cs_chi(phi)) / phi**2
    assert excess == pytest.approx(0.58 / moved.phi_c**1.5, rel=3e-3)


@pytest.mark.analytic
def test_viscosity_law_and_rdf_share_the_jamming_point() -> None:
    law = CoordinationJamming(mu_scale=0.3)
    visc = at_jamming(ViscosityDivergenceLaw(), 0.5, law)
    rdf = at_jamming(ViscosityDivergence(), 0.5, law)
    assert visc.phi_c == rdf.phi_c == float(law.phi_c(0.5))
    # η factor ∝ (φ_J − φ)^−(β − 1): its log slope at the gap 1e-7
    assert _log_slope(visc.factor, visc.phi_c, 1e-7) == pytest.approx(-(visc.beta - 1.0), rel=1e-6)


@pytest.mark.contract
def test_at_jamming_refuses_parts_without_a_divergence_and_freezing_above_phi_j() -> None:
    from ktgf.closures.rdf import CarnahanStarling

    with pytest.raises(InputError, match="has no divergence point phi_c"):
        at_jamming(CarnahanStarling(), 0.5)
    with pytest.raises(InputError, match=r"freezing point phi_f = 0.49 is out of range: valid phi_f < 0.4"):
        at_jamming(ViscosityDivergenceLaw(), 10.0, TabulatedJamming(mu=(0.0, 1.0), phi=(0.64, 0.45)))
    with pytest.raises(InputError, match="particle friction coefficient mu = -0.1"):
        at_jamming(ViscosityDivergenceLaw(), -0.1)


@pytest.mark.contract
def test_check_below_jamming_names_phi_j_in_one_line() -> None:
    law = CoordinationJamming()
    check_below_jamming(np.array([0.3, 0.55]), 0.5, law)
    with pytest.raises(InputError) as err:
        check_below_jamming(np.array([0.3, 0.57]), 0.5, law)
    msg = str(err.value)
    assert "solid fraction phi = 0.57 is out of range" in msg and "phi_J(mu=0.5) = 0.5557" in msg
    assert "coordination(" in msg and "\n" not in msg
