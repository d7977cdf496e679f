"""Linear stability of the HCS: dispersion relations, thresholds by root-finding vs the closed forms,
the critical-size oracle table, the dilute limit, the mode ordering and autodiff checks of g and C."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ktgf import InputError, get_model
from ktgf.closures import PAPER_MODELS
from ktgf.hcs import (
    NoCrossingError,
    NoCrossingWarning,
    box_wavenumber,
    critical_box_size,
    critical_wavenumbers,
    critical_wavenumbers_eig,
    dispersion_relation,
    last_crossing,
    longitudinal_matrix,
)

# oracles.md "HCS critical box sizes, RET with CS χ": (e, φ, L⊥/d, L∥/d), printed to 3 decimals.
ORACLE_BOXES = [
    (0.9, 0.05, 57.331, 95.446),
    (0.9, 0.1, 28.499, 51.216),
    (0.9, 0.2, 15.485, 30.262),
    (0.9, 0.3, 12.101, 23.987),
    (0.9, 0.4, 10.846, 21.029),
    (0.7, 0.1, 17.400, 28.084),
    (0.7, 0.3, 6.847, 12.354),
    (0.7, 0.5, 5.741, 9.853),
]
HALF_LAST_DIGIT = 5e-4 + 1e-9  # the table rounds to 3 decimals


def _grid(model, n_phi=12, n_e=10, e_min=0.05):
    top = min(model.phi_max, 1.0) - 0.02
    phi, e = np.meshgrid(np.linspace(0.01, top, n_phi), np.linspace(e_min, 0.99, n_e), indexing="ij")
    return phi, e


@pytest.mark.published
@pytest.mark.parametrize("method", ["closed", "eig"])
def test_critical_box_oracle_table(method):
    ret = get_model("ret")
    e = np.array([row[0] for row in ORACLE_BOXES])
    phi = np.array([row[1] for row in ORACLE_BOXES])
    r = ret.reduced(phi, e)
    k_perp, k_par = critical_wavenumbers(r) if method == "closed" else critical_wavenumbers_eig(r)
    np.testing.assert_allclose(critical_box_size(phi, k_perp), [row[2] for row in ORACLE_BOXES], rtol=0, atol=HALF_LAST_DIGIT)
    np.testing.assert_allclose(critical_box_size(phi, k_par), [row[3] for row in ORACLE_BOXES], rtol=0, atol=HALF_LAST_DIGIT)


@pytest.mark.analytic
@pytest.mark.parametrize("name", PAPER_MODELS)
def test_root_finding_on_eigenvalues_agrees_with_closed_form(name):
    """Over a (φ, e) grid incl. strong inelasticity: the last zero of the largest growth rate is the closed form.

    Where κ*C − μ*p* ≤ 0 (RET/Proposed at e ≲ 0.18) the closed form says the heat mode is unstable at
    every k* (k∥* = inf); the scan must then report that it found no crossing, not a number.
    """
    model = get_model(name)
    phi, e = _grid(model)
    r = model.reduced(phi, e)
    k_perp, k_par = critical_wavenumbers(r)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", NoCrossingWarning)
        n_perp, n_par = critical_wavenumbers_eig(r, on_no_crossing="inf")
    np.testing.assert_allclose(n_perp, k_perp, rtol=1e-10)
    finite = np.isfinite(k_par)
    np.testing.assert_allclose(n_par[finite], k_par[finite], rtol=1e-10)
    np.testing.assert_array_equal(np.isinf(n_par), ~finite)
    assert len(caught) == (~finite).sum()
    assert all("no crossing found" in str(w.message) for w in caught)


@pytest.mark.analytic
def test_unstable_at_every_wavenumber_in_strongly_inelastic_ret():
    r = get_model("ret").reduced(0.1, 0.1)
    assert r.kappa * r.C - r.mu * r.p < 0
    assert np.isinf(critical_wavenumbers(r)[1])
    assert critical_box_size(0.1, critical_wavenumbers(r)[1]) == 0.0
    with pytest.raises(NoCrossingError, match="still positive.*k\\* = 1000"):
        critical_wavenumbers_eig(r)
    # and it really is unstable at large k*: the heat mode tends to a positive constant
    s = dispersion_relation(r, np.array([1e2, 1e4])).largest_longitudinal
    assert (s > 0).all() and s[1] == pytest.approx(s[0], rel=1e-3)


@pytest.mark.analytic
def test_elastic_gas_is_stable_at_every_size():
    r = get_model("enskog").reduced(0.2, 1.0)
    assert critical_wavenumbers_eig(r) == (0.0, 0.0)
    assert tuple(critical_wavenumbers(r)) == (0.0, 0.0)
    assert critical_box_size(0.2, 0.0) == np.inf


@pytest.mark.contract
def test_last_crossing_reports_failures_clearly():
    with pytest.raises(NoCrossingError, match="no crossing found"):
        last_crossing(lambda k: 1.0 - 0.0 * k, what="constant")
    with pytest.warns(NoCrossingWarning):
        assert last_crossing(lambda k: 1.0 - 0.0 * k, on_no_crossing="inf") == np.inf
    with pytest.raises(NoCrossingError, match="NaN"):
        last_crossing(lambda k: np.nan * k)
    # a band away from k = 0: the *last* crossing is returned, to round-off
    assert last_crossing(lambda k: -(k - 0.1) * (k - 0.3)) == pytest.approx(0.3, rel=1e-13)
    with pytest.raises(InputError, match="k_min"):
        critical_wavenumbers_eig(get_model("ret").reduced(0.1, 0.9), k_min=1.0, k_max=0.5)


@pytest.mark.analytic
@pytest.mark.parametrize("name", PAPER_MODELS)
def test_small_k_limit_of_the_longitudinal_modes(name):
    """At k* → 0 the longitudinal rates are ζ0*/2 (velocity), 0 (density) and −ζ0*/2 (heat)."""
    r = get_model(name).reduced(0.25, 0.8)
    s = dispersion_relation(r, 0.0).longitudinal
    np.testing.assert_allclose(s.real, [r.zeta0 / 2, 0.0, -r.zeta0 / 2], atol=1e-14)
    np.testing.assert_allclose(s.imag, 0.0, atol=1e-14)


@pytest.mark.analytic
@pytest.mark.parametrize("name", PAPER_MODELS)
def test_shear_mode_closed_form_and_zero_eigenvalue_at_threshold(name):
    """s⊥ = ζ0*/2 − η*k*²/2 vanishes at k⊥*; det M(k∥*) = 0 (a zero longitudinal eigenvalue)."""
    r = get_model(name).reduced(0.3, 0.85)
    k_perp, k_par = critical_wavenumbers(r)
    d = dispersion_relation(r, np.array([k_perp, k_par]))
    assert abs(d.transverse[0]) < 1e-14
    assert abs(np.linalg.det(longitudinal_matrix(r, k_par))) < 1e-14
    assert abs(d.largest_longitudinal[1]) < 1e-13
    # just below the thresholds the modes grow, just above they decay
    below = dispersion_relation(r, np.array([0.99 * k_perp, 0.99 * k_par]))
    above = dispersion_relation(r, np.array([1.01 * k_perp, 1.01 * k_par]))
    assert below.transverse[0] > 0 > above.transverse[0]
    assert below.largest_longitudinal[1] > 0 > above.largest_longitudinal[1]


@pytest.mark.published
@pytest.mark.parametrize("e, zeta0, kappa, mu", [(0.9, 0.078951, 1.068491, 0.115695), (0.7, 0.212552, 1.357967, 0.483735)])
def test_dilute_limit_of_the_cluster_threshold(e, zeta0, kappa, mu):
    """φ → 0: k∥*² = 2ζ0*/(5(κ* − μ*)) with the φ = 0 RET values of oracles.md, from the eigenvalues."""
    r = get_model("ret").reduced(1e-9, e)
    _, k_par = critical_wavenumbers_eig(r)
    assert k_par**2 == pytest.approx(2 * zeta0 / (5 * (kappa - mu)), rel=2e-5)


@pytest.mark.analytic
@pytest.mark.parametrize("name", PAPER_MODELS)
def test_dilute_limit_every_model(name):
    """φ → 0 for every model with its own dilute coefficients (g → 1, C → 1, p* → 1)."""
    e = np.array([0.3, 0.6, 0.9, 0.97])
    r = get_model(name).reduced(1e-9, e)
    _, k_par = critical_wavenumbers_eig(r)
    np.testing.assert_allclose(k_par**2, 2 * r.zeta0 / (5 * (r.kappa - r.mu)), rtol=1e-7)


@pytest.mark.analytic
@pytest.mark.parametrize("name", PAPER_MODELS)
def test_vortices_appear_before_clusters_where_the_theory_says_so(name):
    """For 0.4 ≤ e < 1 and φ ≤ 0.5 every model has k⊥* > k∥*: the eigenvalue thresholds give L⊥ < L∥.

    Outside that region the order can reverse (RET/Proposed at e ≲ 0.37, Visc.div. near its
    viscosity divergence φ ≳ 0.57); wherever the closed form orders them, the eigenvalues agree.
    """
    model = get_model(name)
    phi, e = np.meshgrid(np.linspace(0.01, 0.5, 11), np.linspace(0.4, 0.99, 8), indexing="ij")
    k_perp, k_par = critical_wavenumbers_eig(model.reduced(phi, e))
    assert (critical_box_size(phi, k_perp) < critical_box_size(phi, k_par)).all()
    phi, e = _grid(model, n_phi=10, n_e=8, e_min=0.2)
    r = model.reduced(phi, e)
    c_perp, c_par = critical_wavenumbers(r)
    n_perp, n_par = critical_wavenumbers_eig(r)
    theory = critical_box_size(phi, c_perp) < critical_box_size(phi, c_par)
    np.testing.assert_array_equal(critical_box_size(phi, n_perp) < critical_box_size(phi, n_par), theory)


@pytest.mark.analytic
def test_order_reverses_where_the_theory_says_so():
    """RET at e = 0.3 (dilute) and Visc.div. at φ = 0.6: clusters first, L∥ < L⊥, from the eigenvalues."""
    for name, phi, e in (("ret", 0.02, 0.3), ("visc-div", 0.6, 0.9)):
        k_perp, k_par = critical_wavenumbers_eig(get_model(name).reduced(phi, e))
        assert critical_box_size(phi, k_par) < critical_box_size(phi, k_perp)


@pytest.mark.analytic
@pytest.mark.parametrize("name", PAPER_MODELS)
def test_g_and_C_agree_with_autodiff_of_the_models_own_zeta0_and_pressure(name):
    """g = ∂ln ζ0/∂ln n (ζ0 = ν0ζ0* with ν0 ∝ φ at fixed θ) and C = ∂(φp*)/∂φ, by jax.grad."""
    jax = pytest.importorskip("jax")
    import jax.numpy as jnp

    jax.config.update("jax_enable_x64", True)
    model = get_model(name)
    # avoid the freezing point φ_f = 0.49, where the piecewise RDFs have a kink in χ'
    phis = np.concatenate([np.linspace(0.02, 0.46, 9), np.linspace(0.5, min(model.phi_max, 1.0) - 0.03, 4)])

    def ln_zeta0(phi, e):
        return jnp.log(phi * model.reduced(phi, e, check=False).zeta0)

    def phi_p(phi, e):
        return phi * model.reduced(phi, e, check=False).p

    dlnz = jax.vmap(jax.grad(ln_zeta0), in_axes=(0, None))
    dphip = jax.vmap(jax.grad(phi_p), in_axes=(0, None))
    for e in (0.5, 0.9):
        r = model.reduced(phis, e)
        np.testing.assert_allclose(phis * np.asarray(dlnz(jnp.asarray(phis), e)), r.g, rtol=1e-12)
        np.testing.assert_allclose(np.asarray(dphip(jnp.asarray(phis), e)), r.C, rtol=1e-12)


@pytest.mark.contract
def test_dispersion_shapes_and_box_mode():
    r = get_model("ret").reduced(np.array([0.1, 0.2, 0.3]), 0.9)
    from ktgf.hcs import expand_states

    d = dispersion_relation(expand_states(r), np.linspace(0, 1, 7))
    assert d.transverse.shape == (3, 7) and d.longitudinal.shape == (3, 7, 3)
    assert (np.diff(d.longitudinal.real, axis=-1) <= 0).all()  # sorted by decreasing real part
    # the box mode is the inverse of the critical size
    assert box_wavenumber(0.2, critical_box_size(0.2, 0.37)) == pytest.approx(0.37, rel=1e-14)


def _user_models():
    from ktgf.closures import Lun1984, MaAhmadi, Model, Torquato

    return [
        Model("lun-omega-ma", Lun1984(omega="lun"), MaAhmadi(), label="Lun (with omega) + Ma-Ahmadi"),
        get_model("ret", zeta11="ghd", sonine=False),
        Model("enskog-torquato", Lun1984(alpha=1.6), Torquato()),
    ]


@pytest.mark.analytic
@pytest.mark.parametrize("model", _user_models(), ids=lambda m: m.name + str(m.options()))
def test_user_defined_models_closed_form_agrees_with_eigenvalues(model):
    """Any model, not only the registered four: compositions with other RDFs and options."""
    phi, e = _grid(model, n_phi=8, n_e=6, e_min=0.2)
    r = model.reduced(phi, e)
    k_perp, k_par = critical_wavenumbers(r)
    assert np.isfinite(k_par).all()
    n_perp, n_par = critical_wavenumbers_eig(r)
    np.testing.assert_allclose(n_perp, k_perp, rtol=1e-10)
    np.testing.assert_allclose(n_par, k_par, rtol=1e-10)
