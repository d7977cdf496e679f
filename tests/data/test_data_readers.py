"""Readers of the shared data formats: the shared files read as their README says, bad files are one-line errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from helpers.calibration_synthetic import couette_header, with_header, write_uniform_shear
from ktgf.data import read_couette, read_data, read_uniform_shear
from ktgf.errors import InputError


@pytest.mark.regression
def test_shared_uniform_shear_file(data_dir):
    d = read_data(data_dir / "dem_uniform_shear.csv")
    assert d.kind == "uniform-shear"
    np.testing.assert_array_equal(d.phi, [0.3, 0.5])
    # the file's own numbers (README columns), not ours
    assert d.values["eta_over_eta0"][1] == 23.737 and d.sigmas["p_over_nT"][0] == 0.021376
    assert len(d.labels) == 6


@pytest.mark.regression
def test_friction_file_keeps_only_frictionless_rows(data_dir):
    d = read_uniform_shear(data_dir / "dem_uniform_shear_friction.csv")
    np.testing.assert_array_equal(d.phi, [0.5])
    np.testing.assert_array_equal(d.e, [0.7])
    assert d.values["p_over_nT"][0] == 15.091
    assert "2 frictional row(s)" in d.notes[0]


@pytest.mark.regression
def test_shared_couette_file_case_from_header(data_dir):
    d = read_couette(data_dir / "dem_couette_e0.9_phi0.50.csv")
    c = d.case
    # README: H = 20 between wall-sphere centres, slab |y| <= 9.5 -> continuum gap 19 d; U = 10; e = 0.9
    assert (c.e, c.mean_phi, c.gap, c.wall_speed) == (0.9, 0.5, 19.0, 10.0)
    assert (c.tau_wall, c.tau_wall_sigma, c.p_wall, c.p_wall_sigma) == (0.65518, 0.0035, 2.6588, 0.0091)
    assert c.rho_s == pytest.approx(6 / math.pi)
    # header: first occupied bins at y = -+9.25 with ux = -3.1147, 3.1598
    assert d.slip_y == 9.25
    assert d.slip_speed() == pytest.approx(0.5 * (3.11474 + 3.1598), abs=1e-4)
    from ktgf.data import read_table

    t = read_table(data_dir / "dem_couette_e0.9_phi0.50.csv").as_dict()
    sem = {y: s for y, s in zip(t["y"], t["ux_sem"])}
    assert d.slip_sigma() == pytest.approx(0.5 * math.hypot(sem[-9.25], sem[9.25]), rel=1e-12)
    assert sem[-9.25] == 0.00944467


@pytest.mark.contract
def test_modified_header_gives_another_case(data_dir, tmp_path):
    f = with_header(data_dir / "dem_couette_e0.9_phi0.50.csv", tmp_path / "c.csv", couette_header(e=0.8, phi=0.45, H=16.0, U=6.0))
    c = read_couette(f).case
    assert (c.e, c.mean_phi, c.gap, c.wall_speed) == (0.8, 0.45, 15.0, 6.0)


@pytest.mark.contract
@pytest.mark.parametrize("field", ["e", "mean_phi", "H", "U", "tau", "p_yy", "units"])
def test_couette_header_missing_field_is_one_line_error(data_dir, tmp_path, field):
    f = with_header(data_dir / "dem_couette_e0.9_phi0.50.csv", tmp_path / "c.csv", couette_header(drop=field))
    with pytest.raises(InputError) as exc:
        read_couette(f)
    msg = str(exc.value)
    assert "\n" not in msg and "c.csv" in msg
    assert (field in msg) if field != "units" else ("units" in msg)


def _shear(tmp_path, **kw):
    return write_uniform_shear(tmp_path / "s.csv", [0.3, 0.5], [0.9, 0.9], [1.0, 0.9], [3.0, 20.0], [4.0, 14.0], **kw)


@pytest.mark.contract
def test_uniform_shear_missing_column(tmp_path):
    f = _shear(tmp_path)
    f.write_text(f.read_text().replace("dp_over_nT", "dp_nT"))
    with pytest.raises(InputError, match=r"missing column\(s\) dp_over_nT"):
        read_data(f)


@pytest.mark.contract
def test_uniform_shear_nan(tmp_path):
    f = _shear(tmp_path)
    lines = f.read_text().splitlines()
    cells = lines[-1].split(",")
    cells[4] = "nan"
    f.write_text("\n".join(lines[:-1] + [",".join(cells)]) + "\n")
    with pytest.raises(InputError, match=r"column eta_over_eta0 holds NaN .* data row 2"):
        read_data(f)


@pytest.mark.contract
def test_uniform_shear_units_mismatch(tmp_path):
    f = _shear(tmp_path, header="# units d = 1 mm, m = 1 g; shear rate gdot = 1\n")
    with pytest.raises(InputError, match="do not match the shared format"):
        read_data(f)
    g = _shear(tmp_path, header="# units d = m = 1; shear rate gdot = 2\n")
    with pytest.raises(InputError, match="gdot = 1"):
        read_data(g)


@pytest.mark.contract
def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        read_data(tmp_path / "nope.csv")
