"""The smooth junction at φ_f (issue 9 item 1): value and slope continuous, steps in μ*, g, C, L∥ gone."""

from __future__ import annotations

import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.closures.rdf import Torquato, ViscosityDivergence
from ktgf.closures.viscosity_divergence import ViscosityDivergenceLaw
from ktgf.hcs.stability import critical_box_size, critical_wavenumbers

jax = pytest.importorskip("jax")

PHI_F, W = 0.49, 0.01
EPS = 1e-9
KNOTS = [PHI_F, PHI_F + W]  # both ends of the bridge
PIECEWISE = [Torquato, ViscosityDivergence]


pytestmark = pytest.mark.analytic


def _jump(f, x, eps=EPS):
    return float(abs(f(np.array(x + eps)) - f(np.array(x - eps))))


@pytest.mark.parametrize("cls", PIECEWISE)
def test_c0_form_has_the_slope_jump_of_model_md(cls):
    """The named c0 option keeps model.md §2: χ' jumps at φ_f (29.7 → 66.4 for the viscosity-divergence RDF)."""
    r = cls(junction="c0")
    below, above = float(r.dchi(np.array(PHI_F))), float(r.dchi(np.array(PHI_F + 1e-12)))
    assert below == pytest.approx(29.71087, rel=1e-5)  # (5/2 − φ)/(1 − φ)⁴ at 0.49
    assert above == pytest.approx(66.4024 if cls is ViscosityDivergence else 37.9444, rel=1e-4)


@pytest.mark.parametrize("x", KNOTS)
@pytest.mark.parametrize("cls", PIECEWISE)
def test_default_junction_is_continuous_in_value_slope_and_curvature(cls, x):
    r = cls()
    assert r.junction == "c1"
    assert _jump(r.chi, x) < 1e-6
    assert _jump(r.dchi, x) < 1e-5 * float(r.dchi(np.array(x)))


    def curvature_gap(h):  # one-sided differences of the analytic slope on both sides of x
        left = (r.dchi(np.array(x)) - r.dchi(np.array(x - h))) / h
        right = (r.dchi(np.array(x + h)) - r.dchi(np.array(x))) / h
        return abs(float(right - left)), abs(float(right))

    gap6, _ = curvature_gap(1e-6)
    gap7, curv = curvature_gap(1e-7)
    assert gap7 < 0.2 * gap6 and gap7 < 0.01 * curv  # the gap is O(h): no curvature jump


@pytest.mark.parametrize("x", KNOTS)
def test_viscosity_factor_is_smooth(x):
    law = ViscosityDivergenceLaw()
    f = law.factor
    assert _jump(f, x) < 1e-7  # slope × 2ε
    slope = lambda y: (f(np.array(y + 1e-7)) - f(np.array(y - 1e-7))) / 2e-7  # noqa: E731
    assert abs(float(slope(x + 1e-5) - slope(x - 1e-5))) < 1e-2
    c0 = ViscosityDivergenceLaw(junction="c0").factor
    s0 = lambda y: (c0(np.array(y + 1e-7)) - c0(np.array(y - 1e-7))) / 2e-7  # noqa: E731
    assert float(s0(PHI_F + 1e-5) - s0(PHI_F - 1e-5)) == pytest.approx(0.75 / 0.15, rel=1e-3)  # (β − 1)/(φ_c − φ_f)


@pytest.mark.parametrize("cls", PIECEWISE)
def test_unchanged_outside_the_window(cls):
    """Below φ_f the model.md numbers hold exactly; above φ_f + w the published dense branch."""
    lo = np.linspace(0.0, PHI_F, 60)
    hi = np.linspace(PHI_F + W, 0.639, 60)
    for x in (lo, hi):
        assert np.array_equal(cls().chi(x), cls(junction="c0").chi(x))
        assert np.array_equal(cls().dchi(x), cls(junction="c0").dchi(x))


@pytest.mark.parametrize("cls", PIECEWISE)
@pytest.mark.parametrize("width", [0.002, 0.01, 0.05])
def test_bridge_slope_matches_autodiff_and_is_increasing(cls, width):
    r = cls(junction_width=width)
    x = np.linspace(PHI_F - 0.2 * width, PHI_F + 1.2 * width, 29)
    auto = np.array([jax.grad(r.chi)(float(p)) for p in x])
    np.testing.assert_allclose(r.dchi(x), auto, rtol=1e-12)
    assert np.all(np.diff(r.chi(x)) > 0) and np.all(r.dchi(x) > 0)


@pytest.mark.parametrize("name", ["visc-div", "proposed"])
@pytest.mark.parametrize("field", ["mu", "g", "C", "eta", "kappa"])
def test_steps_in_reduced_fields_are_gone(name, field):
    """μ*, g and C hold χ': they jumped at φ_f with the c0 form; with the default they are continuous."""
    e = 0.8
    c0_steps = field in ("mu", "g", "C") and not (name == "visc-div" and field == "mu")  # Enskog has μ* = 0
    for junction, expect_step in (("c0", c0_steps), ("c1", False)):
        m = get_model(name, junction=junction)
        for x in KNOTS:
            a, b = (getattr(m.reduced(np.array(x + s * EPS), e), field) for s in (-1, 1))
            rel = abs(float(b - a)) / max(abs(float(a)), 1e-12)
            if expect_step and x == PHI_F:
                assert rel > 0.05, (junction, field, rel)  # the step the issue reports
            elif junction == "c1":
                assert rel < 1e-6, (field, x, rel)


@pytest.mark.parametrize("name", ["visc-div", "proposed"])
def test_critical_heat_mode_size_has_no_step(name):
    """L∥ (model.md §8) from the reduced fields: a step at φ_f with c0, continuous with the default."""
    e = 0.8

    def l_par(model, x):
        r = model.reduced(np.array(x), e)
        return float(critical_box_size(np.array(x), critical_wavenumbers(r)[1]))

    for junction in ("c0", "c1"):
        m = get_model(name, junction=junction)
        jump = abs(l_par(m, PHI_F + EPS) / l_par(m, PHI_F - EPS) - 1)
        if junction == "c0":
            assert jump > 0.01
        else:
            assert jump < 1e-6
            assert abs(l_par(m, PHI_F + W + EPS) / l_par(m, PHI_F + W - EPS) - 1) < 1e-6
