"""The least-squares driver recovers parameters from synthetic data made by the model with other values.

The synthetic data are exact model outputs (noise-free, stated errors 1 %), so the fitted values
must equal the generating ones to the solver tolerance, from a start at the model's defaults.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from helpers.calibration_synthetic import synthetic_shear
from ktgf import get_model
from ktgf.calibration import calibrate, read_data
from ktgf.errors import InputError

TRUE = {"phi_c": 0.625, "beta": 2.1}


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    truth = get_model("proposed", **TRUE)
    return synthetic_shear(tmp_path_factory.mktemp("syn") / "shear.csv", truth, [0.3, 0.52, 0.55, 0.58, 0.6])


@pytest.mark.analytic
def test_recovers_rdf_parameters_from_uniform_shear(synthetic):
    fit = calibrate(get_model("proposed"), [read_data(synthetic)], ["phi_c", "beta"])
    assert fit.success, fit.message
    assert [p.start for p in fit.parameters] == [0.64, 1.75]  # the defaults, away from the truth
    for name, v in fit.value_dict().items():
        assert v == pytest.approx(TRUE[name], rel=1e-6)
    assert fit.cost < 1e-12
    assert fit.errors == "scaled" and np.all(np.isfinite(fit.stderr))
    assert fit.correlation[0, 0] == pytest.approx(1.0) and abs(fit.correlation[0, 1]) <= 1.0


@pytest.mark.analytic
def test_stated_errors_match_the_linearised_covariance(synthetic):
    """With σ-weights and errors='stated', C = (JᵀJ)⁻¹: check it against the Jacobian of finite differences."""
    data = [read_data(synthetic)]
    fit = calibrate(get_model("proposed"), data, ["phi_c", "beta"], errors="stated")
    from ktgf.calibration.residuals import make_terms

    (term,) = make_terms(get_model("proposed"), data, ["phi_c", "beta"], "sigma")
    x = fit.value_dict()
    J = np.empty((term.obs.size, 2))
    for j, n in enumerate(x):
        h = 1e-6
        J[:, j] = (term.residuals({**x, n: x[n] + h}) - term.residuals({**x, n: x[n] - h})) / (2 * h)
    se = np.sqrt(np.diag(np.linalg.inv(J.T @ J)))
    np.testing.assert_allclose(fit.stderr, se, rtol=1e-5)


@pytest.mark.contract
def test_a_fit_stopped_early_keeps_its_best_point(synthetic):
    fit = calibrate(get_model("proposed"), [read_data(synthetic)], ["phi_c", "beta"], max_evaluations=2)
    assert not fit.success and "stopped" in fit.message
    start_cost = calibrate(get_model("proposed"), [read_data(synthetic)], ["phi_c", "beta"], max_evaluations=1).cost
    assert fit.cost <= start_cost


@pytest.mark.analytic
def test_unidentifiable_parameters_are_reported(data_dir):
    """On dem_uniform_shear.csv (φ = 0.3, 0.5) proposed's φ_c and β act only through χ(0.5): one combination."""
    fit = calibrate(get_model("proposed"), [read_data(data_dir / "dem_uniform_shear.csv")], ["phi_c", "beta"])
    assert not np.all(np.isfinite(fit.stderr))
    assert "do not determine" in fit.message


@pytest.mark.contract
@pytest.mark.parametrize("names, kw, match", [
    (["phi_c"], {"start": {"phi_c": 0.9}}, r"phi_c = 0.9 is out of range: valid 0.601 <= phi_c <= 0.74"),
    (["beta"], {"start": {"beta": -1.0}}, r"beta = -1 is out of range"),
    (["nope"], {}, r"'nope' is not a parameter of model 'proposed'"),
    (["specularity"], {}, r"wall parameters need Couette data"),
    (["phi_c"], {"bounds": {"phi_c": (0.7, 0.65)}}, r"empty range"),
    (["phi_c"], {"weights": "abs"}, r"weights 'abs' is not valid"),
    (["phi_c"], {"walls": {"specularity": 1.5}}, r"wall parameter specularity = 1.5 is out of range"),
    (["phi_c"], {"walls": {"roughness": 0.5}}, r"wall parameter 'roughness' is unknown"),
])
def test_bad_parameters_are_one_line_errors(synthetic, names, kw, match):
    with pytest.raises(InputError, match=match) as exc:
        calibrate(get_model("proposed"), [read_data(synthetic)], names, **kw)
    assert "\n" not in str(exc.value)


@pytest.mark.contract
def test_generic_parameters_are_the_float_options():
    from ktgf.calibration import fittable_parameters

    # Lun et al.'s alpha (a float option) counts; strings (zeta11, omega) and bools (sonine) do not
    for name in ("visc-div", "ret"):
        opts = get_model(name).options()
        expected = {k for k, v in opts.items() if isinstance(v, float) and not isinstance(v, bool)}
        assert set(fittable_parameters(get_model(name))) == expected
    assert {"alpha", "phi_f", "phi_c", "beta"} <= set(fittable_parameters(get_model("visc-div")))
    assert not {"zeta11", "sonine", "omega"} & (set(fittable_parameters(get_model("ret"))) | set(fittable_parameters(get_model("enskog"))))
    assert {"specularity", "wall_restitution"} <= set(fittable_parameters(get_model("ret"), couette=True))
    assert math.isnan(fittable_parameters(get_model("ret"), couette=True)["specularity"])


@pytest.mark.contract
def test_a_failing_evaluation_stops_the_fit_and_keeps_the_best_point(synthetic, monkeypatch):
    """A solver failure in the middle of a fit: no exception, success False, the reason, the best point so far."""
    from ktgf.calibration import residuals
    from ktgf.errors import ConvergenceError

    calls = []
    original = residuals.ShearTerm.residuals

    def flaky(self, values):
        calls.append(dict(values))
        if len(calls) == 3:
            raise ConvergenceError("the Couette solver did not converge at beta=...")
        return original(self, values)

    monkeypatch.setattr(residuals.ShearTerm, "residuals", flaky)
    fit = calibrate(get_model("proposed"), [read_data(synthetic)], ["phi_c", "beta"])
    assert not fit.success and fit.message.startswith("fit failed: the Couette solver did not converge")
    costs = [0.5 * float(np.sum(original(_term(synthetic), v) ** 2)) for v in calls[:2]]
    assert fit.cost == pytest.approx(min(costs))


def _term(path):
    from ktgf.calibration.residuals import make_terms

    return make_terms(get_model("proposed"), [read_data(path)], ["phi_c", "beta"], "sigma")[0]
