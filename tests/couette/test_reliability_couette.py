"""Couette validity is physical for every model: jammed cores and collapsed temperatures are flagged."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest

from ktgf.couette.config import parse_config, run_config
from ktgf.couette.run import validity

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "couette_planar.toml"


pytestmark = pytest.mark.contract


def _run(model: str, mean_phi: float):
    data = copy.deepcopy(tomllib.loads(EXAMPLE.read_text()))
    data.update(model=model, mean_solid_fraction=mean_phi)
    return run_config(parse_config(data))


def test_validity_rules() -> None:
    theta = np.array([1e-3, 2e-3])
    assert validity(0.60, 0.64, 1.0, theta, 1.0) == "ok"
    assert "exceeds phi_rcp" in validity(0.65, 0.64, 1.0, theta, 1.0)
    # a model whose packing limit is phi_rcp: max phi can never exceed phi_rcp, but can jam
    assert validity(0.630, 0.64, 0.64, theta, 1.0) == "ok"
    assert "jammed core" in validity(0.638, 0.64, 0.64, theta, 1.0, "visc-div")
    assert "jammed core" in validity(0.634, 0.64, 0.64, theta, 1.0, jam_tolerance=0.01)
    # theta collapsed by orders of magnitude, relative to its maximum or to U^2
    assert "collapsed temperature" in validity(0.5, 0.64, 0.64, np.array([1e-17, 1e-3]), 1.0)
    assert "collapsed temperature" in validity(0.5, 0.64, 0.64, np.array([1e-17, 2e-17]), 1.0)
    assert "collapsed temperature" in validity(0.5, 0.64, 0.64, np.array([np.nan, 1e-3]), 1.0)
    assert validity(0.5, 0.64, 0.64, np.array([1e-7, 1e-4]), 1.0) == "ok"


@pytest.mark.parametrize("model, mean_phi, valid, words", [
    ("visc-div", 0.58, False, "jammed core"),   # max phi = 0.639 of its limit 0.64 (used to be "valid")
    ("visc-div", 0.30, True, ""),
    ("proposed", 0.50, True, ""),                 # max phi = 0.581: well below its limit
    ("enskog", 0.55, False, "exceeds phi_rcp"),
])
def test_solutions_are_flagged_for_every_model(model: str, mean_phi: float, valid: bool, words: str) -> None:
    ds = _run(model, mean_phi)
    assert bool(ds.attrs["physically_valid"]) is valid, ds.attrs["validity"]
    assert words in ds.attrs["validity"]
    assert ds.attrs["model_packing_limit"] > 0 and ds.attrs["theta_min_over_U2"] > 0
