"""The closures on NumPy and JAX arrays: broadcasting, jit, and analytic derivatives vs autodiff."""

from __future__ import annotations

import numpy as np
import pytest

from ktgf import PAPER_MODELS, get_model, list_models
from ktgf.closures import RDFS, CustomRDF, get_rdf

jax = pytest.importorskip("jax")
jnp = jax.numpy

# Sample points inside every RDF's domain, on both sides of φ_f = 0.49.
MODEL_NAMES = [m.name for m in list_models()]  # every registered model, not only the paper's four
PHI = np.array([0.02, 0.1, 0.25, 0.4, 0.48, 0.5, 0.55, 0.6, 0.63])


@pytest.mark.analytic
@pytest.mark.parametrize("key", sorted(RDFS))
def test_rdf_derivative_matches_autodiff(key):
    rdf = get_rdf(key)
    auto = np.array([jax.grad(rdf.chi)(float(p)) for p in PHI])
    assert np.allclose(rdf.dchi(PHI), auto, rtol=1e-12)


@pytest.mark.analytic
@pytest.mark.parametrize("key", sorted(RDFS))
def test_rdf_derivative_matches_finite_difference(key):
    rdf = get_rdf(key)
    h = 1e-7
    fd = (rdf.chi(PHI + h) - rdf.chi(PHI - h)) / (2 * h)
    assert np.allclose(rdf.dchi(PHI), fd, rtol=1e-6)


@pytest.mark.analytic
@pytest.mark.parametrize("key", sorted(RDFS))
def test_rdf_dilute_limit_and_monotone(key):
    rdf = get_rdf(key)
    assert rdf.chi(0.0) == pytest.approx(1.0, abs=1e-12)
    phi = np.linspace(0, 0.999 * rdf.phi_max, 400)
    assert np.all(np.diff(rdf.chi(phi)) > 0)


@pytest.mark.analytic
@pytest.mark.parametrize("name", MODEL_NAMES)
def test_stability_derivatives_match_autodiff(name):
    """g = ∂ln ζ0/∂ln n and C = ∂(φp*)/∂φ from each model's own ζ0 and p* (model.md §8)."""
    m = get_model(name)
    e = 0.8

    def log_zeta0(log_phi):  # ζ0 = ν0 ζ0*, ν0 ∝ φ at fixed θ
        phi = jnp.exp(log_phi)
        return jnp.log(phi * m.reduced(phi, e, check=False).zeta0)

    def phi_p(phi):
        return phi * m.reduced(phi, e, check=False).p

    phis = PHI[PHI < m.phi_max]  # the frictional model jams at φ_c(μ) < 0.6
    r = m.reduced(phis, e)
    g = np.array([jax.grad(log_zeta0)(np.log(p)) for p in phis])
    c = np.array([jax.grad(phi_p)(float(p)) for p in phis])
    assert np.allclose(r.g, g, rtol=1e-12)
    assert np.allclose(r.C, c, rtol=1e-12)


@pytest.mark.contract
@pytest.mark.parametrize("name", MODEL_NAMES)
def test_jit_equals_numpy(name):
    m = get_model(name)
    phi = PHI[PHI < m.phi_max][:, None]
    # frictional dissipation is written through 1/(1 − e²): e = 1 is outside a frictional model's domain
    e = np.array([0.5, 0.8, 0.95 if m.friction.mu > 0 else 1.0])[None, :]
    ref = m.reduced(phi, e)
    fn = jax.jit(lambda p, q: m.reduced(p, q, check=False))
    got = fn(jnp.asarray(phi), jnp.asarray(e))
    for k in ref._fields:
        assert np.allclose(np.broadcast_to(getattr(ref, k), (phi.size, 3)), getattr(got, k), rtol=1e-13), k


@pytest.mark.contract
def test_jax_concrete_arrays_are_still_checked():
    from ktgf import InputError

    with pytest.raises(InputError):
        get_model("ret").reduced(jnp.asarray([0.2, 1.2]), 0.9)


@pytest.mark.analytic
def test_broadcasting_over_phi_e_theta():
    m = get_model("proposed")
    phi = np.linspace(0.1, 0.6, 6)[:, None, None]
    e = np.linspace(0.6, 1.0, 5)[None, :, None]
    theta = np.array([1e-3, 1e-2])[None, None, :]
    c = m.coefficients(phi, e, theta, d=1e-3, rho_s=1500.0)
    for k in ("p", "eta", "kappa", "omega", "zeta0"):
        assert np.shape(getattr(c, k)) == (6, 5, 2), k
    # coefficients ∝ √θ and p ∝ θ (model.md §1)
    assert np.allclose(c.eta[..., 1] / c.eta[..., 0], np.sqrt(10))
    assert np.allclose(c.p[..., 1] / c.p[..., 0], 10)


@pytest.mark.analytic
def test_custom_rdf_reproduces_carnahan_starling():
    custom = CustomRDF(chi_fn=lambda p: (1 - p / 2) / (1 - p) ** 3, dchi_fn=lambda p: (2.5 - p) / (1 - p) ** 4,
                       packing_limit=1.0, name="my-cs")
    a = get_model("ret").replace(rdf=custom).reduced(PHI, 0.85)
    b = get_model("ret").reduced(PHI, 0.85)
    for k in a._fields:
        assert np.allclose(getattr(a, k), getattr(b, k), rtol=1e-14), k


@pytest.mark.contract
def test_registry_has_the_paper_models_and_aliases():
    names = [m.name for m in list_models()]
    assert set(PAPER_MODELS) <= set(names)
    assert get_model("Visc.Div.").name == "visc-div"
    assert get_model("GD99") is get_model("ret")
    assert get_model("ret", zeta11="ghd").theory.zeta11 == "ghd"
    assert get_model("proposed", beta=2.0).rdf.beta == 2.0


@pytest.mark.contract
def test_every_registered_model_is_hashable_and_documented():
    for m in list_models():
        hash(m)
        assert m.label and m.description and m.theory.reference
        assert m.metadata()["model"] == m.name


# ``power``: quarter exponents by multiplications and square roots (no XLA ``pow``), the rest by ``**``.
QUARTER_EXPONENTS = [1.75, 0.75, -1.75, 2.5, 1.5, -3.0, 0.25, 4.0]


@pytest.mark.analytic
@pytest.mark.parametrize("b", QUARTER_EXPONENTS)
def test_power_quarter_exponents_match_pow(b):
    from ktgf._array import power

    x = np.geomspace(1e-3, 1e3, 2001)
    exact = np.array([float(np.longdouble(v) ** np.longdouble(b)) for v in x])  # extended-precision oracle
    assert np.max(np.abs(power(x, b) / exact - 1.0)) < 1e-15
    assert np.max(np.abs(np.asarray(power(jnp.asarray(x), b)) / exact - 1.0)) < 1e-15


@pytest.mark.analytic
def test_power_edge_values_and_fallback():
    from ktgf._array import power

    with np.errstate(invalid="ignore", divide="ignore"):
        assert np.isnan(power(np.array(-1.0), 1.75)) and power(np.array(0.0), 1.75) == 0.0
        assert power(np.array(0.0), -1.75) == np.inf
    x = np.linspace(0.1, 2.0, 7)
    assert np.array_equal(power(x, 0.678021), x**0.678021)  # not a quarter: plain pow
    assert np.array_equal(power(x, 40.0), x**40.0)          # beyond the multiplication range


@pytest.mark.analytic
def test_power_traced_exponent_differentiates():
    from ktgf._array import power

    g = jax.grad(lambda b: power(jnp.asarray(2.0), b))(1.75)  # a calibration differentiating in β
    assert float(g) == pytest.approx(2.0**1.75 * np.log(2.0), rel=1e-14)


@pytest.mark.contract
@pytest.mark.parametrize("name", ["proposed", "visc-div"])
def test_dense_models_compile_without_pow(name):
    """The divergence exponents (β = 1.75, β − 1 = 0.75) cost no ``pow`` in the compiled closures
    (the fitted β = 4.052 of ``dense`` is no quarter and keeps one)."""
    m = get_model(name)
    text = jax.jit(lambda phi: m.reduced(phi, 0.7, check=False)).lower(jnp.full((8,), 0.55)).compile().as_text()
    assert " power(" not in text
