"""The sheared contact value χ(φ, s) of FrictionalPowerLaw Eq. (3) (docs/dense_physics.md §8).

Oracles: the part's own definition against the plain power-law form at the sheared amplitude; jax.grad for
its slope; the energy balance of the local closure at the closed form's steady state; and particle data —
calibrated on the shared e = 0.9 uniform shear and the cooling states only, the frictionless e = 0.7 row of
the shared frictional file is a prediction.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.friction_couette import PREVIOUS_CHI

from ktgf import get_model
from ktgf.calibration import registry_fits as rf
from ktgf.closures.coefficients import SHEAR_PER_ASTAR
from ktgf.closures.jamming import FrictionalPowerLaw
from ktgf.closures.rdf import jamming_power_chi
from ktgf.couette import PlanarCell, Wall
from ktgf.couette.equations import Problem
from ktgf.couette.geometry import stretched_nodes
from ktgf.couette.solver import naive_start
from ktgf.errors import InputError
from ktgf.shear import steady as steady_module
from ktgf.shear.steady import steady_shear

PHI = np.array([0.05, 0.3, 0.45, 0.55, 0.6])


@pytest.mark.analytic
@pytest.mark.parametrize("mu", [0.0, 0.25])
def test_sheared_chi_is_the_power_law_at_the_sheared_amplitude(mu: float) -> None:
    rdf = FrictionalPowerLaw(mu=mu, a=0.1, exponent=2.1, mu_scale=0.6, amplitude_growth=1.2, shear_amplitude=0.4)
    s = 1.7
    astar = s / (SHEAR_PER_ASTAR * PHI)
    amplitude = (0.1 + 0.4 * astar) * (1.0 + 1.2 * rdf.friction_share)
    np.testing.assert_allclose(rdf.chi(PHI) + rdf.shear_chi(PHI, s),
                               jamming_power_chi(PHI, amplitude, rdf.phi_c, 2.1), rtol=1e-13)
    # no shear, or A = 0: χ(φ) itself
    assert np.all(rdf.shear_chi(PHI, 0.0) == 0.0)
    assert not FrictionalPowerLaw(a=0.1).shear_dependent and rdf.shear_dependent


@pytest.mark.analytic
def test_sheared_chi_slope_is_its_derivative() -> None:
    jax = pytest.importorskip("jax")
    jax.config.update("jax_enable_x64", True)
    rdf = FrictionalPowerLaw(mu=0.5, a=0.05, exponent=2.2, mu_scale=0.6, amplitude_growth=1.0, shear_amplitude=0.4)
    grad = jax.vmap(jax.grad(lambda p: rdf.shear_chi(p, 1.3)))(jax.numpy.asarray(PHI[:-1]))
    np.testing.assert_allclose(rdf.shear_dchi(PHI[:-1], 1.3), np.asarray(grad), rtol=1e-12)


@pytest.mark.analytic
def test_model_sees_the_sheared_chi_only_with_a_shear_measure() -> None:
    m = get_model("dense", shear_amplitude=0.4)
    plain = get_model("dense")
    phi, s = np.array([0.3, 0.5]), np.array([1.0, 2.0])
    assert m.shear_dependent
    # no shear (cooling state, stability analysis): the registered χ, bit for bit
    for field in ("p", "eta", "kappa", "zeta0"):
        np.testing.assert_array_equal(getattr(m.reduced(phi, 0.9), field), getattr(plain.reduced(phi, 0.9), field))
        np.testing.assert_array_equal(getattr(m.reduced(phi, 0.9, hcs=True), field),
                                      getattr(plain.reduced(phi, 0.9, hcs=True), field))
    sheared = m.reduced(phi, 0.9, shear=s)
    chi = m.chi(phi, s)
    np.testing.assert_allclose(sheared.p, 1.0 + 2.0 * 1.9 * phi * chi, rtol=1e-14)
    assert np.all(chi > plain.chi(phi))
    with pytest.raises(InputError, match="no shear"):
        m.reduced(phi, 0.9, hcs=True, chi_shear=s)


@pytest.mark.analytic
@pytest.mark.parametrize("mu, e", [(0.0, 0.9), (0.0, 0.7), (0.5, 0.7)])
def test_steady_shear_is_a_converged_fixed_point_of_the_local_closure(mu: float, e: float, monkeypatch) -> None:
    m = get_model("frictional", mu=mu, shear_amplitude=0.4)
    phi = np.array([0.3, 0.45, 0.55])
    st = steady_shear(m, phi, e)
    s = 1.0 / np.sqrt(st.T)
    r = m.reduced(phi, e, shear=s)  # EKT, friction and χ all at the steady state's own shear measure
    astar = s / (SHEAR_PER_ASTAR * phi)
    heating = (r.eta - 0.0) * astar**2
    assert np.max(np.abs(heating / (1.5 * r.zeta0) - 1.0)) < 1e-12  # (3/2)ζ0 = η* a*² (tangential loss in ζ0)
    np.testing.assert_allclose(st.p_over_nT, r.p, rtol=1e-12)
    monkeypatch.setattr(steady_module, "STRUCTURE_ITERATIONS", steady_module.STRUCTURE_ITERATIONS + 20)
    np.testing.assert_allclose(steady_shear(m, phi, e).T, st.T, rtol=1e-13)  # converged, not stopped short


@pytest.mark.analytic
def test_couette_faces_see_the_sheared_chi() -> None:
    """η and κ live at the faces, p and ζ0 at the nodes: with A > 0 both take the local shear measure."""
    w = Wall(specularity=0.13, restitution=0.9)
    g = PlanarCell(19.0, 10.0)
    x0, x1 = g.bounds(1.0)
    terms = {}
    for A in (0.0, 0.4):
        prob = Problem(get_model("dense", shear_amplitude=A), g, w, w, 0.4, 0.9, stretched_nodes(x0, x1, 40, 1.5),
                       v_scale=10.0)
        terms[A] = prob.terms(naive_start(prob))
    for name in ("F", "p"):  # shear stress (η at the faces), pressure (nodes): χ larger, both larger
        assert np.all(np.abs(terms[0.4][name]) > np.abs(terms[0.0][name]))


@pytest.mark.analytic
def test_static_contact_states_are_torquatos_metastable_branch() -> None:
    """Torquato (1995) Eq. (13), written out here: χ_CS(0.49)(0.64 − 0.49)/(0.64 − φ),
    χ_CS(φ) = (1 − φ/2)/(1 − φ)³."""
    static = rf.static_contact_states()
    phi = static["phi"]
    cs_f = (1.0 - 0.49 / 2.0) / (1.0 - 0.49) ** 3
    np.testing.assert_allclose(static["chi"], cs_f * (0.64 - 0.49) / (0.64 - phi), rtol=1e-12)
    assert phi.min() > 0.5 and phi.max() <= 0.6  # on the branch above freezing, below both divergences


@pytest.mark.dem
def test_fitted_on_the_shared_homogeneous_files_it_predicts_the_e07_pressure() -> None:
    """Calibrated on the shared homogeneous files only (e = 0.9 shear, cooling p/(nT)) and the static contact value
    near jamming (Torquato 1995), the registered family (``test_dense_fit_reproduces_the_registered_parameters``
    checks that it is this fit) gets p/(nT) of the frictionless e = 0.7 row (never fitted) within 5 % (measured
    +0.1 %; the χ(φ) before: −9.6 %).  The static states fix the part of χ without shear: a > 0, so χ diverges at
    φ_J without shear too (the χ(φ) before is 29–85 % above Torquato's there)."""
    params = rf.registered_parameters()
    static = rf.static_contact_states()
    assert params["a"] > 0.0 and params["shear_amplitude"] > 0.0
    assert np.max(np.abs(np.expm1(rf.static_log_errors(params, static)))) < 0.05  # measured 4.7 %
    assert np.min(np.expm1(rf.static_log_errors(PREVIOUS_CHI, static))) > 0.25
    shared = rf.frictional_states(frictional_only=False)
    row = rf.subset(shared, (shared["mu"] == 0.0) & (shared["e"] == 0.7))
    pred = rf.predict(params, row)
    assert abs(pred["p_over_nT"][0] / row["p_over_nT"][0] - 1.0) < 0.05
    previous = rf.predict(PREVIOUS_CHI, row)
    assert abs(previous["p_over_nT"][0] / row["p_over_nT"][0] - 1.0) > 0.05
    # and the cooling states' p/(nT) within 6.5 % (measured 6.1 %; the χ(φ) before: up to 10.4 %)
    assert np.max(np.abs(np.expm1(rf.cooling_log_errors(params, rf.cooling_states())))) < 0.065


@pytest.mark.analytic
def test_with_its_static_part_a_frictional_wall_cell_converges_with_the_mesh() -> None:
    """The dense frictional-wall cell of the 3D check (μ 0.5, Schaeffer, e 0.7, φ̄ 0.57, JJ walls φ' 0.1, e_w 0.9,
    δ_w 30°, 10 d): the wall shear stress on 64, 128, 256 uniform cells changes less at the second doubling
    (measured 320.1, 317.6, 316.3 Pa; 315.7 on 512).  Without the static part (a = 0) the shear gathers in a wall
    band one to three cells thick and the stress does not converge (266.6, 253.6, 238.5, 225.6 Pa; §8)."""
    from ktgf.couette.run import Material, run

    model = get_model("frictional", mu=0.5, stress="schaeffer")
    wall = Wall(specularity=0.1, restitution=0.9, friction_angle=30.0)
    material = Material(1e-3, 2500.0, 0.7)
    tau = [float(run(model, PlanarCell(0.01, 1.0), wall, wall, 0.57, material, n_cells=n, stretch=1.0)
                 ["wall_shear_stress"].values[0]) for n in (64, 128, 256)]
    steps = np.abs(np.diff(tau))
    assert np.all(steps[1:] < steps[:-1] / 1.6), tau
    assert steps[-1] < 0.005 * tau[-1], tau
