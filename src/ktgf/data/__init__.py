"""DEM reference data: the shipped files, one parser and a typed reader per format (the bottom of the package).

>>> from ktgf.data import read_uniform_shear, shipped, UNIFORM_SHEAR
>>> read_uniform_shear(shipped(UNIFORM_SHEAR)).phi
array([0.3, 0.5])
"""

from .files import (
    COUETTE, DATA_ENV, DEM_FILES, FRICTION_SHEAR, FRICTION_SHEAR_EXTRA, HCS_COOLING, UNIFORM_SHEAR,
    UNIFORM_SHEAR_EXTRA, locate_data_dir, shipped, shipped_data_dir,
)
from .formats import (
    RHO_S_DEM, SHEAR_COLUMNS, SHEAR_OBSERVABLES, CouetteCase, CouetteData, UniformShearData, read_cooling,
    read_couette, read_couette_case, read_data, read_friction_shear, read_uniform_shear, uniform_shear_records,
)
from .table import Table, file_hash, read_table

__all__ = [
    "COUETTE", "DATA_ENV", "DEM_FILES", "FRICTION_SHEAR", "FRICTION_SHEAR_EXTRA", "HCS_COOLING", "UNIFORM_SHEAR",
    "UNIFORM_SHEAR_EXTRA", "RHO_S_DEM", "SHEAR_COLUMNS", "SHEAR_OBSERVABLES", "CouetteCase", "CouetteData", "Table",
    "UniformShearData", "file_hash", "locate_data_dir", "read_cooling", "read_couette", "read_couette_case", "read_data",
    "read_friction_shear", "read_table", "read_uniform_shear", "shipped", "shipped_data_dir", "uniform_shear_records",
]
