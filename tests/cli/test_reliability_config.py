"""Configs: every value finite, in range and of its own type; files read as UTF-8 (issue 11)."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.errors import InputError
from ktgf.io import read_toml
from ktgf.solver.config import parse_config
from ktgf.solver.run import MEMORY_FACTOR, Simulation, check_memory

ROOT = Path(__file__).resolve().parents[2]
HCS = {"initial": {"solid_fraction": 0.25, "temperature": 1e-4},
       "grid": {"cells": [8, 8], "relative_to": "transverse", "factor": 1.5}, "time": {"end": 4.0}}


pytestmark = pytest.mark.contract


def _with(section: str, key: str, value) -> dict:
    cfg = copy.deepcopy(HCS)
    cfg.setdefault(section, {})[key] = value
    return cfg


@pytest.mark.parametrize("section, key, value, words", [
    ("time", "end", float("inf"), ["time.end", "finite"]),
    ("time", "end", float("nan"), ["time.end", "finite"]),
    ("particles", "diameter", float("inf"), ["particles.diameter"]),
    ("initial", "temperature", float("nan"), ["initial.temperature"]),
    ("initial", "seed", -1, ["initial.seed", "greater than or equal to 0"]),
    ("initial", "seed", 1.5, ["initial.seed", "integer"]),
    ("model", "restitution", True, ["model.restitution", "valid number", "True"]),
    ("output", "vtk", 1, ["output.vtk", "boolean"]),
    ("grid", "cells", [8.0, 8], ["grid.cells.0", "integer"]),
    ("grid", "cells", [True, 8], ["grid.cells.0"]),
    ("time", "outputs", "10", ["time.outputs"]),
    ("time", "max_steps_per_call", 2**40, ["time.max_steps_per_call"]),
    ("initial", "max_mode", 100, ["initial.max_mode = 100", "<= 4"]),
    ("output", "directory", "", ["output.directory"]),
    ("numerics", "phi_stop", 1.5, ["numerics.phi_stop"]),
])
def test_hcs_config_values_are_checked(section: str, key: str, value, words: list[str]) -> None:
    with pytest.raises(InputError) as exc:
        parse_config(_with(section, key, value))
    msg = str(exc.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_mode_beyond_the_grid_resolution_is_refused() -> None:
    cfg = _with("initial", "perturbation", "mode")
    cfg["initial"].update(mode=[7, 0])
    with pytest.raises(InputError, match=r"initial.mode = \[7, 0\].*cells\[a\]/2"):
        parse_config(cfg)


def test_frictional_model_is_accepted_by_the_3d_solver() -> None:
    # the 3D solver takes friction parts (tests/solver/test_solver_friction.py); what it still refuses is tested there
    cfg = _with("model", "name", "frictional")
    cfg["model"]["restitution"] = 0.7
    assert parse_config(cfg).model.name == "frictional"


def test_numpy_scalars_from_python_callers_are_accepted() -> None:
    import numpy as np

    cfg = _with("model", "restitution", np.float64(0.9))
    cfg["grid"]["cells"] = (np.int64(8), 8)
    assert parse_config(cfg).grid.cells == [8, 8]


def test_memory_is_estimated_and_refused_before_allocating() -> None:
    with pytest.raises(InputError) as exc:
        Simulation(parse_config(_with("grid", "cells", [4096, 4096, 4096])))
    msg = str(exc.value)
    assert "grid.cells = [4096, 4096, 4096]" in msg and "55 TB" in msg and "this machine has" in msg
    # the estimate: MEMORY_FACTOR x 5 fields x cells x itemsize, against the memory given
    assert check_memory((64, 64, 64), "float32", available=10**12) == MEMORY_FACTOR * 5 * 64**3 * 4
    with pytest.raises(InputError, match="float32"):
        check_memory((64, 64, 64), "float64", available=10**6)


@pytest.mark.parametrize("content, words", [
    ("model = 'ret' # é\n".encode("latin-1"), ["not UTF-8", "0xe9"]),
    ("a = 1\n".encode("utf-16"), ["not UTF-8", "0xff"]),
    (bytes(range(256)), ["not UTF-8"]),
    (b"\x00\x01\x02", ["not valid TOML"]),
    (b"[grid\n", ["not valid TOML"]),
])
def test_config_files_must_be_utf8_toml(content: bytes, words: list[str], tmp_path: Path) -> None:
    p = tmp_path / "c.toml"
    p.write_bytes(content)
    with pytest.raises(InputError) as exc:
        read_toml(p)
    for w in words:
        assert w in str(exc.value)
    for cmd in (["run", str(p)], ["couette", "run", str(p)]):
        res = CliRunner().invoke(app, cmd)
        assert res.exit_code == 2 and isinstance(res.exception, SystemExit), res.output
        assert len(res.stderr.strip().splitlines()) == 1


def test_utf8_with_bom_and_a_directory(tmp_path: Path) -> None:
    p = tmp_path / "bom.toml"
    p.write_bytes("\ufeffa = 1\n".encode("utf-8"))
    assert read_toml(p) == {"a": 1}
    for cmd in (["run", str(tmp_path)], ["couette", "run", str(tmp_path)]):
        res = CliRunner().invoke(app, cmd)
        assert res.exit_code == 2 and "is a directory" in res.stderr


def _couette(tmp_path: Path, old: str, new: str) -> Path:
    text = (ROOT / "examples" / "couette_planar.toml").read_text()
    assert old in text
    p = tmp_path / "c.toml"
    p.write_text(text.replace(old, new))
    return p


@pytest.mark.parametrize("old, new, words", [
    ('path = "couette_planar.nc"', 'path = "."', ["output.path", "is a folder"]),
    ('path = "couette_planar.nc"', 'path = "out.txt"', ["output.path", ".nc"]),
    ("restitution = 0.9              # particle", "restitution = true  # particle", ["'restitution'", "valid number"]),
    ("gap = 0.02 ", "gap = inf ", ["geometry.gap", "finite"]),
    ("n_cells = 200", "n_cells = 200.0", ["numerics.n_cells", "integer"]),
    ("specularity = 0.1 ", "specularity = nan ", ["walls.specularity"]),
])
def test_couette_config_values_are_checked(old: str, new: str, words: list[str], tmp_path: Path) -> None:
    res = CliRunner().invoke(app, ["couette", "run", str(_couette(tmp_path, old, new))])
    assert res.exit_code == 2 and isinstance(res.exception, SystemExit), res.output
    line = res.stderr.strip()
    assert "\n" not in line
    for w in words:
        assert w in line, line


def test_couette_out_folder_is_refused(tmp_path: Path) -> None:
    res = CliRunner().invoke(app, ["couette", "run", str(ROOT / "examples" / "couette_planar.toml"), "-o", "."])
    assert res.exit_code == 2 and "--out = '.' is a folder" in res.stderr
