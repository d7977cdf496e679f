"""Model cooling rates against LAMMPS DEM of freely cooling frictionless spheres (dem_hcs_cooling.csv).

The DEM file (see ``shared/data/README.md``) gives the Haff slope A = ζ/√T in units d = m = 1 with
T = m⟨c²⟩/3 = mθ, so the model prediction is A = ζ0(θ = 1, d = 1) = ν0 ζ0* = (96/5)(φ/√π) ζ0*.
We compare with the early-window fits ``A_early`` (T0 → T0/2), the cleanest test of an
instantaneous ζ0.  Nothing is fitted to this file.

Documented expectation (README): the DEM cools 1–10 % slower than Enskog theory (velocity
correlations the theory neglects), with a realistic uncertainty of ±0.5–1 %.  So each model's
A must exceed the DEM value by between −1 % and +11 %: A_DEM/A_model ∈ [0.89, 1.01].
"""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from ktgf.closures import PAPER_MODELS, c_star, get_model
from ktgf.hcs import cooling_rate

DEFICIT_BAND = (0.89, 1.01)  # A_DEM/A_model: 1–10 % deficit widened by the ±1 % DEM uncertainty


pytestmark = pytest.mark.dem


def _rows(data_dir):
    with open(data_dir / "dem_hcs_cooling.csv") as fh:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(line for line in fh if not line.startswith("#"))]


def test_units_agree_with_the_files_own_enskog_normalisation(data_dir):
    """A_early/ratio_early is the file's A_Enskog = (4√π/3)(1 − e²)χ_CS n(1 + 3a2/16), a2 = c*/2.

    Our RET ζ0 with CS χ, converted as above, must equal it: a check of the unit conversion
    (agreement to the 4–5 digits the file prints).
    """
    for row in _rows(data_dir):
        a_file = row["A_early"] / row["ratio_early"]
        a_ret = float(cooling_rate("ret", row["phi"], row["e"], 1.0, d=1.0))
        chi = get_model("ret").chi(row["phi"])
        n = 6.0 * row["phi"] / math.pi
        a_readme = (4.0 * math.sqrt(math.pi) / 3.0) * (1 - row["e"] ** 2) * chi * n * (1 + 3 * c_star(row["e"]) / 32)
        assert a_ret == pytest.approx(a_readme, rel=1e-12)
        assert a_ret == pytest.approx(a_file, rel=3e-4)


@pytest.mark.parametrize("name", PAPER_MODELS)
def test_model_cooling_rate_vs_dem_early_window(name, data_dir):
    """Per-point error of the model ζ0 against DEM, printed, and asserted within the documented deficit."""
    rows = _rows(data_dir)
    errors = []
    print(f"\n{name}: model A vs DEM A_early (dem_hcs_cooling.csv)")
    print("   phi     e    A_model    A_early   A_DEM/A_model   model error")
    for row in rows:
        a_model = float(cooling_rate(name, row["phi"], row["e"], 1.0, d=1.0))
        ratio = row["A_early"] / a_model
        errors.append(a_model / row["A_early"] - 1.0)
        print(f"  {row['phi']:.2f}  {row['e']:.2f}  {a_model:9.5f}  {row['A_early']:9.5f}   {ratio:11.4f}   {errors[-1]:+8.2%}")
        assert DEFICIT_BAND[0] <= ratio <= DEFICIT_BAND[1], (
            f"{name} at phi={row['phi']}, e={row['e']}: A_DEM/A_model = {ratio:.4f} outside the documented {DEFICIT_BAND}"
        )
    errors = np.array(errors)
    print(f"  mean error {errors.mean():+.2%}, max |error| {np.abs(errors).max():.2%}")
    # The model over-predicts cooling on average (DEM deficit), by less than the documented 10 %.
    assert 0.0 < errors.mean() < 0.10
