"""The labelling rule of tests/conftest.py, run on a tiny suite in a subprocess.

The tiny suite gets the real tests/conftest.py and the real marker registrations of pyproject.toml:
labelled tests run, a test with no label or with two (a test label inside a labelled module among
them) is a collection error listing their ids (at most 20), and nothing runs, with pytest-xdist too.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

pytestmark = pytest.mark.contract

ROOT = Path(__file__).resolve().parents[2]

MODULE_LABEL = """
import pytest

pytestmark = pytest.mark.published


def test_module_labelled():
    assert 0.1 + 0.2 != 0.3
"""

TEST_LABELS = """
import pytest


@pytest.mark.analytic
def test_own_label():
    assert 2**10 == 1024
"""


def _suite(tmp_path: Path, **files: str) -> Path:
    """A folder with the real conftest, the real markers and the given test files."""
    markers = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]["markers"]
    (tmp_path / "pyproject.toml").write_text(
        "[tool.pytest.ini_options]\nmarkers = [\n" + "".join(f"    {m!r},\n" for m in markers) + "]\n")
    (tmp_path / "conftest.py").write_text((ROOT / "tests" / "conftest.py").read_text())
    for name, text in files.items():
        (tmp_path / f"{name}.py").write_text(text)
    return tmp_path


def _pytest(folder: Path, *args: str) -> subprocess.CompletedProcess:
    # not this run's worker or options; nor CI's markers, with which pytest repeats a collection error's whole
    # message in its short summary (the list below would then be counted twice)
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTEST_") and k not in ("CI", "BUILD_NUMBER")}
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:randomly", *args],
                          check=False, cwd=folder, env=env, capture_output=True, text=True, timeout=300)


def test_labelled_tests_run(tmp_path):
    run = _pytest(_suite(tmp_path, test_module=MODULE_LABEL, test_own=TEST_LABELS))
    assert run.returncode == 0, run.stdout + run.stderr
    assert "2 passed" in run.stdout
    assert "PytestUnknownMarkWarning" not in run.stdout + run.stderr  # the labels are registered


def test_unlabelled_and_doubly_labelled_tests_stop_the_collection(tmp_path):
    bad = """
import pytest


@pytest.mark.slow
def test_nothing():
    pass


@pytest.mark.dem
@pytest.mark.regression
def test_two():
    pass
"""
    inside = MODULE_LABEL + "\n\n@pytest.mark.analytic\ndef test_label_inside_a_labelled_module():\n    pass\n"
    folder = _suite(tmp_path, test_module=inside, test_own=TEST_LABELS, test_bad=bad)
    run = _pytest(folder, "-m", "not slow")  # the rule holds before -m deselects
    assert run.returncode == pytest.ExitCode.INTERRUPTED, run.stdout + run.stderr
    assert "Interrupted: 1 error during collection" in run.stdout and "ERROR collecting reference labels" in run.stdout
    lines = run.stdout.splitlines()
    assert "3 test(s) without exactly one reference label (published, analytic, dem, regression, contract; " \
           "tests/README.md):" in lines
    assert "  test_bad.py::test_nothing (no label)" in lines
    assert "  test_bad.py::test_two (dem, regression)" in lines
    assert "  test_module.py::test_label_inside_a_labelled_module (analytic, published)" in lines
    assert "test_own_label" not in run.stdout and "test_module_labelled" not in run.stdout
    assert "passed" not in run.stdout  # nothing ran
    # --collect-only (the cheap check of a whole tree) refuses it too
    assert _pytest(folder, "--collect-only").returncode == pytest.ExitCode.INTERRUPTED
    # the default suite runs under pytest-xdist: the error reaches the controller, nothing runs
    xdist = _pytest(folder, "-n", "2")
    assert xdist.returncode != 0 and "  test_bad.py::test_two (dem, regression)" in xdist.stdout.splitlines()
    assert "passed" not in xdist.stdout and "INTERNALERROR" not in xdist.stdout + xdist.stderr


def test_the_list_stops_at_twenty(tmp_path):
    many = "import pytest\n\n\n@pytest.mark.parametrize('i', range(25))\ndef test_many(i):\n    pass\n"
    run = _pytest(_suite(tmp_path, test_many=many), "--collect-only")
    assert run.returncode == pytest.ExitCode.INTERRUPTED, run.stdout + run.stderr
    listed = [ln for ln in run.stdout.splitlines() if ln.startswith("  test_many.py::")]
    assert len(listed) == 20 and listed[-1] == "  test_many.py::test_many[19] (no label)"
    assert "25 test(s)" in run.stdout and "  ... and 5 more" in run.stdout.splitlines()
