"""``ktgf dem cooling``: a tiny homogeneous-cooling run (soft contacts, coarse step: fast) in the format of dem_hcs_cooling.csv.

Oracle: Haff's law with the Enskog cooling rate, which a dilute gas (φ = 0.05) follows to a few per cent
(the shared file: ratio_early 0.97–0.99 at φ ≤ 0.1).
"""

from __future__ import annotations

import csv
import math

import pytest
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.dem.cooling import enskog_haff_rate, sonine_a2
from ktgf.dem.lammps import lammps_available

_NO_LAMMPS = lammps_available()
runner = CliRunner()


@pytest.mark.published
def test_sonine_a2_values():
    # van Noije & Ernst (1998), Eq. (29): a2 vanishes at e = 1 and changes sign at e = 1/√2
    assert sonine_a2(1.0) == 0.0
    assert sonine_a2(1 / math.sqrt(2)) == pytest.approx(0.0, abs=1e-15)
    assert sonine_a2(0.9) < 0 < sonine_a2(0.5)


@pytest.mark.skipif(_NO_LAMMPS is not None, reason=f"LAMMPS not usable: {_NO_LAMMPS}")
@pytest.mark.analytic
def test_dilute_cooling_follows_haff(tmp_path, monkeypatch, data_dir):
    monkeypatch.setenv("KTGF_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "hcs.csv"
    r = runner.invoke(app, ["dem", "cooling", "--phi", "0.05", "--e", "0.8", "--particles", "256", "--seeds", "2", "--contact-fraction", "0.05", "--steps-per-contact", "20",
                            "--run-dir", str(tmp_path / "runs"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    lines = out.read_text().splitlines()
    shared = (data_dir / "dem_hcs_cooling.csv").read_text().splitlines()
    title = next(ln for ln in lines if not ln.startswith("#"))
    assert title == next(ln for ln in shared if not ln.startswith("#"))
    row = next(csv.DictReader([ln for ln in lines if not ln.startswith("#")]))
    assert float(row["A_main"]) == pytest.approx(float(row["ratio_main"]) * enskog_haff_rate(0.05, 0.8), rel=1e-4)
    assert 0.9 < float(row["ratio_early"]) < 1.1
    # dilute p/(nT) = 1 + 2(1 + e) φ χ (Enskog) ≈ 1.19 at φ = 0.05, e = 0.8
    assert float(row["p_over_nT"]) == pytest.approx(1 + 2 * 1.8 * 0.05 * (1 - 0.025) / 0.95**3, rel=0.03)
