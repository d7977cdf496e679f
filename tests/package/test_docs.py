"""The generated parts of the docs match the registry, and the package runs as ``python -m ktgf``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from ktgf.cli._common import markdown_table
from ktgf.cli.closures import model_rows

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.regression
def test_models_doc_is_generated_from_registry():
    text = (ROOT / "docs" / "models.md").read_text()
    block = text.split("<!-- registry:begin -->\n", 1)[1].split("<!-- registry:end -->", 1)[0]
    assert block == markdown_table(model_rows()), "regenerate with: ktgf models --format markdown"


@pytest.mark.contract
def test_python_dash_m_ktgf_runs():
    out = subprocess.run([sys.executable, "-m", "ktgf", "--version"], capture_output=True, text=True, check=True)
    assert out.stdout.startswith("ktgf ")
