"""Checkpoints are checked on load and output folders belong to one run (issue 11).

Damaged files (truncated, bit-flipped, random, key-less, older format) and files that load
but do not fit the run (index, time, shape, dtype, history, config) are refused by
``ktgf run --resume`` with one line naming what does not fit and exit code 2; harmless config
changes are accepted.  A second run into a locked folder, a fresh run over another run's
files and ``--overwrite`` are exercised on the CLI.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from helpers.tiny_case import tiny_case
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.solver.io import load_checkpoint, save_checkpoint
from ktgf.solver.outdir import LOCK

pytestmark = pytest.mark.contract


def case_text(end: float = 4.0, vtk_every: int = 2) -> str:
    return tiny_case(end=end, output=f"checkpoint_every = 1\nvtk_every = {vtk_every}")


def _case(tmp: Path, name: str = "case.toml", end: float = 4.0, vtk_every: int = 2, extra: str = "") -> Path:
    p = tmp / name
    p.write_text(case_text(end, vtk_every) + extra)
    return p


def _run(*args: str) -> tuple[int, str]:
    res = CliRunner().invoke(app, ["run", *map(str, args), "--no-progress"])
    assert res.exception is None or isinstance(res.exception, SystemExit), repr(res.exception)
    return res.exit_code, res.stderr


def _one_line_error(code: int, err: str, *words: str) -> None:
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), err
    for w in words:
        assert w in lines[0], lines[0]


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    """A finished run: its folder (with checkpoint.npz after the last output)."""
    tmp = tmp_path_factory.mktemp("done")
    code, err = _run(_case(tmp), "-o", tmp / "run")
    assert code == 0, err
    return tmp / "run"


@pytest.fixture
def ck(finished: Path, tmp_path: Path) -> Path:
    p = tmp_path / "ck.npz"
    p.write_bytes((finished / "checkpoint.npz").read_bytes())
    return p


def _resume(tmp: Path, ck: Path, **case) -> tuple[int, str]:
    return _run(_case(tmp, **case), "-o", tmp / "out", "--resume", ck)


# -- damaged files --------------------------------------------------------------------------------

def _truncate(p: Path) -> None:
    p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])


def _flip(p: Path) -> None:
    raw = bytearray(p.read_bytes())
    raw[len(raw) // 3] ^= 0x10
    p.write_bytes(bytes(raw))


def _random(p: Path) -> None:
    p.write_bytes(np.random.default_rng(0).bytes(5000))


def _keyless(p: Path) -> None:
    with open(p, "wb") as f:
        np.savez(f, U=np.zeros((5, 8)))


def _old_format(p: Path) -> None:  # the layout before format versions (no format, no hash)
    z = dict(np.load(p))
    with open(p, "wb") as f:
        np.savez(f, **{k: v for k, v in z.items() if k not in ("format", "hash")})


def _empty(p: Path) -> None:
    p.write_bytes(b"")


@pytest.mark.parametrize("damage, words", [
    (_truncate, ["unreadable"]), (_flip, ["checkpoint"]), (_random, ["unreadable"]),
    (_keyless, ["lacks the field(s)", "hash"]), (_old_format, ["no format version"]), (_empty, ["unreadable"]),
])
def test_damaged_checkpoints_are_refused_in_one_line(damage, words, ck: Path, tmp_path: Path) -> None:
    damage(ck)
    _one_line_error(*_resume(tmp_path, ck), str(ck), *words)


def test_bit_flip_anywhere_is_refused_or_harmless(ck: Path, tmp_path: Path) -> None:
    """200 single-bit flips spread over the file: each is refused (zip CRC, header or SHA-256) or
    hit bytes that carry no content (zip timestamps, header padding) — never different content."""
    from ktgf.errors import InputError

    good = load_checkpoint(ck)
    raw = ck.read_bytes()
    refused = 0
    for pos in np.linspace(0, len(raw) - 1, 200).astype(int):
        bad = bytearray(raw)
        bad[pos] ^= 1 << (pos % 8)
        ck.write_bytes(bytes(bad))
        try:
            c = load_checkpoint(ck)
        except InputError as exc:
            assert "\n" not in str(exc)
            refused += 1
            continue
        assert np.array_equal(c["U"], good["U"]) and c["history"] == good["history"] and c["config"] == good["config"]
        assert (c["t"], c["steps"], c["output_index"]) == (good["t"], good["steps"], good["output_index"])
    assert refused >= 180


def test_missing_and_directory_checkpoints(tmp_path: Path) -> None:
    _one_line_error(*_resume(tmp_path, tmp_path / "nope.npz"), "does not exist")
    (tmp_path / "dir.npz").mkdir()
    _one_line_error(*_resume(tmp_path, tmp_path / "dir.npz"), "directory")


# -- files that load but do not fit ---------------------------------------------------------------

def _resave(p: Path, **change) -> None:
    c = load_checkpoint(p)
    c.update(change)
    save_checkpoint(p, c["U"], c["t"], c["steps"], c["output_index"], c["history"], c["config"])


@pytest.mark.parametrize("change, words", [
    ({"output_index": -5}, ["output_index = -5", "valid 0 <= output_index <= 5"]),
    ({"output_index": 10**6}, ["output_index = 1000000"]),
    ({"output_index": 3}, ["history", "rows", "output_index = 3"]),
    ({"t": float("nan")}, ["field t = nan"]),
    ({"t": 1e9}, ["field t = 1e+09", "end time"]),
    ({"t": 0.05}, ["history.time", "t = 0.05"]),
    ({"steps": -1}, ["steps = -1"]),
    ({"U": np.zeros((5, 16))}, ["shape (5, 16)", "(5, 8)"]),
    ({"U": np.zeros((5, 8), dtype=np.float32)}, ["dtype float32"]),
    ({"U": np.full((5, 8), np.nan)}, ["NaN"]),
    ({"history": {"time": [0.0]}}, ["history has the columns"]),
    ({"config": "not json"}, ["config is not JSON"]),
])
def test_checkpoints_that_do_not_fit_are_refused(change: dict, words: list[str], ck: Path, tmp_path: Path) -> None:
    _resave(ck, **change)
    _one_line_error(*_resume(tmp_path, ck), *words)


def test_history_times_must_be_the_output_times(ck: Path, tmp_path: Path) -> None:
    c = load_checkpoint(ck)
    hist = {k: list(v) for k, v in c["history"].items()}
    hist["time"][2] *= 1.0000001
    _resave(ck, history=hist)
    _one_line_error(*_resume(tmp_path, ck), "history.time")


def test_another_config_is_refused_naming_the_field(ck: Path, tmp_path: Path) -> None:
    code, err = _run(_case(tmp_path, extra="[numerics]\ncfl = 0.3\n"), "-o", tmp_path / "o", "--resume", ck)
    _one_line_error(code, err, "field numerics.cfl = 0.4 in the checkpoint, 0.3 now")
    text = case_text(4.0, 2).replace("restitution = 0.8", "restitution = 0.9")
    (tmp_path / "e.toml").write_text(text)
    _one_line_error(*_run(tmp_path / "e.toml", "-o", tmp_path / "o", "--resume", ck), "model.restitution")


def test_harmless_changes_are_accepted_on_resume(finished: Path, ck: Path, tmp_path: Path) -> None:
    # another folder and VTK cadence, the same end: nothing left to do, same time series
    code, err = _resume(tmp_path, ck, vtk_every=1)
    assert code == 0, err
    same, ref = xr.load_dataset(tmp_path / "out" / "cooling.nc"), xr.load_dataset(finished / "cooling.nc")
    assert np.array_equal(same.theta_mean.values, ref.theta_mean.values)
    # a later end time: the run goes on from t_end along the new output schedule
    code, err = _run(_case(tmp_path, "later.toml", end=6.0), "-o", tmp_path / "later", "--resume", ck)
    assert code == 0, err
    ds = xr.load_dataset(tmp_path / "later" / "cooling.nc")
    assert np.array_equal(ds.theta_mean.values[:5], ref.theta_mean.values)
    assert ds.sizes["time"] == 7 and np.all(np.diff(ds.time.values) > 0)
    assert float(ds.tau[-1]) == pytest.approx(6.0, rel=1e-12)


# -- the output folder belongs to one run ---------------------------------------------------------

def _lock(directory: Path, pid: int, host: str | None = None) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / LOCK).write_text(
        f'{{"pid": {pid}, "host": "{host or socket.gethostname()}", "started": "2026-01-01T00:00:00+00:00"}}')


def test_a_second_run_into_a_locked_folder_stops_naming_the_other(tmp_path: Path) -> None:
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        _lock(tmp_path / "run", other.pid)
        _one_line_error(*_run(_case(tmp_path), "-o", tmp_path / "run"), "in use by another run",
                        f"pid {other.pid}", socket.gethostname(), "2026-01-01")
        assert not (tmp_path / "run" / "checkpoint.npz").exists()
    finally:
        other.kill()
        other.wait()
    # now its process is gone: the stale lock is taken over, and released at the end
    code, err = _run(_case(tmp_path), "-o", tmp_path / "run")
    assert code == 0, err
    assert not (tmp_path / "run" / LOCK).exists()


def test_a_lock_from_another_host_is_respected(tmp_path: Path) -> None:
    _lock(tmp_path / "run", os.getpid() + 10**6, host="elsewhere.example")
    _one_line_error(*_run(_case(tmp_path), "-o", tmp_path / "run"), "elsewhere.example")


def test_fresh_run_over_a_finished_one_refuses_and_overwrite_clears_it(tmp_path: Path) -> None:
    run = tmp_path / "run"
    assert _run(_case(tmp_path, vtk_every=1), "-o", run)[0] == 0
    assert len(list(run.glob("fields_*.vti"))) == 5
    _one_line_error(*_run(_case(tmp_path), "-o", run), "already holds", "--overwrite")
    _one_line_error(*_run(_case(tmp_path), "-o", run, "--overwrite", "--resume", run / "checkpoint.npz"), "exclude")
    code, err = _run(_case(tmp_path, vtk_every=0), "-o", run, "--overwrite")
    assert code == 0, err
    assert sorted(p.name for p in run.glob("fields_*.vti")) == ["fields_00000.vti", "fields_00004.vti"]
    assert sorted(p.name for p in run.iterdir()) == ["checkpoint.npz", "cooling.nc", "fields_00000.vti", "fields_00004.vti"]


def test_checkpoint_roundtrip_is_exact_and_written_atomically(tmp_path: Path) -> None:
    U = np.random.default_rng(1).normal(size=(5, 4, 4))
    hist = {"time": [0.0, 0.1], "x": [[1.0, 2.0], [3.0, float(np.nextafter(3.0, 4.0))]]}
    save_checkpoint(tmp_path / "c.npz", U, 0.1, 7, 2, hist, '{"a": 1}')
    c = load_checkpoint(tmp_path / "c.npz")
    assert np.array_equal(c["U"], U) and c["t"] == 0.1 and c["steps"] == 7 and c["history"] == hist
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.npz"]  # no temporary left behind
