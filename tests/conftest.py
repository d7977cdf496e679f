"""Shared fixtures: paths to the shared reference material and float64 JAX."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
DATA = SHARED / "data"


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The DEM reference data folder; tests that need it skip (saying so) when it is absent."""
    if not DATA.is_dir():
        pytest.skip(f"reference data folder {DATA} is absent")
    return DATA


@pytest.fixture(scope="session", autouse=True)
def _jax_x64() -> None:
    """Closures are checked against 6-digit oracles, so JAX runs in float64 in the tests."""
    try:
        import jax
    except ImportError:  # pragma: no cover
        return
    jax.config.update("jax_enable_x64", True)
