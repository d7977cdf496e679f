"""Jenkins & Zhang (2002) e_eff as coded in SedFoam, and ktgf's Walton averages in their common limit.

Oracles: the SedFoam code (github.com/SedFoam/sedfoam, commit 079bc886, solver/kineticTheoryModels/
kineticTheoryModel/kineticTheoryModel.C, "Frictional dissipation (Jenkins & Zhang (2002))"), re-typed below;
the analytic limits of those expressions; and ktgf's WaltonRestitution (a numerical Maxwellian average of
the same collision rule, derived independently), which must meet them for nearly elastic, weakly
frictional spheres.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf.closures.friction.collisions import RoughSphereRestitution, WaltonRestitution
from ktgf.closures.friction.jenkins_zhang import JenkinsZhangRestitution

JZ = JenkinsZhangRestitution()


def sedfoam_f_mu(e: float, mu: float) -> tuple[float, float]:
    """(f_mu, b1/b2) exactly as the SedFoam block computes them (its alphaSmall guard left out)."""
    mu0 = 7.0 / 2 * mu * (1 + e)
    a1 = mu / mu0 * (math.pi * mu0 * (1 - 2 / math.pi * math.atan(mu0))
                     + 2 * mu0**2 / (1 + mu0**2) * (1 - 2 * mu / mu0))
    a2 = 5.0 / 2 * mu / mu0 * (math.pi / 2 * mu0 * (1 - 2 / math.pi * math.atan(mu0))
                               + (mu0**2 - mu0**4) / (1 + mu0**2) ** 2)
    b1 = mu**2 / (1 + mu0**2)
    b2 = 1.0 / 2 * mu / mu0 * (math.pi / 2 * mu0 * (1 - 2 / math.pi * math.atan(mu0)) + mu0**2 / (1 + mu0**2))
    return 1.0 / 2 * (a1 - a2 * b1 / b2), b1 / b2


@pytest.mark.published
@pytest.mark.parametrize("e", [0.7, 0.9, 0.99])
@pytest.mark.parametrize("mu", [0.01, 0.1, 0.5, 2.0])
def test_effective_restitution_is_the_coded_one(e, mu) -> None:
    f, ratio = sedfoam_f_mu(e, mu)
    assert JZ.effective_restitution(e, mu) == pytest.approx(e - f, rel=1e-14)
    assert JZ.rotational_ratio(e, mu) == pytest.approx(ratio, rel=1e-14)


@pytest.mark.analytic
def test_frictionless_is_the_normal_restitution() -> None:
    for e in (0.5, 0.9):
        assert JZ.effective_restitution(e, 0.0) == e
        assert JZ.rotational_ratio(e, 0.0) == 0.0


@pytest.mark.analytic
def test_limits_of_the_closed_form() -> None:
    for e in (0.7, 1.0):
        mu = 1e-7
        assert JZ.friction_loss(e, mu) / mu == pytest.approx(math.pi / 2, rel=1e-5)
        assert JZ.rotational_ratio(e, mu) / mu == pytest.approx(4 / math.pi, rel=1e-5)
        k = 3.5 * (1 + e)  # all contacts stick: f → 2(1 − 1/k)/k, b1/b2 → 1/k
        assert JZ.friction_loss(e, 1e7) == pytest.approx(2 * (1 - 1 / k) / k, rel=1e-5)
        assert JZ.rotational_ratio(e, 1e7) == pytest.approx(1 / k, rel=1e-5)
    assert JZ.friction_loss(1.0, 1e7) == pytest.approx(12 / 49, rel=1e-5)  # 2η(1 − η), η = q/(2(1 + q)) = 1/7
    # the sticking limit of the exact Maxwellian average (rough spheres, β = 0): 4[η(1 − η) − η³/(q − η)]
    rough = RoughSphereRestitution(beta=0.0)
    assert rough.inelasticity(1.0, 1.0) == pytest.approx(4 * (6 / 49 - (1 / 343) / (0.4 - 1 / 7)), rel=1e-13)
    assert 2 * JZ.friction_loss(1.0, 1e7) - rough.inelasticity(1.0, 1.0) == pytest.approx(
        4 * (1 / 343) / (0.4 - 1 / 7), rel=1e-4)  # the energy that rotation returns, absent from the closed form


@pytest.mark.analytic
@pytest.mark.parametrize("beta0", [1e-12, 1.0])
def test_walton_average_meets_the_closed_form_for_nearly_elastic_weak_friction(beta0) -> None:
    walton = WaltonRestitution(beta0=beta0)
    e = 0.9999
    errors = []
    for mu in (0.001, 0.003):
        f_jz, r_jz = float(JZ.friction_loss(e, mu)), float(JZ.rotational_ratio(e, mu))
        f_w = e - float(walton.effective_restitution(e, mu))
        r_w = float(walton.rotational_ratio(e, mu))
        errors.append((f_w / f_jz - 1.0, r_w / r_jz - 1.0))
        assert abs(f_w / f_jz - 1.0) < 3.0 * mu and abs(r_w / r_jz - 1.0) < 3.0 * mu
    # and the difference is O(μ): it grows about threefold from μ = 0.001 to 0.003
    ratios = np.array(errors[1]) / np.array(errors[0])
    assert np.all((ratios > 2.0) & (ratios < 4.5))


@pytest.mark.analytic
def test_jax_derivative() -> None:
    jax = pytest.importorskip("jax")
    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    grad = jax.grad(lambda m: JZ.effective_restitution(jnp.asarray(0.9), m))(jnp.asarray(0.3))
    h = 1e-6
    fd = (JZ.effective_restitution(0.9, 0.3 + h) - JZ.effective_restitution(0.9, 0.3 - h)) / (2 * h)
    assert float(grad) == pytest.approx(float(fd), rel=1e-7)
    assert float(jax.grad(lambda m: JZ.effective_restitution(jnp.asarray(0.9), m))(jnp.asarray(0.0))) == pytest.approx(
        -math.pi / 2, rel=1e-6)
