"""Slow: ``ktgf dem shear`` at N = 864 (and a Couette cell) against the shared DEM files (independent LAMMPS runs,
shared/data/README.md), within 2 σ (combined standard errors) + 3 %.

Protocols as in the README: frictionless, two seeds, strain 2–6; frictional, five seeds, strain 2–10.
"""

from __future__ import annotations

import math

import pytest
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.data import read_friction_shear, read_table
from ktgf.dem.lammps import lammps_available

_NO_LAMMPS = lammps_available()
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(_NO_LAMMPS is not None, reason=f"LAMMPS not usable: {_NO_LAMMPS}"), pytest.mark.dem]
runner = CliRunner()


def _agree(mine: dict, ref: dict, names: tuple[str, ...]) -> list[str]:
    bad = []
    for k in names:
        sigma = math.hypot(mine["d" + k], ref["d" + k])
        if abs(mine[k] - ref[k]) > 2 * sigma + 0.03 * abs(ref[k]):
            bad.append(f"{k}: ktgf {mine[k]:.5g} ± {mine['d' + k]:.2g}, shared {ref[k]:.5g} ± {ref['d' + k]:.2g}")
    return bad


def test_frictionless_phi05_e09(tmp_path, data_dir):
    out = tmp_path / "s.csv"
    r = runner.invoke(app, ["dem", "shear", "--phi", "0.5", "--e", "0.9", "--seeds", "2", "--strain", "6", "--skip", "2",
                            "--columns", "smooth", "--run-dir", str(tmp_path / "runs"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    mine = read_table(out).records()[0]  # the frictionless columns (no mu)
    ref = next(x for x in read_table(data_dir / "dem_uniform_shear.csv").records() if x["phi"] == 0.5)
    assert not _agree(mine, ref, ("T", "eta_over_eta0", "p_over_nT"))


def test_frictional_mu05_phi05_e07(tmp_path, data_dir):
    out = tmp_path / "f.csv"
    r = runner.invoke(app, ["dem", "shear", "--phi", "0.5", "--e", "0.7", "--mu", "0.5", "--seeds", "5", "--strain", "10",
                            "--run-dir", str(tmp_path / "runs"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    mine = read_friction_shear(out)[0]
    ref = next(x for x in read_friction_shear(data_dir / "dem_uniform_shear_friction.csv") if (x["mu"], x["phi"]) == (0.5, 0.5))
    assert not _agree(mine, ref, ("T", "Trot_over_T", "p_star", "tau_over_p", "p_over_nT", "eta_over_eta0"))


@pytest.mark.slow(minutes=4.7)
def test_couette_wall_stresses(tmp_path, data_dir):
    # a shorter protocol than the shared file's (30 + 20 strain units, ~5 CPU minutes): the wall stresses
    # are converged by then (measured: within 1.4 % of the shared file), the dense core's profiles are not (docs/dem.md)
    from ktgf.data import read_couette

    out = tmp_path / "c.csv"
    r = runner.invoke(app, ["dem", "couette", "--strain", "50", "--skip", "30", "--run-dir", str(tmp_path / "runs"),
                            "--out", str(out)])
    assert r.exit_code == 0, r.output
    mine, ref = read_couette(out).case, read_couette(data_dir / "dem_couette_e0.9_phi0.50.csv").case
    for a, da, b, db in ((mine.tau_wall, mine.tau_wall_sigma, ref.tau_wall, ref.tau_wall_sigma),
                         (mine.p_wall, mine.p_wall_sigma, ref.p_wall, ref.p_wall_sigma)):
        assert abs(a - b) <= 2 * math.hypot(da, db) + 0.03 * b
