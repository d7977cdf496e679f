"""Haff's law: closed form vs the integrated ODE, and the oracle numbers of oracles.md."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ktgf import InputError, get_model
from ktgf.closures import PAPER_MODELS, nu0
from ktgf.hcs import cooling_rate, cooling_time, haff_history, haff_temperature, integrate_cooling
from ktgf.io import write_netcdf

ORACLE_REL = 1e-5  # oracles.md: 6-digit values, 1e-5 relative


@pytest.mark.published
def test_haff_oracle_numbers_ret():
    """oracles.md 'Haff's law': d = 1, θ0 = 1, RET with CS χ."""
    assert nu0(0.1, 1.0, 1.0) == pytest.approx(1.083244, rel=ORACLE_REL)
    assert cooling_rate("ret", 0.1, 0.9, 1.0, d=1.0) == pytest.approx(0.111449, rel=ORACLE_REL)
    assert cooling_time("ret", 0.1, 0.9, 1.0, d=1.0) == pytest.approx(17.945375, rel=ORACLE_REL)
    assert cooling_rate("ret", 0.3, 0.7, 1.0, d=1.0) == pytest.approx(1.711739, rel=ORACLE_REL)
    assert cooling_time("ret", 0.3, 0.7, 1.0, d=1.0) == pytest.approx(1.168402, rel=ORACLE_REL)


@pytest.mark.analytic
@pytest.mark.parametrize("name", PAPER_MODELS)
@pytest.mark.parametrize("phi,e", [(0.1, 0.9), (0.3, 0.7), (0.55, 0.5)])
def test_integrated_cooling_follows_haff(name, phi, e):
    """The ODE dθ/dt = −ζ0(θ)θ, integrated with the model's SI ζ0(θ), reproduces θ0/(1 + t/t0)²."""
    theta0, d = 2.5e-3, 1e-3
    t0 = cooling_time(name, phi, e, theta0, d=d)
    t = np.linspace(0.0, 50.0 * t0, 101)
    theta = integrate_cooling(name, phi, e, theta0, t, d=d)
    np.testing.assert_allclose(theta, haff_temperature(t, theta0, t0), rtol=1e-8)
    # At t = t0 the temperature is a quarter of θ0 (√θ halves): an independent check of t0 = 2/ζ0.
    assert integrate_cooling(name, phi, e, theta0, [t0], d=d)[0] == pytest.approx(theta0 / 4, rel=1e-8)


@pytest.mark.analytic
def test_cooling_time_scales_as_inverse_sqrt_theta0_and_linear_in_d():
    t1 = cooling_time("enskog", 0.2, 0.8, 1e-2, d=1e-3)
    assert cooling_time("enskog", 0.2, 0.8, 4e-2, d=1e-3) == pytest.approx(t1 / 2, rel=1e-12)
    assert cooling_time("enskog", 0.2, 0.8, 1e-2, d=3e-3) == pytest.approx(3 * t1, rel=1e-12)


@pytest.mark.analytic
def test_elastic_gas_does_not_cool():
    t = np.linspace(0.0, 10.0, 5)
    np.testing.assert_allclose(integrate_cooling("ret", 0.2, 1.0, 1.0, t, d=1.0), 1.0, rtol=0, atol=1e-14)
    assert math.isinf(cooling_time("ret", 0.2, 1.0, 1.0, d=1.0))


@pytest.mark.published
def test_haff_history_dataset_and_netcdf(tmp_path):
    import xarray as xr

    ds = haff_history(PAPER_MODELS, 0.3, 0.7, 1.0, d=1.0, n=50)
    assert ds["theta_numeric"].dims == ("model", "t") and ds.sizes == {"model": 4, "t": 50}
    np.testing.assert_allclose(ds["theta_numeric"], ds["theta_haff"], rtol=1e-8)
    ret = list(ds["model"].values).index("ret")
    assert float(ds["t0"][ret]) == pytest.approx(1.168402, rel=ORACLE_REL)
    assert float(ds["t"][-1]) == pytest.approx(10 * float(ds["t0"].max()))
    back = xr.load_dataset(write_netcdf(ds, tmp_path / "haff.nc"))
    assert back.attrs["ktgf_version"] and "ret" in back.attrs["models"]
    np.testing.assert_array_equal(back["theta_numeric"].values, ds["theta_numeric"].values)


@pytest.mark.contract
@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(phi=0.7, e=0.9, theta0=1.0, t=[0, 1]), "phi = 0.7"),
        (dict(phi=0.2, e=1.1, theta0=1.0, t=[0, 1]), "e = 1.1"),
        (dict(phi=0.2, e=0.9, theta0=-1.0, t=[0, 1]), "theta = -1"),
        (dict(phi=0.2, e=0.9, theta0=1.0, t=[-1.0, 1]), "time t = -1"),
        (dict(phi=0.2, e=0.9, theta0=1.0, t=[2.0, 1.0]), "non-decreasing"),
    ],
)
def test_integrate_cooling_rejects_bad_input(kwargs, match):
    with pytest.raises(InputError, match=match):
        integrate_cooling(get_model("visc-div"), d=1e-3, **kwargs)
