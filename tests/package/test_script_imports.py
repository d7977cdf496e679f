"""The scripts in benchmarks/ and docs/ import modules that exist.

They run outside the test suite (by hand, or to regenerate a docs table), so a moved test helper breaks
them silently: ``benchmarks/chute_bagnold.py`` and ``benchmarks/couette_friction_map.py`` had imported
helpers from their old places.  Each script's imports are read from its source (not run: some docs
scripts compute their tables at import) and looked up with the script's own folder and ``tests/`` on
the path, as the scripts set it.
"""

from __future__ import annotations

import ast
import importlib.util
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.contract

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = sorted([*ROOT.glob("benchmarks/**/*.py"), *ROOT.glob("docs/*.py")])


def _imported_modules(path: Path) -> list[str]:
    """Absolute module names of the script's import statements, anywhere in the file."""
    names = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.append(node.module)
    return names


def test_the_scripts_are_found() -> None:
    assert len(SCRIPTS) >= 20 and any(p.name == "chute_bagnold.py" for p in SCRIPTS)


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_import_of_a_script_resolves(script: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "path", [str(script.parent), str(ROOT / "tests"), *sys.path])
    missing = []
    for name in _imported_modules(script):
        try:
            found = importlib.util.find_spec(name) is not None
        except ModuleNotFoundError:  # a parent package is missing
            found = False
        if not found:
            missing.append(name)
    assert not missing, f"{script.relative_to(ROOT)} imports modules that do not exist: {missing}"
