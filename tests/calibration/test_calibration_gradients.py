"""Jacobians of the calibration residuals against finite differences, and a Couette fit that recovers known walls/RDF.

Uniform shear: jax.jacfwd through the closures (exact) against central differences (h = 1e-6,
truncation ~1e-10).  Couette: the implicit-function-theorem Jacobian (one factorisation, no
re-solve) against central differences of fully re-solved cells.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers.calibration_synthetic import synthetic_couette as synthetic_couette_file
from helpers.calibration_synthetic import synthetic_shear
from ktgf import get_model
from ktgf.calibration import calibrate, read_data
from ktgf.calibration.residuals import _shear_jacobian_function, make_terms


def _fd(term, x, h_rel=1e-6):
    J = np.empty((term.obs.size, len(x)))
    for j, n in enumerate(x):
        h = h_rel * max(abs(x[n]), 1e-2)
        J[:, j] = (term.residuals({**x, n: x[n] + h}) - term.residuals({**x, n: x[n] - h})) / (2 * h)
    return J


@pytest.mark.analytic
@pytest.mark.parametrize("model, x", [
    ("proposed", {"phi_f": 0.47, "phi_c": 0.63, "beta": 1.9}),
    ("visc-div", {"phi_c": 0.65, "beta": 1.6, "alpha": 1.1}),
])
def test_uniform_shear_jax_jacobian_matches_finite_differences(tmp_path, model, x):
    f = synthetic_shear(tmp_path / "s.csv", get_model("ret"), [0.3, 0.5, 0.55, 0.6])
    (term,) = make_terms(get_model(model), [read_data(f)], list(x), "sigma")
    J = term.jacobian(x)
    assert term.method == "jax", term.method_note  # exact: traced through the closures and the closed form
    assert np.abs(J).max() > 1.0  # the parameters matter
    np.testing.assert_allclose(J, _fd(term, x), rtol=1e-6, atol=1e-7 * np.abs(J).max())


@pytest.mark.contract
def test_uniform_shear_jacobian_compiled_once_per_model_and_data(tmp_path):
    """A second term of the same model, names and states reuses the compiled Jacobian; other states do not."""
    x = {"phi_c": 0.65, "beta": 1.6}
    f1 = synthetic_shear(tmp_path / "a.csv", get_model("ret"), [0.3, 0.5])
    f2 = synthetic_shear(tmp_path / "b.csv", get_model("ret"), [0.3, 0.55])
    (t1,) = make_terms(get_model("visc-div"), [read_data(f1)], list(x), "sigma")
    (t2,) = make_terms(get_model("visc-div"), [read_data(f1)], list(x), "sigma")
    J1, J2 = t1.jacobian(x), t2.jacobian(x)
    assert t1._jac is t2._jac
    np.testing.assert_array_equal(J1, J2)
    # other states or other fitted names get their own function (not called here: no second compilation)
    other_data = _shear_jacobian_function(get_model("visc-div"), ("phi_c", "beta"), read_data(f2))
    other_names = _shear_jacobian_function(get_model("visc-div"), ("beta", "phi_c"), read_data(f1))
    assert other_data is not t1._jac and other_names is not t1._jac


N_CELLS = 60
TRUTH = {"specularity": 0.2, "beta": 2.0}


@pytest.fixture(scope="module")
def synthetic_couette(tmp_path_factory, data_dir):
    """Couette data of proposed (β = 2) with JJ walls φ' = 0.2 in the shared file's case, from the Dataset route."""
    from ktgf.data import read_couette

    case = read_couette(data_dir / "dem_couette_e0.9_phi0.50.csv").case
    return synthetic_couette_file(tmp_path_factory.mktemp("syn") / "couette.csv", get_model("proposed", beta=TRUTH["beta"]),
                                  TRUTH["specularity"], case, N_CELLS)


@pytest.mark.analytic
def test_couette_ift_jacobian_matches_resolved_finite_differences(synthetic_couette):
    x = {"specularity": 0.15, "beta": 1.8, "wall_restitution": 0.85}
    (term,) = make_terms(get_model("proposed"), [read_data(synthetic_couette)], list(x), "relative", n_cells=N_CELLS)
    J = term.jacobian(x)
    J_fd = np.empty_like(J)
    for j, n in enumerate(x):
        h = 1e-4 * x[n]
        up = term.residuals({**x, n: x[n] + h})
        dn = term.residuals({**x, n: x[n] - h})
        J_fd[:, j] = (up - dn) / (2 * h)
    np.testing.assert_allclose(J, J_fd, rtol=2e-4, atol=2e-5 * np.abs(J).max())


@pytest.mark.analytic
def test_couette_fit_recovers_walls_and_rdf_exponent(synthetic_couette):
    fit = calibrate(get_model("proposed"), [read_data(synthetic_couette)], ["specularity", "beta"], n_cells=N_CELLS)
    assert fit.success, fit.message
    assert fit.value_dict() == pytest.approx(TRUTH, rel=1e-4)
    assert fit.walls["wall_restitution"] == 0.9  # not fitted: e_w = e of the header


@pytest.mark.analytic
def test_jax_jacobian_survives_option_checks_that_reject_tracers(tmp_path):
    """Parts whose __post_init__ accepts only real numbers (as strict option checks do) are still traced exactly."""
    import dataclasses
    from numbers import Real

    from ktgf.closures.rdf import ViscosityDivergence
    from ktgf.errors import InputError

    @dataclasses.dataclass(frozen=True)
    class StrictVD(ViscosityDivergence):
        def __post_init__(self) -> None:
            for k in ("phi_f", "phi_c", "beta"):
                if not isinstance(getattr(self, k), Real):
                    raise InputError(f"option {k} must be a real number")

    model = get_model("proposed").replace(rdf=StrictVD())
    f = synthetic_shear(tmp_path / "s.csv", get_model("proposed", beta=2.2), [0.52, 0.56, 0.6])
    (term,) = make_terms(model, [read_data(f)], ["phi_c", "beta"], "sigma")
    x = {"phi_c": 0.63, "beta": 1.9}
    J = term.jacobian(x)
    assert term.method == "jax", term.method_note
    np.testing.assert_allclose(J, _fd(term, x), rtol=1e-6, atol=1e-7 * np.abs(J).max())
