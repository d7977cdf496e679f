"""Closure formulas against independent numbers: shared/theory/oracles.md tables and exact limits.

Reference types: [published] oracles.md 6-digit tables (independent implementation, 1e-5 rel);
[analytic] elastic, dilute and Lun≡RET(c*=0) limits; [analytic] SI forms of model.md §4.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf import get_model
from ktgf.closures import CarnahanStarling, Torquato, ViscosityDivergence, c_star, eta0, kappa0, nu0

REL = 1e-5

C_STAR = [(1.0, 0.0), (0.95, -0.019455), (0.9, -0.029121), (0.8, -0.025154), (0.7, 0.002612),
          (0.6, 0.047710), (0.5, 0.104918), (0.3, 0.236123), (0.0, 32.0 / 81.0)]

CS_TABLE = [(0.1, 1.303155, 3.657979), (0.2, 1.757812, 5.615234), (0.3, 2.478134, 9.162849),
            (0.4, 3.703704, 16.203704), (0.5, 6.0, 32.0)]

# φ, e, p*, ζ0*, η*, λ_b*, κ*, μ*, ζ10   (oracles.md, RET with CS χ, c* included)
RET_TABLE = [
    (0.0, 0.9, 1, 0.078951, 1.043320, 0, 1.068491, 0.115695, 0),
    (0.0, 0.7, 1, 0.212552, 1.147863, 0, 1.357967, 0.483735, 0),
    (0.1, 0.9, 1.495199, 0.102885, 1.241861, 0.201946, 1.382541, 0.144449, -0.049520),
    (0.1, 0.7, 1.443073, 0.276988, 1.246326, 0.180509, 1.510915, 0.587987, -0.132922),
    (0.3, 0.9, 3.825073, 0.195650, 3.831883, 3.456257, 4.022990, 0.288186, -0.282507),
    (0.3, 0.5, 3.230321, 0.782034, 2.830335, 2.717205, 3.047872, 2.147739, -1.115160),
    (0.4, 0.7, 6.037037, 0.787230, 6.894825, 8.208424, 6.280098, 1.509636, -1.511111),
    (0.5, 0.9, 12.400000, 0.473703, 18.661180, 23.245024, 17.843527, 1.082889, -1.140000),
]


def close(a, b, rel=REL, abs_=1e-6):
    return np.allclose(np.asarray(a, float), np.asarray(b, float), rtol=rel, atol=abs_)


@pytest.mark.published
@pytest.mark.parametrize("e, expected", C_STAR)
def test_c_star_table(e, expected):
    assert close(c_star(e), expected)


@pytest.mark.published
@pytest.mark.parametrize("phi, chi, dchi", CS_TABLE)
def test_carnahan_starling_table(phi, chi, dchi):
    cs = CarnahanStarling()
    assert close(cs.chi(phi), chi) and close(cs.dchi(phi), dchi)


@pytest.mark.published
@pytest.mark.parametrize("row", RET_TABLE, ids=lambda r: f"phi{r[0]}-e{r[1]}")
def test_ret_table(row):
    phi, e, p, zeta0, eta, lam, kappa, mu, zeta10 = row
    r = get_model("ret").reduced(phi, e)
    got = [r.p, r.zeta0, r.eta, r.lambda_b, r.kappa, r.mu]
    assert close(got, [p, zeta0, eta, lam, kappa, mu])
    z10 = -2.0 * (1 - e**2) * phi * CarnahanStarling().chi(phi)
    assert close(z10, zeta10)


@pytest.mark.analytic
@pytest.mark.parametrize("variant", ["gd99", "ghd"])
def test_zeta11_is_a_small_correction(variant):
    """model.md §3: ζ11 is at most 2.3 % of ζ10 (over 0 < φ ≤ 0.6, 0.05 ≤ e < 1)."""
    phi = np.linspace(0.01, 0.6, 40)[:, None]
    e = np.linspace(0.05, 0.99, 40)[None, :]
    r = get_model("ret", zeta11=variant).reduced(phi, e)
    r0 = get_model("ret", zeta11="none").reduced(phi, e)
    z10 = -2.0 * (1 - e**2) * phi * CarnahanStarling().chi(phi)
    assert np.allclose(r0.zeta_u, z10, rtol=1e-12)
    ratio = np.abs((r.zeta_u - z10) / z10)
    assert 0 < ratio.max() <= 0.023


PHI = np.array([0.0, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.55])


@pytest.mark.analytic
def test_ret_elastic_limit_is_chapman_cowling_enskog():
    chi = CarnahanStarling().chi(PHI)
    r = get_model("ret").reduced(PHI, 1.0)
    assert np.all(r.zeta0 == 0) and np.all(r.mu == 0)
    assert close(r.eta, (1 / chi) * (1 + 8 * PHI * chi / 5) ** 2 + 768 / (25 * math.pi) * PHI**2 * chi, rel=1e-12)
    assert close(r.kappa, (1 / chi) * (1 + 12 * PHI * chi / 5) ** 2 + 512 / (25 * math.pi) * PHI**2 * chi, rel=1e-12)
    assert close(r.lambda_b, 256 / (5 * math.pi) * PHI**2 * chi, rel=1e-12)


@pytest.mark.analytic
@pytest.mark.parametrize("e", [0.5, 0.7, 0.9, 0.99])
def test_ret_dilute_limit_without_sonine(e):
    r = get_model("ret", sonine=False).reduced(0.0, e)
    assert close(r.eta, 24 / ((1 + e) * (13 - e)), rel=1e-12)
    assert close(r.kappa, 32 / ((1 + e) * (9 + 7 * e)), rel=1e-12)
    assert close(r.mu, 640 * (1 - e) / ((1 + e) * (19 - 3 * e) * (9 + 7 * e)), rel=1e-12)


@pytest.mark.published
@pytest.mark.parametrize("e", [0.5, 0.7, 0.9, 0.99])
def test_ret_dilute_limit_with_sonine(e):
    """oracles.md: φ → 0 values with c* included (Brey et al. 1998 Boltzmann coefficients)."""
    cs = c_star(e)
    zeta0 = (5 / 12) * (1 - e**2) * (1 + 3 * cs / 32)
    nu_eta = (1 - (1 - e) ** 2 / 4) * (1 - cs / 64)
    nu_kappa = (1 / 3) * (1 + e) * (1 + (33 / 16) * (1 - e) + (19 - 3 * e) * cs / 1024)
    kappa = (2 / 3) * (1 + cs) / (nu_kappa - 2 * zeta0)
    r = get_model("ret").reduced(0.0, e)
    assert close(r.eta, 1 / (nu_eta - zeta0 / 2), rel=1e-12)
    assert close(r.kappa, kappa, rel=1e-12)
    assert close(r.mu, 2 * (zeta0 * kappa + cs / 3) / (2 * nu_kappa - 3 * zeta0), rel=1e-12)


@pytest.mark.analytic
def test_enskog_equals_ret_at_e_one():
    """Lun's coefficients are RET's with c* = 0 and ζ0* dropped: identical in the elastic limit."""
    a, b = get_model("enskog").reduced(PHI, 1.0), get_model("ret").reduced(PHI, 1.0)
    for k in ("p", "eta", "lambda_b", "kappa", "mu", "zeta0"):
        assert close(getattr(a, k), getattr(b, k), rel=1e-12), k


@pytest.mark.analytic
@pytest.mark.parametrize("e", [0.6, 0.8, 0.95])
def test_enskog_in_si_matches_lun_1984_dimensional_forms(e):
    """model.md §4 in its original SI form (K0, γ, λ_b with ρ_s d √θ) against Model.coefficients."""
    d, rho_s, theta = 2e-3, 2500.0, 0.04
    phi = np.array([0.05, 0.2, 0.4, 0.55])
    chi = CarnahanStarling().chi(phi)
    eta_l = (1 + e) / 2
    c = get_model("enskog").coefficients(phi, e, theta, d=d, rho_s=rho_s)
    m = rho_s * math.pi * d**3 / 6
    e0 = 5 / (16 * d**2) * math.sqrt(m * (m * theta) / math.pi)  # η0 = 5/(16d²)√(mT/π) with T = mθ
    assert close(eta0(theta, d, rho_s), e0, rel=1e-12)
    assert close(c.p, rho_s * phi * theta * (1 + 4 * eta_l * phi * chi), rel=1e-12)
    assert close(c.lambda_b, 8 / (3 * math.sqrt(math.pi)) * eta_l * rho_s * d * phi**2 * chi * math.sqrt(theta), rel=1e-12)
    eta = e0 * ((1 + 1.6 * eta_l * phi * chi) * (1 + 1.6 * eta_l * (3 * eta_l - 2) * phi * chi) / (eta_l * (2 - eta_l) * chi)
                + 768 / (25 * math.pi) * eta_l * phi**2 * chi)
    assert close(c.eta, eta, rel=1e-12)
    k0 = 75 * rho_s * d * math.sqrt(math.pi * theta) / (48 * eta_l * (41 - 33 * eta_l))
    kappa = k0 / chi * ((1 + 2.4 * eta_l * phi * chi) * (1 + 2.4 * eta_l**2 * (4 * eta_l - 3) * phi * chi)
                        + 64 / (25 * math.pi) * (41 - 33 * eta_l) * (eta_l * phi * chi) ** 2)
    assert close(c.kappa, kappa, rel=1e-12)
    gamma = 12 * (1 - e**2) * rho_s * phi**2 * chi * theta**1.5 / (d * math.sqrt(math.pi))
    assert close(1.5 * rho_s * phi * theta * c.zeta0, gamma, rel=1e-12)
    assert np.all(c.omega == 0) and np.all(c.zeta_u == 0)


@pytest.mark.analytic
def test_lun_omega_option_matches_dimensional_form():
    e, d, rho_s, theta = 0.8, 1e-3, 1500.0, 0.01
    phi = np.array([0.1, 0.3, 0.5])
    cs = CarnahanStarling()
    chi, dchi = cs.chi(phi), cs.dchi(phi)
    eta_l = (1 + e) / 2
    omega = (15 * math.sqrt(math.pi) / 4 * (eta_l - 1) * (2 * eta_l - 1) / (41 - 33 * eta_l)
             * (1 + 2.4 * eta_l * phi * chi) * (2 * chi + phi * dchi) / chi * rho_s * d * theta**1.5)
    c = get_model("enskog", omega="lun").coefficients(phi, e, theta, d=d, rho_s=rho_s)
    assert close(c.omega, omega, rel=1e-12)


@pytest.mark.analytic
def test_reference_scales():
    theta, d, rho_s, phi = 0.02, 1e-3, 1500.0, 0.3
    assert close(kappa0(theta, d, rho_s), 3.75 * eta0(theta, d, rho_s), rel=1e-14)
    # ν0 = ρθ/η0 (model.md §1)
    assert close(nu0(phi, theta, d), rho_s * phi * theta / eta0(theta, d, rho_s), rel=1e-12)


@pytest.mark.analytic
def test_ret_si_conversion():
    theta, d, rho_s, phi, e = 0.02, 1e-3, 1500.0, 0.3, 0.8
    m = get_model("ret")
    r, c = m.reduced(phi, e), m.coefficients(phi, e, theta, d=d, rho_s=rho_s)
    e0 = eta0(theta, d, rho_s)
    assert close(c.p, rho_s * phi * theta * r.p, rel=1e-14)
    assert close(c.eta, e0 * r.eta, rel=1e-14)
    assert close(c.kappa, 3.75 * e0 * r.kappa, rel=1e-14)
    assert close(c.omega, theta * 3.75 * e0 * r.mu / phi, rel=1e-14)
    assert close(c.zeta0, nu0(phi, theta, d) * r.zeta0, rel=1e-14)


@pytest.mark.analytic
def test_viscosity_divergence_rdf_is_cs_below_freezing():
    phi = np.linspace(0, 0.49, 50)
    assert np.array_equal(ViscosityDivergence().chi(phi), CarnahanStarling().chi(phi))
    assert np.array_equal(ViscosityDivergence().dchi(phi), CarnahanStarling().dchi(phi))


@pytest.mark.analytic
def test_visc_div_is_enskog_with_torquato_below_freezing():
    phi = np.linspace(0.01, 0.49, 30)[:, None]
    e = np.array([0.6, 0.9, 1.0])
    a = get_model("visc-div").reduced(phi, e)
    b = get_model("enskog").replace(rdf=Torquato()).reduced(phi, e)
    for k in a._fields:
        assert np.allclose(getattr(a, k), getattr(b, k), rtol=1e-14, atol=0), k


@pytest.mark.analytic
def test_proposed_is_ret_below_freezing():
    phi = np.linspace(0.01, 0.49, 30)
    a, b = get_model("proposed").reduced(phi, 0.8), get_model("ret").reduced(phi, 0.8)
    for k in a._fields:
        assert np.allclose(getattr(a, k), getattr(b, k), rtol=1e-14, atol=0), k


@pytest.mark.analytic
@pytest.mark.parametrize("name", ["visc-div", "proposed"])
def test_viscosity_diverges_with_exponent_beta(name):
    """Both dense models give η ∝ (φ_c − φ)^(−β), β = 1.75 (model.md §§5–6): local log slope."""
    phi_c, beta = 0.64, 1.75
    gap = np.array([1e-5, 1e-6])
    eta = get_model(name).reduced(phi_c - gap, 0.9).eta
    slope = np.log(eta[1] / eta[0]) / np.log(gap[1] / gap[0])
    assert slope == pytest.approx(-beta, rel=2e-3)
    # and the other coefficients keep the weaker (φ_c − φ)^(−1) or (−β) law of their χ
    p = get_model(name).reduced(phi_c - gap, 0.9).p
    p_slope = np.log(p[1] / p[0]) / np.log(gap[1] / gap[0])
    assert p_slope == pytest.approx(-1.0 if name == "visc-div" else -beta, rel=2e-3)
