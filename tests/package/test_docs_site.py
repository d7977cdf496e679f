"""The documentation site builds (MkDocs, strict: no broken link or missing page) and ships the physics."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


pytestmark = pytest.mark.contract


def test_docs_site_builds_with_api_reference(tmp_path) -> None:
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings")
    site = tmp_path / "site"
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-f", str(ROOT / "mkdocs.yml"), "-d", str(site)],
                          capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr[-3000:]
    api = (site / "api" / "index.html").read_text()
    assert "get_model" in api and "write_netcdf" in api  # docstrings rendered, not just headings
    model = (site / "model" / "index.html").read_text()
    assert "Garzó" in model and "Johnson" in model and "k∥*²" in model
    assert (site / "choosing" / "index.html").is_file() and (site / "examples" / "index.html").is_file()


def test_nothing_points_at_the_unshipped_spec() -> None:
    """Docs and docstrings cite docs/model.md (shipped), never ../shared/theory/model.md."""
    files = [*ROOT.joinpath("src").rglob("*.py"), *ROOT.joinpath("docs").rglob("*.md"), ROOT / "README.md"]
    bad = [str(f.relative_to(ROOT)) for f in files if "shared/theory" in f.read_text(encoding="utf-8")]
    assert not bad, bad
    sections = set(re.findall(r"^## (\d+)\.", (ROOT / "docs" / "model.md").read_text(), flags=re.M))
    cited = set()
    for f in ROOT.joinpath("src").rglob("*.py"):
        cited |= set(re.findall(r"model\.md`{0,2} §(\d+)", f.read_text(encoding="utf-8")))
    assert cited and cited <= sections, cited - sections
