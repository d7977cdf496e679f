"""Property-based tests (hypothesis) of the HCS functions: valid states give finite, signed
results; any other input is an InputError — never NaN, never another exception (issue 11).

CI runs a bounded number of examples (``max_examples`` below); ``-m slow`` runs 20x more.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ktgf.closures import PAPER_MODELS, get_model
from ktgf.errors import InputError
from ktgf.hcs import (
    box_wavenumber,
    cooling_rate,
    cooling_time,
    critical_box_size,
    critical_wavenumbers,
    dispersion_relation,
    haff_temperature,
)

FAST = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
LONG = settings(max_examples=3000, deadline=None, suppress_health_check=[HealthCheck.too_slow])

MODELS = {name: get_model(name) for name in PAPER_MODELS}


pytestmark = pytest.mark.contract


@st.composite
def states(draw):
    """(model, phi, e) inside the model's domain."""
    name = draw(st.sampled_from(sorted(MODELS)))
    m = MODELS[name]
    phi = draw(st.floats(1e-4, 0.995 * min(m.phi_max, 0.74), allow_nan=False))
    e = draw(st.floats(0.05, 1.0, allow_nan=False))
    return m, phi, e


#: anything a user might pass: numbers of every size and sign, NaN, inf, None, text, lists
ANY = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**6, 10**6), st.none(), st.booleans(),
    st.text(max_size=5), st.lists(st.floats(-2, 2), max_size=3),
)


def _stability_properties(m, phi: float, e: float) -> None:
    r = m.reduced(phi, e)
    k_perp, k_par = (float(k) for k in critical_wavenumbers(r))
    # k_perp is finite; k_par is inf where the heat mode is unstable at every wavenumber (documented)
    assert 0 <= k_perp < math.inf and k_par >= 0 and not math.isnan(k_par)
    for k in (k_perp, k_par):
        L = float(critical_box_size(phi, k))
        assert L >= 0 and not math.isnan(L)
        assert math.isinf(L) == (k == 0) and (L == 0) == math.isinf(k)
        if 0 < k < math.inf:  # the box of the critical size has its lowest mode at k*
            assert float(box_wavenumber(phi, L)) == pytest.approx(k, rel=1e-12)
    if e == 1.0:  # elastic: no cooling, no instability
        assert k_perp == 0 and k_par == 0
    d = dispersion_relation(r, np.array([0.0, 0.5 * k_perp, 2 * k_perp + 0.1, 10.0]))
    assert np.isfinite(d.transverse).all() and np.isfinite(d.longitudinal).all()
    # shear mode: unstable below k_perp*, stable above (s_perp(k) = (zeta0 - eta k^2)/2)
    if k_perp > 0:
        assert d.transverse[1] > 0 > d.transverse[2]


def _cooling_properties(m, phi: float, e: float, theta0: float, dia: float) -> None:
    zeta = float(cooling_rate(m, phi, e, theta0, d=dia))
    t0 = float(cooling_time(m, phi, e, theta0, d=dia))
    assert zeta >= 0 and math.isfinite(zeta)
    assert t0 > 0 and not math.isnan(t0)
    if math.isfinite(t0):  # Haff: theta(t0) = theta0 / 4, decreasing
        assert float(haff_temperature(t0, theta0, t0)) == pytest.approx(theta0 / 4, rel=1e-12)
        th = haff_temperature(np.array([0.0, t0, 2 * t0]), theta0, t0)
        assert np.all(np.diff(th) < 0)


@FAST
@given(states())
def test_stability_of_valid_states(state) -> None:
    _stability_properties(*state)


@FAST
@given(states(), st.floats(1e-8, 1e3), st.floats(1e-6, 1e-1))
def test_cooling_of_valid_states(state, theta0: float, dia: float) -> None:
    _cooling_properties(*state, theta0, dia)


@FAST
@given(st.sampled_from(sorted(MODELS)), ANY, ANY, ANY, ANY)
def test_any_input_gives_finite_results_or_an_input_error(name: str, phi, e, theta0, dia) -> None:
    try:
        zeta = cooling_rate(MODELS[name], phi, e, theta0, d=dia)
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    z = np.asarray(zeta, dtype=float)
    assert np.isfinite(z).all() and (z >= 0).all()


@FAST
@given(st.sampled_from(sorted(MODELS)), ANY, ANY)
def test_reduced_coefficients_never_silently_nan(name: str, phi, e) -> None:
    try:
        r = MODELS[name].reduced(phi, e)
    except InputError:
        return
    for value in (r.p, r.eta, r.kappa, r.zeta0):
        assert np.isfinite(np.asarray(value, dtype=float)).all()


@pytest.mark.slow
@LONG
@given(states(), st.floats(1e-8, 1e3), st.floats(1e-6, 1e-1))
def test_long_fuzz_of_valid_states(state, theta0: float, dia: float) -> None:
    _stability_properties(*state)
    _cooling_properties(*state, theta0, dia)


@pytest.mark.slow
@LONG
@given(st.sampled_from(sorted(MODELS)), ANY, ANY, ANY, ANY)
def test_long_fuzz_of_any_input(name: str, phi, e, theta0, dia) -> None:
    test_any_input_gives_finite_results_or_an_input_error.hypothesis.inner_test(name, phi, e, theta0, dia)
