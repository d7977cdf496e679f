"""Model options are validated where models are made (issue 11, assigned to issue 9's dense work).

Every bad option raises :class:`ktgf.errors.InputError` with one line naming the option, the value
and the valid range; numbers must be finite reals (not bools or strings), booleans real booleans.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ktgf import InputError, get_model
from ktgf.closures.options import CLOSE_PACKING
from ktgf.closures.rdf import JammingPowerLaw, LunSavage, MaAhmadi, Torquato, ViscosityDivergence

NAN, INF = float("nan"), float("inf")


pytestmark = pytest.mark.contract


@pytest.mark.parametrize(
    "name, options, fragment",
    [
        ("enskog", {"alpha": -5}, "option alpha = -5"),
        ("enskog", {"alpha": NAN}, "option alpha = nan"),
        ("enskog", {"alpha": "1.6"}, "must be a real number"),
        ("enskog", {"alpha": True}, "must be a real number"),
        ("enskog", {"omega": "yes"}, "option omega = 'yes'"),
        ("proposed", {"phi_c": 1.5}, "option phi_c = 1.5"),
        ("proposed", {"phi_c": 0.45}, "valid 0.49 < phi_c"),
        ("proposed", {"phi_f": NAN}, "option phi_f = nan"),
        ("proposed", {"phi_c": INF}, "option phi_c = inf"),
        ("proposed", {"beta": NAN}, "option beta = nan"),
        ("proposed", {"beta": -1.0}, "valid 0 < beta"),
        ("visc-div", {"beta": INF}, "option beta = inf"),
        ("visc-div", {"phi_f": 0.7}, "phi_f"),
        ("proposed", {"junction": "c3"}, "option junction = 'c3'"),
        ("proposed", {"junction_width": 0.0}, "option junction_width = 0 is out of range"),
        ("proposed", {"junction_width": 0.2}, "0 < width < phi_c - phi_f"),
        ("ret", {"sonine": "no"}, "option sonine = 'no'"),
        ("ret", {"sonine": 0}, "must be true or false"),
        ("ret", {"zeta11": "new"}, "option zeta11 = 'new'"),
        ("ret", {"dissipation": "magic"}, "option dissipation = 'magic'"),
        ("ret", {"dissipation": "jenkins-berzi-2010", "c": -1.0}, "option c = -1 is out of range"),
        ("dense", {"exponent": -1.0}, "option exponent = -1"),
        ("dense", {"phi_c": 0.3}, "has no option(s) ['phi_c']"),  # φ_J(μ) comes from the jamming law
    ],
)
def test_bad_option_is_a_one_line_input_error(name, options, fragment):
    with pytest.raises(InputError) as info:
        get_model(name, **options)
    msg = str(info.value)
    assert fragment in msg and "\n" not in msg


def test_valid_options_still_work():
    assert get_model("ret", sonine=False).theory.sonine is False
    assert get_model("ret", sonine=np.bool_(True)).theory.sonine is True
    assert get_model("enskog", alpha=1.6).theory.alpha == 1.6
    m = get_model("proposed", phi_c=CLOSE_PACKING, junction="c0")
    assert m.phi_max == pytest.approx(0.74048, abs=1e-5)
    assert get_model("ret", dissipation="jenkins-berzi-2010", c=0.8).dissipation.c == 0.8


@pytest.mark.parametrize("cls", [LunSavage, MaAhmadi, JammingPowerLaw])
@pytest.mark.parametrize("phi_c", [0.0, -0.1, 0.75, 1.5, NAN, INF])
def test_single_branch_rdfs_check_phi_c(cls, phi_c):
    with pytest.raises(InputError, match="option phi_c"):
        cls(phi_c=phi_c)


@pytest.mark.parametrize("kw", [{"exponent": 0.0}, {"exponent": NAN}, {"a": -0.1}, {"a": INF}])
def test_jamming_power_law_checks_exponent_and_amplitude(kw):
    with pytest.raises(InputError, match=f"option {next(iter(kw))}"):
        JammingPowerLaw(**kw)


finite = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=300, deadline=None)
@given(phi_f=finite, phi_c=finite, beta=finite)
def test_piecewise_rdf_accepts_exactly_the_documented_range(phi_f, phi_c, beta):
    """Valid iff 0 < φ_f < 1, φ_f < φ_c ≤ π/√18, φ_c − φ_f > width (0.01), 0 < β ≤ 10; then χ is finite and
    rising, or (only where the dense branch starts flatter than CS) the smooth junction refuses by name."""
    valid = (
        all(math.isfinite(v) for v in (phi_f, phi_c, beta))
        and 0 < phi_f < 1 and phi_f < phi_c <= CLOSE_PACKING and phi_c - phi_f > 0.01 and 0 < beta <= 10
    )
    if not valid:
        with pytest.raises(InputError):
            ViscosityDivergence(phi_f=phi_f, phi_c=phi_c, beta=beta)
        return
    try:
        r = ViscosityDivergence(phi_f=phi_f, phi_c=phi_c, beta=beta)
    except InputError as exc:  # the smooth bridge refuses only when the dense branch starts flatter than CS
        assert "not monotone" in str(exc)
        c0 = ViscosityDivergence(phi_f=phi_f, phi_c=phi_c, beta=beta, junction="c0")
        assert c0.dchi(np.array(phi_f + 1e-12)) < c0.dchi(np.array(phi_f))
        return
    x = np.linspace(0.0, phi_c * (1 - 1e-6), 200)
    chi = r.chi(x)
    assert np.all(np.isfinite(chi)) and np.all(np.diff(chi) >= 0)


@settings(max_examples=200, deadline=None)
@given(alpha=st.one_of(finite, st.booleans(), st.text(max_size=3)))
def test_enskog_alpha_is_a_real_number_above_minus_two(alpha):
    ok = isinstance(alpha, float) and math.isfinite(alpha) and -2 < alpha <= 10
    if ok:
        eta = get_model("enskog", alpha=alpha).reduced(np.linspace(0.01, 0.6, 20), 0.9).eta
        assert np.all(eta > 0)
    else:
        with pytest.raises(InputError, match="option alpha"):
            get_model("enskog", alpha=alpha)


@settings(max_examples=100, deadline=None)
@given(value=st.one_of(st.text(max_size=4), st.integers(), st.floats(), st.none()))
def test_sonine_must_be_a_boolean(value):
    with pytest.raises(InputError, match="option sonine"):
        get_model("ret", sonine=value)


def test_torquato_phi_f_below_phi_c():
    with pytest.raises(InputError, match="phi_f < phi_c"):
        Torquato(phi_f=0.6, phi_c=0.55)


def test_missing_state_is_an_error_not_nan():
    m = get_model("ret")
    with pytest.raises(InputError, match="solid fraction phi is missing"):
        m.coefficients(None, 0.9, 1.0, d=1e-3, rho_s=1500.0)
    with pytest.raises(InputError, match="restitution coefficient e is missing"):
        m.reduced(0.3, None)


def test_non_monotone_bridge_is_refused_and_c0_still_allowed():
    """Found by hypothesis: φ_f = 0.125, φ_c = 0.5, β = 0.25 — the dense branch starts flatter than CS."""
    with pytest.raises(InputError, match="not monotone"):
        ViscosityDivergence(phi_f=0.125, phi_c=0.5, beta=0.25)
    r = ViscosityDivergence(phi_f=0.125, phi_c=0.5, beta=0.25, junction="c0")
    assert np.all(np.diff(r.chi(np.linspace(0, 0.49, 100))) > 0)
