"""The homogeneous cooling state of frictional models (docs/friction.md §7).

Oracle: the coupled cooling of translation and rotation of rough spheres (Luding, Huthmann, McNamara &
Zippelius, PRE 58, 3416 (1998)), integrated directly from the collision coefficients A, B, C (which
tests/closures/test_friction_collisions.py checks against a Monte Carlo of the collision rule), starting without
rotation.  After the transient T must follow Haff's law with the rate ktgf's HCS predicts.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ktgf.closures.friction.collisions import RoughSphereRestitution, WaltonRestitution
from ktgf.closures.friction.model_slot import NoFriction
from ktgf.closures.models import get_model
from ktgf.errors import InputError
from ktgf.hcs import cooling_rate, cooling_time, critical_wavenumbers, haff_temperature, integrate_cooling

PHI, E, D, THETA0 = 0.2, 0.7, 1e-3, 1e-2
LATE = 1e3  # start of the Haff window, in Haff times t0


def coupled_history(model, energy_changes, t, rtol=1e-11):
    """(T, T_rot) from dT/dt = ζs(T) ΔE_tr(r) T/(1 − e²), dT_rot/dt = ζs(T) ΔE_rot(r) T/(1 − e²), T_rot(0) = 0.

    ``energy_changes(r)`` gives (ΔE_tr, ΔE_rot) per collision in units where the smooth gas has ΔE_tr = −(1 − e²);
    ζs is the cooling rate of the model without its friction part (same RDF, so the same collision frequency).
    """
    # the smooth gas's collision frequency scales as √T (ν0, model.md §8): ζs(T) = ζs(T0) √(T/T0)
    z0 = float(cooling_rate(model.replace(friction=NoFriction()), PHI, E, THETA0, d=D)) / (1.0 - E**2)

    def rhs(_, y):
        T, Tr = y
        tr, rot = energy_changes(Tr / T)
        z = z0 * np.sqrt(T / THETA0) * T
        return [z * tr, z * rot]

    sol = solve_ivp(rhs, (0.0, t[-1]), [THETA0, 0.0], method="DOP853", t_eval=t, rtol=rtol, atol=1e-30)
    assert sol.success
    return sol.y


def rough_energy_changes(law, mu):
    A, B, C = law.collision_coefficients(E, mu)
    return lambda r: (-4.0 * (A - B * r), 4.0 * (B - C * r))


def check_haff_after_transient(model, T, Tr, t, r_expected, rtol):
    t0 = float(cooling_time(model, PHI, E, THETA0, d=D))
    # T_rot/T approaches its HCS value as a power of t (measured: 1e-2 at 10 t0, 4e-7 at 1e3 t0 for the rough case)
    late = t >= LATE * t0
    i1 = np.flatnonzero(late)[0]
    assert Tr[-1] / T[-1] == pytest.approx(r_expected, rel=rtol)
    t1_haff = float(cooling_time(model, PHI, E, T[i1], d=D))
    predicted = haff_temperature(t[late] - t[i1], T[i1], t1_haff)
    np.testing.assert_allclose(T[late], predicted, rtol=rtol)
    return t0


@pytest.mark.analytic
def test_rough_sphere_hcs_is_haffs_law_with_the_predicted_rate():
    beta, mu = 0.4, 0.5
    model = get_model("frictional", restitution="rough-sphere", tangential_beta=beta, mu=mu)
    law = RoughSphereRestitution(beta=beta)
    t0 = float(cooling_time(model, PHI, E, THETA0, d=D))
    t = np.concatenate([[0.0], np.geomspace(1e-3 * t0, 1e5 * t0, 81)])
    T, Tr = coupled_history(model, rough_energy_changes(law, mu), t)
    check_haff_after_transient(model, T, Tr, t, float(law.hcs_rotational_ratio(E, mu)), rtol=1e-6)
    # ktgf's own integration of dθ/dt = −ζ0(θ)θ from θ at the same late time agrees too
    i1 = np.flatnonzero(t >= LATE * t0)[0]
    own = integrate_cooling(model, PHI, E, T[i1], t[i1:] - t[i1], d=D)
    np.testing.assert_allclose(own, T[i1:], rtol=1e-6)
    # the steady-shear dissipation is not the HCS one (would cool faster here)
    shear = float(model.reduced(PHI, E).zeta0) / float(model.reduced(PHI, E, hcs=True).zeta0)
    assert shear > 1.05


@pytest.mark.analytic
def test_walton_hcs_is_haffs_law_with_the_predicted_rate():
    mu = 0.5
    model = get_model("frictional", mu=mu)
    law = WaltonRestitution()
    t0 = float(cooling_time(model, PHI, E, THETA0, d=D))
    t = np.concatenate([[0.0], np.geomspace(1e-3 * t0, 3e3 * t0, 29)])
    T, Tr = coupled_history(model, lambda r: law._energy_changes(E, mu, r), t, rtol=1e-8)
    # Walton's ratio settles more slowly (measured: T_rot/T 4.5e-6 below r_HCS at 3e3 t0, Haff within 7e-6);
    # each step is a quadrature, so the window stops at 3e3 t0 (5 s) and the tolerance is 2e-5
    check_haff_after_transient(model, T, Tr, t, law.hcs_rotational_ratio(E, mu), rtol=2e-5)
    # the HCS cools 1.5 times more slowly than the steady-shear e_eff says (docs/friction.md §7)
    shear = float(model.reduced(PHI, E).zeta0) / float(model.reduced(PHI, E, hcs=True).zeta0)
    assert shear == pytest.approx(law.inelasticity(E, mu) / law.hcs_inelasticity(E, mu), rel=1e-12)
    assert 1.4 < shear < 1.6


@pytest.mark.analytic
def test_mu_zero_is_the_frictionless_hcs_bit_for_bit():
    frictional = get_model("frictional", mu=0.0)
    smooth = frictional.replace(friction=NoFriction())
    phi, e = np.array([0.1, 0.3, 0.5]), np.array([0.5, 0.7, 0.9])
    for a, b in zip(frictional.reduced(phi, e, hcs=True), smooth.reduced(phi, e, hcs=True)):
        assert np.array_equal(a, b)
    for a, b in zip(critical_wavenumbers(frictional.reduced(phi, e, hcs=True)), critical_wavenumbers(smooth.reduced(phi, e))):
        assert np.array_equal(a, b)
    t = np.linspace(0.0, 1.0, 5)
    assert np.array_equal(integrate_cooling(frictional, 0.3, 0.7, THETA0, t, d=D), integrate_cooling(smooth, 0.3, 0.7, THETA0, t, d=D))


@pytest.mark.analytic
def test_the_correlation_length_is_inactive_in_the_hcs():
    ekt = get_model("frictional")  # with the EKT correlation length (c fitted in shear)
    plain = get_model("frictional", dissipation="none")
    assert float(cooling_rate(ekt, 0.5, 0.7, THETA0, d=D)) == float(cooling_rate(plain, 0.5, 0.7, THETA0, d=D))
    with pytest.raises(InputError, match="no shear"):
        ekt.reduced(0.5, 0.7, hcs=True, shear=1.0)


@pytest.mark.contract
def test_no_finite_hcs_ratio_is_a_one_line_error():
    model = get_model("frictional", mu=0.3)
    with pytest.raises(InputError) as info:
        cooling_rate(model, 0.3, 0.7, THETA0, d=D)
    msg = str(info.value)
    assert "\n" not in msg and "mu = 0.3" in msg and "e = 0.7" in msg and "valid mu >=" in msg
    threshold = float(msg.split("valid mu >= ")[1].split()[0])
    assert 0.3 < threshold < 0.5
    assert np.isfinite(WaltonRestitution().hcs_rotational_ratio(0.7, threshold + 2e-3))
    with pytest.raises(InputError, match="chialvo-sundaresan-2013.*no homogeneous cooling state"):
        cooling_rate(get_model("frictional", restitution="chialvo-sundaresan-2013", tangential_stress="none"), 0.3, 0.7,
                     THETA0, d=D)


@pytest.mark.contract
def test_hcs_cli_without_a_finite_ratio_exits_2_with_one_line(tmp_path):
    from typer.testing import CliRunner

    from ktgf.calibration.model_file import dumps
    from ktgf.cli import app

    path = tmp_path / "weak.toml"
    path.write_text(dumps("frictional", {"mu": 0.3}, name="weak"))
    res = CliRunner().invoke(app, ["hcs", "haff", "--model-file", str(path), "--phi", "0.3", "--e", "0.7",
                                   "--theta0", "0.01", "--d", "0.001", "--n", "3"])
    assert res.exit_code == 2
    lines = [ln for ln in res.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "no homogeneous cooling state" in lines[0] and "valid mu >=" in lines[0]
