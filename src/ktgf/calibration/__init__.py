"""Calibration: fit model parameters to particle data (readers, residuals, least-squares driver, model files).

>>> from ktgf import get_model
>>> from ktgf.calibration import calibrate, read_data
>>> fit = calibrate(get_model("proposed"), [read_data("dem_uniform_shear.csv")], ["phi_c", "beta"])  # doctest: +SKIP
>>> fit.value_dict(), fit.stderr                                                                    # doctest: +SKIP

Modules: :mod:`.data` (shared data formats), :mod:`.residuals` (predictions, residuals, exact
Jacobians), :mod:`.fit` (the driver), :mod:`.model_file` (the TOML files every command reads
with ``--model-file``).  See ``docs/calibration.md``.
"""

from ..data import CouetteCase, CouetteData, UniformShearData, read_couette, read_couette_case, read_data, read_uniform_shear
from .fit import FitResult, calibrate, fittable_parameters

__all__ = [
    "CouetteCase", "CouetteData", "FitResult", "UniformShearData", "calibrate", "fittable_parameters", "read_couette",
    "read_couette_case", "read_data", "read_uniform_shear",
]
