"""Reading the DEM reference tables (``/work/shared/data/*.csv``: '#' header lines, then CSV with a title row)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

HCS_COOLING = "dem_hcs_cooling.csv"
UNIFORM_SHEAR = "dem_uniform_shear.csv"
COUETTE = "dem_couette_e0.9_phi0.50.csv"


def read_table(path: str | Path) -> dict[str, np.ndarray]:
    """Columns of a DEM CSV file as float arrays, keyed by the names of its title row."""
    rows = [ln for ln in Path(path).read_text(encoding="utf-8").splitlines() if ln.strip() and not ln.startswith("#")]
    names = [n.strip() for n in rows[0].split(",")]
    values = np.array([[float(v) for v in ln.split(",")] for ln in rows[1:]], dtype=float)
    return {n: values[:, i] for i, n in enumerate(names)}


def header_lines(path: str | Path) -> list[str]:
    """The '#' comment lines of a DEM file (without the '#'), which describe the run."""
    return [ln[1:].strip() for ln in Path(path).read_text(encoding="utf-8").splitlines() if ln.startswith("#")]
