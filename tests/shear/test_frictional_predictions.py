"""The registered ``frictional`` against uniform-shear states it was never fitted to: ktgf's own LAMMPS runs.

``docs/data/ktgf_dem_uniform_shear_predictions.csv`` holds states run with ``ktgf dem shear`` (the protocol of the
shared frictional file: 864 spheres, γ̇ = 1, strain 2–10, two seeds) at friction and restitution the shared data do
not have: μ 0.1 and 0.25 (e 0.7), μ 0.5 at e 0.9, μ 0 at e 0.7.  Nothing was fitted to them (docs/friction.md §6.2).
Where the model meets the issue-33 goals (T within 15 %, p/(nT) and τ/p within 10 %) the test says so; the states
and quantities where it does not are listed in :data:`MISSES` with the measured error, so a change that fixes or
breaks one shows here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ktgf import get_model
from ktgf.data import read_friction_shear
from ktgf.shear.steady import steady_shear

FILE = Path(__file__).resolve().parents[2] / "docs" / "data" / "ktgf_dem_uniform_shear_predictions.csv"
GOALS = {"T": 0.15, "p_over_nT": 0.10, "tau_over_p": 0.10}
#: (μ, φ, e, quantity): the measured relative error (docs/friction.md §6.2); each must stay within 2 points of it.
MISSES: dict[tuple[float, float, float, str], float] = {
    # frictionless (the registered `dense`) at e = 0.7: T and τ/p of the e = 0.9 fit do not carry over (p/(nT) does)
    (0.0, 0.3, 0.7, "T"): +0.223,
    (0.0, 0.4, 0.7, "T"): +0.206,
    (0.0, 0.55, 0.7, "tau_over_p"): +0.172,
    (0.0, 0.58, 0.7, "T"): -0.163,
    (0.0, 0.58, 0.7, "tau_over_p"): +0.260,
    # weaker friction at the fit's e = 0.7
    (0.1, 0.5, 0.7, "T"): +0.200,
    (0.1, 0.57, 0.7, "tau_over_p"): +0.158,
    (0.25, 0.5, 0.7, "T"): +0.174,
    (0.25, 0.57, 0.7, "tau_over_p"): +0.137,
    # the fit's μ = 0.5 at e = 0.9: T and τ/p miss above φ 0.4 (p/(nT) within 9.2 %)
    (0.5, 0.4, 0.9, "tau_over_p"): -0.126,
    (0.5, 0.5, 0.9, "T"): +0.393,
    (0.5, 0.5, 0.9, "tau_over_p"): -0.216,
    (0.5, 0.55, 0.9, "T"): +0.775,
    (0.5, 0.55, 0.9, "tau_over_p"): -0.236,
}


def _errors():
    rows = read_friction_shear(FILE)
    out = {}
    for r in rows:
        s = steady_shear(get_model("frictional", mu=r["mu"]), np.array([r["phi"]]), r["e"])
        dem = {"T": r["T"], "tau_over_p": r["tau_over_p"], "p_over_nT": r["p_star"] / (r["phi"] * r["T"])}
        for q in GOALS:
            out[(r["mu"], r["phi"], r["e"], q)] = float(np.asarray(getattr(s, q))[0]) / dem[q] - 1.0
    return out


@pytest.mark.dem
def test_frictional_predictions_of_states_it_was_never_fitted_to():
    errors = _errors()
    assert set(MISSES) <= set(errors)
    for key, err in errors.items():
        if key in MISSES:
            assert abs(err - MISSES[key]) < 0.02, (key, err, MISSES[key])
            assert abs(err) > GOALS[key[3]], (key, err, "now within the goal: move it out of MISSES")
        else:
            assert abs(err) <= GOALS[key[3]], (key, err)
