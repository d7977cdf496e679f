"""Chains of runs: ``initial.from_run = "earlier.toml"`` runs that configuration first (:mod:`ktgf.solver.chain`).

Oracles: the earlier stage's own run (the chain's result must be what running the stages one by one gives,
bit for bit, also after a Ctrl-C in the earlier stage), the step counts the runs report, and the files'
modification times (a complete earlier stage is not run again).
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np
import pytest
from helpers.couette_case import couette_case
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.errors import InputError
from ktgf.solver.chain import run_chain
from ktgf.solver.config import load_config
from ktgf.solver.interrupt import Interrupted
from ktgf.solver.io import load_checkpoint
from ktgf.solver.run import Simulation

pytestmark = pytest.mark.contract


def _write_chain(folder: Path) -> Path:
    """Two stages in ``folder``: a 2D Couette cell of 8 × 4 cells from rest, then the same cell twice as wide
    along its periodic axis started from the first's result; returns the second's config."""
    first = couette_case([8, 4], 1.0, lengths="[10.0, 4.0]") + 'directory = "a_run"\n'
    second = (couette_case([8, 8], 1.0, lengths="[10.0, 8.0]") + 'directory = "b_run"\n').replace(
        'temperature = 1e-3\n', 'from_run = "a.toml"\n')
    (folder / "a.toml").write_text(first)
    (folder / "b.toml").write_text(second)
    return folder / "b.toml"


def _by_hand(folder: Path, monkeypatch: pytest.MonkeyPatch) -> np.ndarray:
    """The last state of the two stages run one by one, each by :class:`Simulation`."""
    monkeypatch.chdir(folder)
    Simulation(load_config(folder / "a.toml")).run(progress=False)
    text = (folder / "b.toml").read_text().replace('from_run = "a.toml"', 'from_run = "a_run"')
    (folder / "b_hand.toml").write_text(text)
    sim = Simulation(load_config(folder / "b_hand.toml"))
    sim.run(progress=False)
    return np.asarray(sim.state)


@pytest.fixture(scope="module")
def by_hand(tmp_path_factory: pytest.TempPathFactory) -> np.ndarray:
    folder = tmp_path_factory.mktemp("hand")
    _write_chain(folder)
    with pytest.MonkeyPatch.context() as mp:
        return _by_hand(folder, mp)


def test_ktgf_run_of_the_last_config_runs_the_chain_and_reuses_a_complete_stage(
        by_hand: np.ndarray, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    last = _write_chain(tmp_path)
    monkeypatch.chdir(tmp_path)
    res = CliRunner().invoke(app, ["run", str(last), "--no-progress"])
    assert res.exit_code == 0, res.output
    assert np.array_equal(load_checkpoint(tmp_path / "b_run" / "checkpoint.npz")["U"], by_hand)
    ver = json.loads((tmp_path / "b_run" / "verification.json").read_text())
    first = json.loads((tmp_path / "a_run" / "verification.json").read_text())
    assert ver["run"]["sequence"]["steps"] == first["run"]["step_count"] + ver["run"]["step_count"]
    stamp = (tmp_path / "a_run" / "checkpoint.npz").stat().st_mtime_ns
    with caplog.at_level(logging.INFO, logger="ktgf"):
        sim, _ = run_chain(last, progress=False, overwrite=True)  # again: only the last stage runs
    assert "chain: reusing the complete run of" in caplog.text and "a.toml" in caplog.text
    assert (tmp_path / "a_run" / "checkpoint.npz").stat().st_mtime_ns == stamp
    assert np.array_equal(np.asarray(sim.state), by_hand)


def test_ctrl_c_in_the_earlier_stage_then_running_the_chain_again_gives_the_same_result(
        by_hand: np.ndarray, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    last = _write_chain(tmp_path)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("KTGF_TEST_INTERRUPT", "chunk:1")
    with pytest.raises(Interrupted, match="running the chain again continues it") as exc:
        run_chain(last, progress=False)
    assert exc.value.checkpoint is None and not (tmp_path / "b_run").exists()
    monkeypatch.delenv("KTGF_TEST_INTERRUPT")
    steps_before = int(load_checkpoint(tmp_path / "a_run" / "checkpoint.npz")["steps"])
    assert steps_before > 0
    sim, _ = run_chain(last, progress=False)
    assert np.array_equal(np.asarray(sim.state), by_hand)


def test_a_missing_earlier_config_and_a_config_source_outside_a_chain_are_refused_in_one_line(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    last = _write_chain(tmp_path)
    (tmp_path / "a.toml").unlink()
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="field initial.from_run = 'a.toml': no run configuration") as exc:
        run_chain(last, progress=False)
    assert "\n" not in str(exc.value)
    with pytest.raises(InputError, match="is a run configuration: run the chain with ktgf run"):
        Simulation(load_config(last))
    # a chain that returns to itself, found before anything runs
    (tmp_path / "a.toml").write_text(last.read_text().replace('from_run = "a.toml"', 'from_run = "b.toml"'))
    (tmp_path / "b.toml").write_text(last.read_text())
    with pytest.raises(InputError, match="the chain returns to") as exc:
        run_chain(last, progress=False)
    assert "\n" not in str(exc.value) and not (tmp_path / "a_run").exists()
