"""Every netCDF file of the report: netCDF4 (the chosen engine), CF-1.8, UDUNITS-valid units on every number."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
import xarray as xr

from helpers.cf_units import valid_units
from ktgf.io import CONVENTIONS, NETCDF_ENGINE, open_netcdf, write_netcdf


pytestmark = pytest.mark.contract


@pytest.mark.parametrize("units, ok", [("1", True), ("m2 s-2", True), ("m/s", True), ("W/m2", True), ("1/s", True),
                                       ("Pa", True), ("d", False), ("s-1 d", False), ("", False), ("reduced", False)])
def test_unit_checker_itself(units: str, ok: bool) -> None:
    assert valid_units(units) is ok


def test_writer_uses_netcdf4_and_cf(tmp_path) -> None:
    ds = xr.Dataset({"a": ("x", np.arange(3.0), {"units": "m"})}, attrs={"title": "t"})
    path = write_netcdf(ds, tmp_path / "a.nc")
    assert h5py.is_hdf5(path)  # netCDF4 is HDF5; netCDF3 (the SciPy fallback) is not
    with open_netcdf(path) as back:
        assert back.attrs["Conventions"] == CONVENTIONS == "CF-1.8" and back.attrs["title"] == "t"
    assert "Conventions" not in ds.attrs  # the caller's Dataset is not modified


def test_every_report_netcdf_is_cf(quick_report) -> None:
    files = sorted((quick_report.out / "data").rglob("*.nc"))
    assert files, "the report wrote no netCDF file"
    bad: list[str] = []
    for f in files:
        assert h5py.is_hdf5(f), f"{f} is not netCDF4/HDF5"
        with xr.open_dataset(f, engine=NETCDF_ENGINE) as ds:
            assert ds.attrs.get("Conventions") == "CF-1.8", f
            for name, var in {**ds.data_vars, **ds.coords}.items():
                units = var.attrs.get("units")
                if var.dtype.kind in "fiuc" and var.ndim > 0 and name not in ("branch",) and units is None:
                    bad.append(f"{f.name}:{name} has no units")
                elif units is not None and not valid_units(units):
                    bad.append(f"{f.name}:{name} units {units!r}")
    assert not bad, "; ".join(bad)
