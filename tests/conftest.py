"""Shared fixtures (paths to the shared reference material, float64 JAX) and the rule that every test
names where its expected value comes from (one of the reference labels, tests/README.md)."""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# The shared folder sits next to the main checkout (/work/main -> /work/shared) and two levels up
# from a helper worktree (/work/wt/<topic> -> /work/shared); KTGF_SHARED overrides both.
_CANDIDATES = [Path(os.environ["KTGF_SHARED"])] if os.environ.get("KTGF_SHARED") else []
_CANDIDATES += [ROOT.parent / "shared", ROOT.parent.parent / "shared"]
SHARED = next((c for c in _CANDIDATES if c.is_dir()), _CANDIDATES[0])
DATA = SHARED / "data"

#: The reference labels (registered in pyproject.toml): every test carries exactly one.
REFERENCE_LABELS = ("published", "analytic", "dem", "regression", "contract")
#: How many offending test ids the collection error lists.
LISTED = 20


def _start_the_longest_tests_first(config, items) -> None:
    """With ``--dist load`` (CI's slow step), start the longest tests first: ``@pytest.mark.slow(minutes=…)``
    (worker-minutes on 2 idle cores) sorts a test ahead of the others, longest first, so that pytest-xdist hands
    them out in turn and its workers finish together instead of one running a 6-minute test alone at the end
    (tests/README.md, "What CI runs").  Not with the default ``worksteal``, which gives each worker a contiguous
    block of the list (the long tests would all go to one worker).  ``-m`` deselection keeps this order."""
    if config.getoption("dist", default="no") != "load":
        return

    def minutes(item) -> float:
        return max((m.kwargs.get("minutes", 0.0) for m in item.iter_markers("slow")), default=0.0)

    items.sort(key=lambda item: -minutes(item))  # stable: the rest keep their order


@pytest.hookimpl(tryfirst=True)  # before ``-m`` deselects: the rule holds for slow tests too
def pytest_collection_modifyitems(config, items) -> None:
    """Fail the collection when a test has no reference label or more than one.

    A file labels all its tests with one module-level ``pytestmark``, or (when its tests differ)
    each test with its own decorator and no module label; a test label inside a labelled module
    is two labels, refused like any other pair.
    """
    bad = []
    for item in items:
        labels = sorted(m.name for m in item.iter_markers() if m.name in REFERENCE_LABELS)
        if len(labels) != 1:
            bad.append(f"{item.nodeid} ({', '.join(labels) or 'no label'})")
    if bad:
        more = f"\n  ... and {len(bad) - LISTED} more" if len(bad) > LISTED else ""
        message = (f"{len(bad)} test(s) without exactly one reference label ({', '.join(REFERENCE_LABELS)}; "
                   "tests/README.md):\n  " + "\n  ".join(bad[:LISTED]) + more)
        # A collection error, not an exception (which pytest-xdist's workers turn into an INTERNALERROR):
        # pytest shows it and stops ("Interrupted: 1 error during collection", also with --collect-only);
        # xdist's workers hand it to the controller, which shows it once, and have nothing left to run.
        config.hook.pytest_collectreport(
            report=pytest.CollectReport("reference labels", "failed", message, result=[]))
        items.clear()
    _start_the_longest_tests_first(config, items)


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The DEM reference data shipped in the package (a copy of ``shared/data``: ``tests/data/test_shipped.py``)."""
    from ktgf.data import shipped_data_dir

    return shipped_data_dir()


def run_temp(tmp_path_factory) -> Path:
    """The temporary folder of the whole test run: shared by the pytest-xdist workers, else this process's."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@pytest.fixture(scope="session", autouse=True)
def _jax_x64() -> None:
    """Closures are checked against 6-digit oracles, so JAX runs in float64 in the tests."""
    try:
        import jax
    except ImportError:  # pragma: no cover
        return
    jax.config.update("jax_enable_x64", True)


@pytest.fixture(scope="session", autouse=True)
def _jax_compilation_cache(tmp_path_factory) -> None:
    """The test processes of one run share a JAX compilation cache in the run's temporary folder.

    Many tests compile the same step functions on the same grids; every run starts with the cache
    empty.  Subprocesses started by tests do not use it, so they compile as a user's first run does.
    """
    try:
        import jax
    except ImportError:  # pragma: no cover
        return
    jax.config.update("jax_compilation_cache_dir", str(run_temp(tmp_path_factory) / "jax_cache"))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.2)


@pytest.fixture(scope="session")
def quick_report(tmp_path_factory):
    """One ``ktgf reproduce --quick`` report per test run; tests copy it before changing it.

    Under pytest-xdist the first worker that needs it builds it in the run's shared temporary
    folder (behind a file lock); every worker then rebuilds its own copy from the report's cache,
    which recomputes nothing, so the minute-long build happens once per run, not once per worker.
    The copy reports the statuses of that one build ("computed"), not "cached".
    """
    from ktgf.report import ReportSettings, build_report

    def build(out):
        return build_report(ReportSettings.preset(quick=True, out=out))

    own = tmp_path_factory.mktemp("quick") / "r"
    try:
        import fcntl
    except ImportError:  # pragma: no cover - no flock (Windows): each worker builds its own
        fcntl = None
    if fcntl is None or not os.environ.get("PYTEST_XDIST_WORKER"):
        return build(own)
    shared = run_temp(tmp_path_factory) / "quick_report"
    shared.mkdir(exist_ok=True)
    record = shared / "statuses.json"
    with open(shared / "lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not record.exists():
            record.write_text(json.dumps(build(shared / "r").statuses))
    statuses = json.loads(record.read_text())
    shutil.copytree(shared / "r", own)
    report = build(own)
    report.results = [dataclasses.replace(r, status=statuses[r.key]) if r.status == "cached" else r
                      for r in report.results]
    return report
