"""Fault injection for ``ktgf run``: signals at chosen moments, crashes, resume bit for bit.

Each case runs ``ktgf run`` with ``KTGF_TEST_INTERRUPT`` placing a SIGINT (or a SIGKILL) at a
deterministic point of the run loop (ktgf.solver.interrupt.fault_hook), then resumes it and
compares the time series (cooling.nc, every variable and the step count), the .vti files and the
final state (checkpoint.npz) with an uninterrupted run, bit for bit.  The signal is real (the
process signals itself); most cases run the CLI in-process (typer's CliRunner, compiled code
cached), the crash and compile cases in a subprocess.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from helpers.tiny_case import tiny_case

from ktgf.solver.io import load_checkpoint
from ktgf.solver.outdir import LOCK

# 1D, 8 cells, one step per compiled chunk (many chunk boundaries), checkpoints every 2nd output
CASE = tiny_case(time="max_steps_per_call = 1", output='directory = "run"\ncheckpoint_every = 2\nvtk_every = 2')


pytestmark = pytest.mark.contract


def _cli(*args: str, fault: str | None = None, monkeypatch: pytest.MonkeyPatch) -> tuple[int, str]:
    """``ktgf ARGS`` in this process; (exit code, stderr)."""
    from typer.testing import CliRunner

    from ktgf.cli import app

    if fault:
        monkeypatch.setenv("KTGF_TEST_INTERRUPT", fault)
    else:
        monkeypatch.delenv("KTGF_TEST_INTERRUPT", raising=False)
    res = CliRunner().invoke(app, list(args))
    monkeypatch.delenv("KTGF_TEST_INTERRUPT", raising=False)
    assert res.exception is None or isinstance(res.exception, SystemExit), repr(res.exception)
    return res.exit_code, res.stderr


def _ktgf(*args: str, cwd: Path, fault: str | None = None, timeout: float = 300) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONFAULTHANDLER": "1"}
    env.pop("KTGF_TEST_INTERRUPT", None)
    if fault:
        env["KTGF_TEST_INTERRUPT"] = fault
    return subprocess.run([sys.executable, "-m", "ktgf", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=timeout, check=False)


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> Path:
    """An uninterrupted run (in a subprocess, like the interrupted ones)."""
    d = tmp_path_factory.mktemp("ref")
    (d / "case.toml").write_text(CASE)
    res = _ktgf("run", "case.toml", "--no-progress", cwd=d)
    assert res.returncode == 0, res.stderr
    return d / "run"


def _assert_same_run(run: Path, ref: Path) -> None:
    a, b = xr.load_dataset(run / "cooling.nc"), xr.load_dataset(ref / "cooling.nc")
    assert a.sizes == b.sizes and set(a.data_vars) == set(b.data_vars)
    assert np.array_equal(a.time.values, b.time.values)
    for name in b.data_vars:
        assert np.array_equal(a[name].values, b[name].values), name
    assert a.attrs["parameters"] == b.attrs["parameters"] and a.attrs["run_complete"] == 1
    ca, cb = load_checkpoint(run / "checkpoint.npz"), load_checkpoint(ref / "checkpoint.npz")
    assert np.array_equal(ca["U"], cb["U"]) and ca["t"] == cb["t"] and ca["steps"] == cb["steps"]
    assert ca["history"] == cb["history"]
    for vti in sorted(p.name for p in ref.glob("*.vti")):
        assert (run / vti).read_bytes() == (ref / vti).read_bytes(), vti
    assert not list(run.glob(".*tmp*")) and not (run / LOCK).exists()


def _check_interrupted_files(run: Path) -> None:
    """What an interrupted run leaves: a checkpoint whose history is the time series on disk."""
    ck = load_checkpoint(run / "checkpoint.npz")
    k = ck["output_index"]
    assert all(len(v) == k for v in ck["history"].values())
    if k:
        ds = xr.load_dataset(run / "cooling.nc")
        assert ds.sizes["time"] == k and ds.attrs["run_complete"] == 0
        assert np.array_equal(ds.time.values, ck["history"]["time"])
        assert np.array_equal(ds.theta_mean.values, ck["history"]["theta_mean"])


@pytest.mark.parametrize("fault", ["chunk:1", "chunk:3", "output:0", "output:1", "output:2", "checkpoint:2",
                                   "output:4", "checkpoint:4"])
def test_sigint_then_resume_is_bit_for_bit(fault: str, reference: Path, tmp_path: Path,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "case.toml").write_text(CASE)
    case, run = str(tmp_path / "case.toml"), tmp_path / "run"
    code, err = _cli("run", case, "-o", str(run), "--no-progress", fault=fault, monkeypatch=monkeypatch)
    assert code == 130, err
    assert "checkpoint written to" in err and "--resume" in err
    _check_interrupted_files(run)
    if load_checkpoint(run / "checkpoint.npz")["output_index"] < 5:
        # starting afresh over the unfinished run is refused in one line (nothing lost) ...
        code, again = _cli("run", case, "-o", str(run), "--no-progress", monkeypatch=monkeypatch)
        assert code == 2 and "unfinished run" in again and "--resume" in again and "--overwrite" in again
        assert len(again.strip().splitlines()) == 1
    # ... and resuming reproduces the uninterrupted run
    code, err = _cli("run", case, "-o", str(run), "--no-progress", "--resume", str(run / "checkpoint.npz"),
                     monkeypatch=monkeypatch)
    assert code == 0, err
    _assert_same_run(run, reference)


@pytest.mark.parametrize("fault", ["compile", "output:2"])
def test_sigint_in_a_subprocess_exits_130_cleanly(fault: str, reference: Path, tmp_path: Path) -> None:
    """The whole process: no traceback, no 'Exception ignored', no crash on exit (the compile case
    segfaulted before), exit code 130; the resume is bit for bit."""
    (tmp_path / "case.toml").write_text(CASE)
    res = _ktgf("run", "case.toml", "--no-progress", cwd=tmp_path, fault=fault)
    assert res.returncode == 130, res.stderr
    assert "Traceback" not in res.stderr and "Fatal Python error" not in res.stderr and "Exception ignored" not in res.stderr
    assert "checkpoint written to" in res.stderr
    run = tmp_path / "run"
    _check_interrupted_files(run)
    from ktgf.solver.config import load_config
    from ktgf.solver.run import Simulation

    Simulation(load_config(tmp_path / "case.toml"), run).run(progress=False, resume=run / "checkpoint.npz")
    _assert_same_run(run, reference)


def test_kill_9_while_writing_then_resume_is_bit_for_bit(reference: Path, tmp_path: Path) -> None:
    """A crash (SIGKILL) while output 3 is written: the last checkpoint (output 2) and the stale
    lock are left; the resume takes the lock over and reproduces the run."""
    (tmp_path / "case.toml").write_text(CASE)
    res = _ktgf("run", "case.toml", "--no-progress", cwd=tmp_path, fault="output:3:KILL")
    assert res.returncode == -signal.SIGKILL
    run = tmp_path / "run"
    assert (run / LOCK).exists()
    _check_interrupted_files(run)
    assert load_checkpoint(run / "checkpoint.npz")["output_index"] == 3
    from ktgf.solver.config import load_config
    from ktgf.solver.run import Simulation

    Simulation(load_config(tmp_path / "case.toml"), run).run(progress=False, resume=run / "checkpoint.npz")
    _assert_same_run(run, reference)


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0])
def test_real_ctrl_c_at_any_moment(delay: float, reference: Path, tmp_path: Path) -> None:
    """SIGINT from outside at a wall-clock moment (imports, compile, stepping or writing)."""
    (tmp_path / "case.toml").write_text(CASE)
    env = {k: v for k, v in os.environ.items() if k != "KTGF_TEST_INTERRUPT"}
    proc = subprocess.Popen([sys.executable, "-m", "ktgf", "run", "case.toml", "--no-progress"], cwd=tmp_path,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=300)
    run = tmp_path / "run"
    if proc.returncode != 130:  # the run had finished: only a signal during interpreter shutdown kills it
        assert proc.returncode in (0, -signal.SIGINT), err
        assert xr.load_dataset(run / "cooling.nc").attrs["run_complete"] == 1
    assert "Traceback" not in err and "Fatal Python error" not in err and "Exception ignored" not in err
    if (run / "checkpoint.npz").exists():
        res = _ktgf("run", "case.toml", "--no-progress", "--resume", "run/checkpoint.npz", cwd=tmp_path)
        assert res.returncode == 0, res.stderr
        _assert_same_run(run, reference)


@pytest.mark.slow
def test_second_ctrl_c_quits_at_once_and_leaves_a_resumable_folder(reference: Path, tmp_path: Path) -> None:
    (tmp_path / "case.toml").write_text(CASE)
    env = {**os.environ, "KTGF_TEST_INTERRUPT": "compile"}
    proc = subprocess.Popen([sys.executable, "-m", "ktgf", "run", "case.toml", "--no-progress"], cwd=tmp_path,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    seen = []
    for line in proc.stderr:  # the hook's SIGINT lands during the first compile; then send the second
        seen.append(line)
        if "Interrupt received" in line:
            proc.send_signal(signal.SIGINT)
            break
    _, rest = proc.communicate(timeout=300)
    err = "".join(seen) + rest
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "Fatal Python error" not in err
    res = _ktgf("run", "case.toml", "--no-progress", cwd=tmp_path, fault=None)
    if (tmp_path / "run" / "checkpoint.npz").exists():
        assert res.returncode == 2
        res = _ktgf("run", "case.toml", "--no-progress", "--resume", "run/checkpoint.npz", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    _assert_same_run(tmp_path / "run", reference)
