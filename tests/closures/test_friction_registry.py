"""The ``friction`` part of the registry: exact reduction at μ = 0, the ``frictional`` model, model files, ``ktgf shear --mu``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from ktgf import get_model, list_models
from ktgf.calibration.model_file import dumps, load_model_file, part_choice_options
from ktgf.calibration.registry_fits import fit_frictional, fit_sheared_structure, frictional_states
from ktgf.cli import app
from ktgf.closures.dense import DENSE_PARAMETERS
from ktgf.closures.friction import WaltonRestitution
from ktgf.closures.friction.calibrated import FRICTIONAL_PARAMETERS
from ktgf.closures.friction.model_slot import Friction
from ktgf.closures.rdf import JammingPowerLaw
from ktgf.errors import InputError
from ktgf.shear.steady import steady_shear

runner = CliRunner()
PHI = np.array([0.05, 0.2, 0.35, 0.45, 0.5, 0.55])


def _same_bits(a, b) -> bool:
    return all(np.array_equal(np.asarray(x), np.asarray(y)) for x, y in zip(a, b))


FRICTIONLESS = get_model("dense")
#: φ_J(0) = 6/(6 + 2√3), the frictionless jamming fraction of the contact-number law (Makse group, "Jamming II", abstract).
PHI_J0 = 6.0 / (6.0 + 2.0 * 3.0**0.5)


@pytest.mark.analytic
def test_frictional_model_at_mu_zero_is_dense_bit_for_bit():
    """One family (issue 33, item 2): μ = 0 gives φ_J(0) and the μ = 0 amplitude exactly and ζ0 untouched: ``dense``."""
    fr = get_model("frictional", mu=0.0)
    for e in (0.5, 0.7, 0.95, 1.0):  # e = 1 is allowed without friction
        assert _same_bits(fr.reduced(PHI, e), FRICTIONLESS.reduced(PHI, e))
        assert _same_bits(fr.reduced(PHI, e, shear=np.full(PHI.size, 3.0)), FRICTIONLESS.reduced(PHI, e, shear=np.full(PHI.size, 3.0)))
        assert _same_bits(fr.coefficients(PHI, e, 0.01, d=1e-3, rho_s=2500.0),
                          FRICTIONLESS.coefficients(PHI, e, 0.01, d=1e-3, rho_s=2500.0))
    a, b = steady_shear(fr, PHI, 0.7), steady_shear(FRICTIONLESS, PHI, 0.7)
    assert _same_bits(a._replace(Trot_over_T=0), b._replace(Trot_over_T=0))
    assert np.all(a.Trot_over_T == 0.0) and np.all(np.isnan(b.Trot_over_T))  # no rotation excited / not modelled
    # and without the EKT part the frictionless core is RET + CS + a φ²/(φ_J(0) − φ)^b at the published φ_J(0)
    core = JammingPowerLaw(a=DENSE_PARAMETERS["a"], phi_c=PHI_J0, exponent=DENSE_PARAMETERS["exponent"])
    assert _same_bits(get_model("frictional", mu=0.0, dissipation="none").reduced(PHI, 0.7),
                      get_model("ret").replace(rdf=core).reduced(PHI, 0.7))


@pytest.mark.analytic
@pytest.mark.parametrize("name", [m.name for m in list_models() if m.friction.key == "none"])
@pytest.mark.parametrize("law", ["walton", "rough-sphere", "chialvo-sundaresan-2013"])
def test_every_model_with_a_friction_part_at_mu_zero_is_unchanged(name, law):
    base = get_model(name)
    fr = base.with_options(friction="coulomb", mu=0.0, restitution=law)
    phi = PHI[PHI < base.phi_max]
    assert _same_bits(fr.reduced(phi, 0.8), base.reduced(phi, 0.8))


@pytest.mark.analytic
def test_friction_changes_the_dissipation_and_the_viscosity_by_walton_closed_forms():
    """ζ0* by Walton's factor, η* by share × (3/5)λ_b* (the tangential impulses' stress), nothing else; with a
    shear measure s, ζ0* gains (1 − f) share (3/5)λ_b* a*²/(3/2), a* = s/(kφ); without the option only ζ0* moves."""
    fr = get_model("frictional", mu=0.5)
    ref = FRICTIONLESS.replace(rdf=fr.rdf)
    a, b = fr.reduced(PHI[:-1], 0.7), ref.reduced(PHI[:-1], 0.7)
    law = WaltonRestitution()
    inel, share = law.inelasticity(0.7, 0.5), law.tangential_shear_share(0.7, 0.5)
    for k in a._fields:
        if k == "zeta0":
            np.testing.assert_allclose(a.zeta0, b.zeta0 * inel / (1 - 0.7**2), rtol=1e-14)
        elif k == "eta":
            np.testing.assert_allclose(a.eta, b.eta + share * 0.6 * b.lambda_b, rtol=1e-14)
        else:
            assert np.array_equal(getattr(a, k), getattr(b, k)), k
    shear = np.full(PHI[:-1].shape, 1.7)
    sheared = fr.reduced(PHI[:-1], 0.7, shear=shear)
    plain = fr.with_options(tangential_stress="none").reduced(PHI[:-1], 0.7, shear=shear)
    astar = shear / (96.0 / (5.0 * np.sqrt(np.pi)) * PHI[:-1])
    lambda_b = ref.reduced(PHI[:-1], 0.7, shear=shear).lambda_b  # at the sheared χ, which the shear measure raises
    loss = (1.0 - law.tangential_work_fraction(0.7, 0.5)) * share * 0.6 * lambda_b
    np.testing.assert_allclose(sheared.zeta0, plain.zeta0 + loss * astar**2 / 1.5, rtol=1e-13)


@pytest.mark.contract
def test_mu_is_routed_to_the_friction_part_and_the_jamming_fraction():
    m = get_model("frictional", mu=0.1)
    assert m.friction.mu == 0.1 and m.rdf.mu == 0.1
    z = 4.0 + 2.0 / (1.0 + 0.1 / FRICTIONAL_PARAMETERS["mu_scale"])  # Z_J from 6 to 4 (Maxwell counting)
    assert m.phi_max == pytest.approx(z / (z + 2.0 * 3.0**0.5), rel=1e-14)  # φ(Z) of Song, Wang & Makse (2008)
    assert get_model("frictional").friction.mu == 0.5  # registered default
    assert m.metadata()["friction"] == "coulomb" and '"friction"' in m.metadata()["model_options"]


@pytest.mark.analytic
def test_registered_model_is_its_documented_parts_checked_by_a_dilute_limit():
    """``frictional`` (μ = 0.5, e = 0.7) against numbers that do not come from its own code path.

    Analytic limit: as φ → 0 (χ → 1, L = d) uniform shear is the Boltzmann-limit closed form of
    model.md §9 with ζ0* scaled by Walton's factor (1 − e_eff²)/(1 − e²):
    φ²T → 25π η*/(13824 ζ0* F) and τ/p → √(3η*ζ0*F/2), p* → 1, where η*, ζ0* are the published φ = 0
    RET values of oracles.md (e = 0.7) and F comes from Walton's rule, which
    test_friction_collisions.py checks against a Monte Carlo of the collision rule.  Its RDF is the
    Chialvo–Sundaresan (2013) form, written out here with the fitted a, b, k and μ_Z, diverging at φ_J(0.5) of the
    contact-number law, Z_J = 4 + 2/(1 + μ/μ_Z), φ_J = Z_J/(Z_J + 2√3).
    """
    m = get_model("frictional", mu=0.5)
    eta_star, zeta0_star = 1.147863, 0.212552  # oracles.md, RET at φ = 0, e = 0.7
    factor = WaltonRestitution(beta0=1.0).inelasticity(0.7, 0.5) / (1 - 0.7**2)
    assert factor > 1.1  # friction adds dissipation: the limit differs from the frictionless one
    phi = 1e-7
    s = steady_shear(m, [phi], 0.7)
    assert s.L_over_d[0] == 1.0
    assert phi**2 * s.T[0] == pytest.approx(25 * np.pi * eta_star / (13824 * zeta0_star * factor), rel=2e-5)
    assert s.tau_over_p[0] == pytest.approx(np.sqrt(1.5 * eta_star * zeta0_star * factor), rel=2e-5)
    assert s.p_over_nT[0] == pytest.approx(1.0, abs=1e-5)
    x = np.array([0.1, 0.3, 0.45, 0.55])
    mu_z, k = FRICTIONAL_PARAMETERS["mu_scale"], FRICTIONAL_PARAMETERS["amplitude_growth"]
    z = 4.0 + 2.0 / (1.0 + 0.5 / mu_z)
    phi_j, amp = z / (z + 2.0 * 3.0**0.5), DENSE_PARAMETERS["a"] * (1.0 + k * 0.5 / (0.5 + mu_z))
    want = (1 - x / 2) / (1 - x) ** 3 + amp * x**2 / (phi_j - x) ** DENSE_PARAMETERS["exponent"]
    np.testing.assert_allclose(m.rdf.chi(x), want, rtol=1e-12)


@pytest.mark.contract
@pytest.mark.parametrize(
    "options, field",
    [
        ({"mu": -0.1}, "mu"),
        ({"stress": "schaeffer", "jj_phi_max": 0.6}, "jj_phi_max"),  # above φ_J(0.5) = 0.5959
        ({"stress": "schaeffer", "jj_phi_min": 0.6}, "jj_phi_min"),
        ({"blend": "tanh", "blend_phi_star": 0.6}, "blend_phi_star"),
        ({"blend": "tanh", "blend_phi_star": 0.5, "blend_width": 0.0}, "blend_width"),
        ({"blend": "sigmoid"}, "blend_phi_star"),
        ({"restitution": "smooth"}, "restitution"),
        ({"stress": "mfix"}, "stress"),
        ({"regularisation": -1e-3}, "regularisation"),
    ],
)
def test_bad_friction_options_are_one_line_errors_naming_the_option(options, field):
    with pytest.raises(InputError) as info:
        get_model("frictional", **options)
    msg = str(info.value)
    assert field in msg and "\n" not in msg


@pytest.mark.contract
def test_frictional_dissipation_needs_e_below_one():
    with pytest.raises(InputError, match="restitution coefficient e = 1"):
        get_model("frictional").reduced(0.3, 1.0)


@pytest.mark.contract
def test_model_files_round_trip_the_friction_part(tmp_path):
    cases = [
        ("frictional", {"mu": 0.3, "restitution": "rough-sphere", "tangential_beta": 0.699}),
        ("frictional", {"restitution": "chialvo-sundaresan-2013", "tangential_stress": "none"}),
        ("ret", {"friction": "coulomb", "mu": 0.25, "stress": "srivastava-sundaresan", "jj_phi_min": 0.55,
                 "blend": "tanh", "blend_phi_star": 0.56}),
        ("frictional", {"friction": "none"}),  # friction removed: RET with the frictionless CS13 RDF at mu = 0.5's φ_c
    ]
    for k, (base, opts) in enumerate(cases):
        path = tmp_path / f"m{k}.toml"
        path.write_text(dumps(base, opts, name=f"m{k}"))
        mf = load_model_file(path)
        want = get_model(base, **opts)
        assert mf.model.friction == want.friction and mf.model.rdf == want.rdf
        assert _same_bits(mf.model.reduced(0.4, 0.7), want.reduced(0.4, 0.7))
        # what a calibration would write back (the part choice and the changed options) reloads to the same model
        written = {**part_choice_options(mf.model, get_model(base)),
                   **{o: v for o, v in mf.model.options().items() if get_model(base).options().get(o, object()) != v}}
        again = tmp_path / f"again{k}.toml"
        again.write_text(dumps(base, written))
        assert load_model_file(again).model.friction == mf.model.friction


@pytest.mark.contract
def test_model_file_friction_option_errors_name_the_field(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(dumps("ret", {"mu": 0.3}))  # no friction part chosen: mu is not an option of ret
    with pytest.raises(InputError, match="model.options.mu"):
        load_model_file(path)


@pytest.mark.contract
def test_shear_cli_mu_prints_the_dem_columns():
    r = runner.invoke(app, ["shear", "--model", "frictional", "--mu", "0.5", "--phi", "0.4,0.5", "--e", "0.7", "--format", "json"])
    assert r.exit_code == 0, r.output
    rows = json.loads(r.stdout)
    want = steady_shear(get_model("frictional", mu=0.5), [0.4, 0.5], 0.7)
    for i, row in enumerate(rows):
        for col in ("phi", "T", "Trot_over_T", "p_star", "tau_over_p", "p_over_nT"):
            assert row[col] == pytest.approx(float(getattr(want, col)[i]), rel=1e-12), col
        assert {"eta_star", "eta_over_eta0", "astar", "L_over_d"} <= set(row)  # the frictionless columns stay
    # a frictionless model: no rotation (null), and --mu 0 changes nothing
    plain = json.loads(runner.invoke(app, ["shear", "--model", "ret", "--phi", "0.3", "--e", "0.7", "--format", "json"]).stdout)
    zero = json.loads(runner.invoke(app, ["shear", "--model", "ret", "--mu", "0", "--phi", "0.3", "--e", "0.7",
                                          "--format", "json"]).stdout)
    assert plain == zero and plain[0]["Trot_over_T"] is None
    csv = runner.invoke(app, ["shear", "--model", "frictional", "--mu", "0.3", "--phi", "0.4", "--e", "0.7", "--format", "csv"])
    assert csv.stdout.splitlines()[0] == ("model,phi,e,T,eta_star,eta_over_eta0,p_over_nT,astar,tau_over_p,L_over_d,"
                                          "Trot_over_T,p_star,mu")  # the frictionless columns keep their places


@pytest.mark.contract
def test_shear_cli_says_when_a_fitted_model_is_asked_at_another_restitution():
    """The registered fits know their restitutions (REGISTERED_FITS): dense e = 0.9, frictional's μ > 0 part e = 0.7;
    a request elsewhere prints one note on stderr naming the fitted e, the output itself unchanged."""
    from ktgf.calibration.registry_fits import fitted_restitutions

    assert fitted_restitutions("dense", 0.0) == (0.9,) and fitted_restitutions("frictional", 0.0) == (0.9,)
    assert fitted_restitutions("frictional", 0.25) == (0.7,) and fitted_restitutions("ret", 0.0) is None

    def note(*args):
        r = runner.invoke(app, ["shear", *args, "--phi", "0.5", "--format", "json"])
        assert r.exit_code == 0, r.output
        json.loads(r.stdout)  # stdout stays clean JSON
        return r.stderr

    assert "dense (mu = 0) was fitted at e = 0.9 only; e = 0.7 is a prediction" in note("--model", "dense", "--e", "0.7")
    assert "frictional (mu = 0.5) was fitted at e = 0.7 only; e = 0.9" in note("--model", "frictional", "--e", "0.7,0.9")
    assert "note" not in note("--model", "dense", "--e", "0.9")
    assert "note" not in note("--model", "frictional", "--mu", "0.25", "--e", "0.7")
    assert "note" not in note("--model", "ret", "--e", "0.7")


@pytest.mark.contract
@pytest.mark.parametrize(
    "extra, word",
    [
        (["--mu", "-0.5"], "mu"),
        (["--mu", "0.5", "-O", "stress=schaeffer", "-O", "jj_phi_max=0.6"], "jj_phi_max"),
        (["--mu", "0.5", "-O", "blend=tanh", "-O", "blend_phi_star=0.5", "-O", "blend_width=0"], "blend_width"),
        (["--mu", "0.5", "-O", "stress=schaeffer"], "--stress-scale"),
        (["--mu", "0.5", "--phi", "0.6"], "phi"),
    ],
)
def test_shear_cli_bad_friction_input_exits_2_with_one_line(extra, word):
    args = ["shear", "--model", "frictional", "--e", "0.7"] + (["--phi", "0.4"] if "--phi" not in extra else []) + extra
    r = runner.invoke(app, args)
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and word in lines[0]


@pytest.mark.analytic
def test_shear_cli_frictional_stress_adds_to_the_pressure():
    """At φ = 0.55 > φ_min the Johnson–Jackson stress adds p_f/(ρ_s d²γ̇²) to p* and sin φ_fr p_f to τ."""
    scale = 2500.0 * 1e-6 * 100.0  # ρ_s d² γ̇² [Pa]: 2500 kg/m³, 1 mm, 10 /s
    args = ["shear", "--model", "frictional", "--mu", "0.5", "--phi", "0.55", "--e", "0.7", "--format", "json"]
    kin = json.loads(runner.invoke(app, args).stdout)[0]
    r = runner.invoke(app, args + ["-O", "stress=schaeffer", "--stress-scale", str(scale)])
    assert r.exit_code == 0, r.output
    fr = json.loads(r.stdout)[0]
    m = get_model("frictional", stress="schaeffer")
    p_f = float(m.friction.pressure_part(m.phi_max).pressure(0.55)) / scale
    assert fr["p_star"] == pytest.approx(kin["p_star"] + p_f, rel=1e-12)
    tau = kin["tau_over_p"] * kin["p_star"] + np.sin(np.radians(28.5)) * p_f
    assert fr["tau_over_p"] == pytest.approx(tau / fr["p_star"], rel=1e-12)


@pytest.mark.contract
def test_walton_under_jit_is_the_numpy_value():
    jax = pytest.importorskip("jax")
    m = get_model("frictional")
    got = jax.jit(lambda e: m.reduced(0.4, e, check=False).zeta0)(jax.numpy.asarray(0.7))
    assert float(got) == float(m.reduced(0.4, 0.7).zeta0)


@pytest.mark.contract
def test_friction_part_is_hashable_and_a_value():
    a, b = Friction(mu=0.3), Friction(mu=0.3)
    assert a == b and hash(a) == hash(b) and a.law == b.law


@pytest.mark.dem
def test_the_fitted_constants_are_the_registered_ones():
    """μ_Z and k of ``frictional`` refit from the shipped μ = 0.5 uniform shear (a, b, c, A from step 1)."""
    step1 = fit_sheared_structure()
    fit = fit_frictional(step1.values)
    assert fit.success and fit.n_points == 21
    for name, value in FRICTIONAL_PARAMETERS.items():
        assert fit.values[name] == pytest.approx(value, rel=2e-4), name
    rdf = get_model("frictional").rdf
    assert (rdf.mu_scale, rdf.amplitude_growth) == (FRICTIONAL_PARAMETERS["mu_scale"], FRICTIONAL_PARAMETERS["amplitude_growth"])


@pytest.mark.dem
def test_frictional_pressure_within_ten_percent_at_mu_half_and_phi_j_alone_is_not_enough():
    """Issue 33 goal for p/(nT) at μ = 0.5, φ 0.3–0.57 (the fit set of μ_Z, k); moving φ_J(μ) alone (k = 0, μ_Z
    refit) misses it by more than 20 %, so the second parameter is needed and the test can fail."""
    states = frictional_states()
    s = steady_shear(get_model("frictional", mu=0.5), states["phi"], 0.7)
    err = s.p_over_nT / states["p_over_nT"] - 1.0
    assert np.all(np.abs(err) < 0.10), err
    alone = fit_frictional(DENSE_PARAMETERS, states, hold={"amplitude_growth": 0.0})
    assert np.max(np.abs(np.expm1(alone.residuals[1]))) > 0.20


@pytest.mark.analytic
def test_tangential_stress_of_rough_spheres_is_sticking_walton_and_chialvo_sundaresan_is_refused():
    """Constant β: share 3η/(2(1 + e)) exactly (the first-order Maxwellian result) and Walton's rule at STICKING_MU
    has the rough-sphere T_rot/T (steady and HCS) to 1e-13; β = −1 has no tangential impulse; an effective restitution
    (Chialvo–Sundaresan) is refused in one line naming the fix."""
    from ktgf.closures.friction import RoughSphereRestitution
    from ktgf.closures.friction.model_slot import STICKING_MU

    for beta in (0.699, -0.5):
        part = Friction(mu=0.3, restitution="rough-sphere", tangential_beta=beta, tangential_stress="maxwellian")
        rough, sticking = RoughSphereRestitution(beta=beta), WaltonRestitution(beta0=beta)
        share, loss = part.tangential_coefficients(0.7)
        assert share == pytest.approx(1.5 * rough.tangential_factor(0.3) / 1.7, rel=1e-13)
        assert sticking.rotational_ratio(0.7, STICKING_MU) == pytest.approx(rough.rotational_ratio(0.7, 0.3), rel=1e-13)
        assert sticking.hcs_rotational_ratio(0.7, STICKING_MU) == pytest.approx(rough.hcs_rotational_ratio(0.7, 0.3),
                                                                                rel=1e-12)
        assert np.isfinite(loss)
    smooth = Friction(mu=0.3, restitution="rough-sphere", tangential_beta=-1.0, tangential_stress="maxwellian")
    assert smooth.tangential_coefficients(0.7) == (0.0, 0.0)
    with pytest.raises(InputError) as info:
        Friction(mu=0.3, restitution="chialvo-sundaresan-2013", tangential_stress="maxwellian")
    assert "\n" not in str(info.value) and "tangential_stress = 'none'" in str(info.value)


@pytest.mark.dem
def test_frictional_meets_the_goals_to_phi_055_cross_validated():
    """Issue 33 goals (T 15 %, p/(nT) and τ/p 10 %) at μ = 0.5, leave-one-state-out refits of μ_Z and k predicting
    each left-out state, φ 0.3–0.55 (φ 0.57 misses them: docs/friction.md §6.0).  Without the tangential impulses'
    stress τ/p misses at φ ≤ 0.52 (−10.6 to −16.5 %), so the test can fail."""
    from ktgf.calibration.registry_fits import OBSERVABLES, leave_one_out

    states = frictional_states()
    loo = leave_one_out(lambda sub: {**DENSE_PARAMETERS, **fit_frictional(DENSE_PARAMETERS, sub).values}, states)
    goals = {"T": 0.15, "p_over_nT": 0.10, "tau_over_p": 0.10}
    inside = states["phi"] <= 0.55
    for k, name in enumerate(OBSERVABLES):
        assert np.all(np.abs(loo[k][inside]) < goals[name]), (name, loo[k])


@pytest.mark.dem
def test_nothing_refused_where_the_particles_flow():
    """Issue 33 item 6: μ = 0.5, φ = 0.57 flows in the DEM (p* = 79): the model answers; above φ_J(μ) one line names it."""
    m = get_model("frictional", mu=0.5)
    assert m.phi_max > 0.57
    assert np.isfinite(steady_shear(m, 0.57, 0.7).p_star)
    with pytest.raises(InputError) as info:
        steady_shear(m, 0.6, 0.7)
    msg = str(info.value)
    assert "\n" not in msg and "phi_J(mu=0.5)" in msg and f"{m.phi_max:.4g}" in msg
