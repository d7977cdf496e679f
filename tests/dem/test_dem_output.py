"""``ktgf dem shear``: tiny LAMMPS runs written in the shared formats and read back by the project's readers;
bad input (one line, exit 2) and resumed sweeps."""

from __future__ import annotations

import stat
import textwrap

import pytest
from typer.testing import CliRunner

from ktgf.data import read_uniform_shear
from ktgf.cli import app
from ktgf.data import read_friction_shear
from ktgf.dem.lammps import lammps_available

pytestmark = pytest.mark.contract

_NO_LAMMPS = lammps_available()
needs_lammps = pytest.mark.skipif(_NO_LAMMPS is not None, reason=f"LAMMPS not usable: {_NO_LAMMPS}")
runner = CliRunner()
TINY = ["--particles", "108", "--seeds", "2", "--strain", "0.4", "--skip", "0.2"]


@pytest.fixture(autouse=True)
def _private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("KTGF_CACHE_DIR", str(tmp_path / "cache"))


def _shear(*args):
    return runner.invoke(app, ["dem", "shear", *args])


@needs_lammps
def test_frictional_file_reads_back(tmp_path):
    out = tmp_path / "f.csv"
    r = _shear("--phi", "0.3", "--e", "0.7", "--mu", "0.5", *TINY, "--run-dir", str(tmp_path / "runs"), "--out", str(out))
    assert r.exit_code == 0, r.output
    rows = read_friction_shear(out)
    assert len(rows) == 1
    row = rows[0]
    assert (row["mu"], row["phi"], row["e"], row["N"], row["seeds"]) == (0.5, 0.3, 0.7, 108, 2)
    assert row["T"] > 0 and row["dT"] > 0 and row["p_star"] > 0
    assert 0 < row["Trot_over_T"] < 2  # frictional spheres spin
    assert 0 < row["tau_over_p"] < 1 and row["tau_star"] > 0  # shear stress opposes the shear
    text = out.read_text()
    assert "LAMMPS" in text and "kn=" in text and "seeds 1,2" in text and "Q6" in text
    assert (tmp_path / "runs" / "mu0.5_phi0.3_e0.7_N108_fc0.01" / "seed2" / "log.lammps").is_file()
    with pytest.raises(Exception, match="no frictionless"):
        read_uniform_shear(out)  # the frictionless reader refuses frictional rows, as with the shared file


@needs_lammps
def test_frictionless_files_read_back_and_resume(tmp_path, monkeypatch):
    runs = tmp_path / "runs"
    for columns in ("friction", "smooth"):
        out = tmp_path / f"{columns}.csv"
        r = _shear("--phi", "0.3", "--e", "0.9", *TINY, "--run-dir", str(runs), "--out", str(out), "--columns", columns)
        assert r.exit_code == 0, r.output
        data = read_uniform_shear(out)
        assert list(data.phi) == [0.3] and list(data.e) == [0.9]
        assert data.values["T"][0] > 0 and data.sigmas["T"][0] > 0
        if columns == "friction":
            first = out.read_text()
        else:  # the second command found the runs of the first: nothing rerun
            from ktgf.dem.lammps import Lammps

            def no_run(*a, **k):
                raise AssertionError("a finished run was rerun")

            monkeypatch.setattr(Lammps, "run", no_run)
            r = _shear("--phi", "0.3", "--e", "0.9", *TINY, "--run-dir", str(runs), "--out", str(tmp_path / "again.csv"))
            assert r.exit_code == 0, r.output
            assert (tmp_path / "again.csv").read_text() == first


@pytest.mark.parametrize("args, words", [
    (["--phi", "0.64", "--e", "0.9"], ["phi = 0.64", "jamming", "would jam"]),
    (["--phi", "0.6", "--e", "0.7", "--mu", "0.5"], ["phi = 0.6", "jamming", "0.594"]),
    (["--phi", "0.5", "--e", "1.2"], ["e = 1.2", "0 < e"]),
    (["--phi", "0.5", "--e", "0"], ["e = 0", "0 < e"]),
    (["--phi", "0.5", "--e", "0.9", "--mu", "-0.1"], ["mu = -0.1", "mu >= 0"]),
    (["--phi", "0.5", "--e", "0.9", "--particles", "50"], ["N = 50", "N >= 100"]),
])
def test_bad_input_is_one_line_exit_2(args, words, tmp_path):
    r = _shear(*args, "--run-dir", str(tmp_path))
    assert r.exit_code == 2
    msg = r.output.strip()
    assert msg.count("\n") == 0
    for w in words:
        assert w in msg


def _fake_lmp(tmp_path, banner_styles: str, fail: bool):
    exe = tmp_path / "fake_lmp"
    exe.write_text(textwrap.dedent(f"""\
        #!/bin/sh
        if [ "$1" = "-h" ]; then
          echo "Large-scale Atomic/Molecular Massively Parallel Simulator - 1 Jan 2099"
          echo "{banner_styles}"
          exit 0
        fi
        log=log.lammps
        while [ $# -gt 0 ]; do [ "$1" = "-log" ] && log=$2; shift; done
        echo "LAMMPS (1 Jan 2099)" > $log
        echo "ERROR: Fake failure on purpose (src/fake.cpp:1)" >> $log
        exit {1 if fail else 0}
        """))
    exe.chmod(exe.stat().st_mode | stat.S_IEXEC)
    return exe


def test_no_lammps_says_how_to_install(tmp_path, monkeypatch):
    monkeypatch.setenv("KTGF_LAMMPS", str(tmp_path / "nowhere" / "lmp"))
    r = _shear("--phi", "0.3", "--e", "0.9", "--run-dir", str(tmp_path))
    assert r.exit_code == 2
    assert 'pip install "ktgf[dem]"' in r.output and r.output.strip().count("\n") == 0


def test_lammps_without_granular_is_refused(tmp_path, monkeypatch):
    monkeypatch.setenv("KTGF_LAMMPS", str(_fake_lmp(tmp_path, "lj/cut  eam", fail=False)))
    r = _shear("--phi", "0.3", "--e", "0.9", "--run-dir", str(tmp_path))
    assert r.exit_code == 2
    assert "GRANULAR" in r.output and r.output.strip().count("\n") == 0


def test_failed_lammps_run_shows_its_log(tmp_path, monkeypatch):
    monkeypatch.setenv("KTGF_LAMMPS", str(_fake_lmp(tmp_path, "gran/hooke/history gran/hooke", fail=True)))
    r = _shear("--phi", "0.3", "--e", "0.9", "--run-dir", str(tmp_path / "runs"))
    assert r.exit_code == 2
    assert "Fake failure on purpose" in r.output and "kept in" in r.output
    assert r.output.strip().count("\n") == 0


def test_stiffness_change_is_relative_to_the_base_run():
    from ktgf.dem.shear import ShearState
    from ktgf.dem.sweep import stiffness_change

    keys = ("T", "p_star", "tau_over_p", "p_over_nT", "eta_over_eta0")
    base = ShearState(0.0, 0.5, 0.9, 864, [1], dict.fromkeys(keys, 2.0), dict.fromkeys(keys, 0.03))
    stiffer = ShearState(0.0, 0.5, 0.9, 864, [1], dict.fromkeys(keys, 2.1), dict.fromkeys(keys, 0.04))
    change = stiffness_change(base, stiffer)
    assert change["T"][0] == pytest.approx(0.05)
    assert change["T"][1] == pytest.approx(0.1 / 0.05)
