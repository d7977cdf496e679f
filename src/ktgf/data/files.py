"""The DEM reference files: their names, the copies shipped inside the package, and where a run finds them.

The files of ``shared/data`` ship as package data (``ktgf/data/dem/``, with their README and
provenance), so an installed wheel and a clone of the repository have them.  A run looks in an
explicit folder (``--data``), then ``$KTGF_DATA``, then the shipped copy.
"""

from __future__ import annotations

import os
from pathlib import Path

DATA_ENV = "KTGF_DATA"

HCS_COOLING = "dem_hcs_cooling.csv"
UNIFORM_SHEAR = "dem_uniform_shear.csv"
UNIFORM_SHEAR_EXTRA = "dem_uniform_shear_extra.csv"
FRICTION_SHEAR = "dem_uniform_shear_friction.csv"
FRICTION_SHEAR_EXTRA = "dem_uniform_shear_friction_extra.csv"
COUETTE = "dem_couette_e0.9_phi0.50.csv"
#: Every shipped file, calibration data first (README: homogeneous flows calibrate, the Couette cell validates).
DEM_FILES = (UNIFORM_SHEAR, UNIFORM_SHEAR_EXTRA, FRICTION_SHEAR, FRICTION_SHEAR_EXTRA, HCS_COOLING, COUETTE)


def shipped_data_dir() -> Path:
    """The folder of DEM files shipped inside the package."""
    return Path(__file__).resolve().parent / "dem"


def shipped(name: str) -> Path:
    """Path of a shipped DEM file by name (e.g. ``shipped(COUETTE)``)."""
    return shipped_data_dir() / name


def locate_data_dir(explicit: Path | None) -> tuple[Path | None, str]:
    """The DEM data folder to use, and a sentence saying where it came from (or why there is none).

    Order: the explicit option, ``$KTGF_DATA``, then the shipped copy.  A folder named explicitly
    (option or variable) that does not exist is reported, not an error: the comparisons are then left out.
    """
    if explicit is not None:
        src, path = "--data", Path(explicit)
    elif os.environ.get(DATA_ENV):
        src, path = f"${DATA_ENV}", Path(os.environ[DATA_ENV])
    else:
        return shipped_data_dir(), f"DEM reference data shipped with ktgf ({shipped_data_dir()})"
    if path.is_dir():
        return path.resolve(), f"DEM reference data from {path.resolve()} (given by {src})"
    return None, f"DEM reference data folder {path} (given by {src}) does not exist: comparisons with particle simulations are left out"
