"""``ktgf dem couette``: a tiny cell (soft contacts, coarse step: fast) written in the format of dem_couette_e0.9_phi0.50.csv and read back by
``ktgf.data.read_couette``.

Oracles: sphere volume (π/6) and its halves for the slab intersection; the solid volume of all flowing
spheres (N π/6) recovered from the φ profile; the wall layer's solid fraction, exact and as printed in the shared file.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from typer.testing import CliRunner

from ktgf.data import read_couette
from ktgf.cli import app
from ktgf.dem.couette import slab_volume
from ktgf.dem.lammps import lammps_available

_NO_LAMMPS = lammps_available()
runner = CliRunner()


@pytest.mark.analytic
def test_slab_volume_of_a_sphere():
    assert slab_volume(np.array(0.0), -1, 1) == pytest.approx(math.pi / 6)
    assert slab_volume(np.array(0.0), 0, 1) == pytest.approx(math.pi / 12)
    assert slab_volume(np.array(3.0), -1, 1) == 0.0
    # a cap of height h = 0.25 of a sphere of radius 1/2: π h² (3r − h)/3
    assert slab_volume(np.array(0.0), 0.25, 1) == pytest.approx(math.pi * 0.25**2 * (1.5 - 0.25) / 3)


@pytest.mark.skipif(_NO_LAMMPS is not None, reason=f"LAMMPS not usable: {_NO_LAMMPS}")
@pytest.mark.contract
def test_tiny_cell_reads_back(tmp_path, monkeypatch, data_dir):
    monkeypatch.setenv("KTGF_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "c.csv"
    r = runner.invoke(app, ["dem", "couette", "--phi", "0.45", "--height", "8", "--wall-spheres-x", "6", "--wall-rows-z", "6",
                            "--strain", "6", "--skip", "2", "--contact-time", "0.01", "--steps-per-contact", "25", "--run-dir", str(tmp_path / "runs"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    d = read_couette(out)
    assert (d.case.e, d.case.mean_phi, d.case.gap, d.case.wall_speed) == (0.9, 0.45, 7.0, 10.0)
    assert d.case.tau_wall > 0 and d.case.p_wall > 0
    assert d.u[0] < 0 < d.u[-1] and 0 < d.slip_speed() < 5
    names, table = _table(out)
    shared_names, shared = _table(data_dir / "dem_couette_e0.9_phi0.50.csv")
    assert names == shared_names
    area = 6 * 6 * math.sqrt(3) / 2
    n = round(0.45 * area * 7 / (math.pi / 6))
    assert table["phi"].sum() * 0.5 * area == pytest.approx(n * math.pi / 6, rel=1e-6)
    # each half of a hexagonal layer of touching spheres in its 0.5-thick bin: (π/12)/(√3/4) = π/(3√3)
    assert table["phi_wall"].max() == pytest.approx(math.pi / (3 * math.sqrt(3)), rel=1e-5)
    assert table["phi_wall"].max() == pytest.approx(shared["phi_wall"].max(), rel=1e-3)  # the shared file's histogram value


def _table(path):
    lines = [ln for ln in path.read_text().splitlines() if ln.strip() and not ln.startswith("#")]
    names = lines[0].split(",")
    values = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    return names, {k: values[:, i] for i, k in enumerate(names)}
