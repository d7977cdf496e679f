"""Calibration: fit model parameters to particle data (readers, residuals, least-squares driver, model files).

>>> from ktgf import get_model
>>> from ktgf.calibration import calibrate, read_data
>>> fit = calibrate(get_model("proposed"), [read_data("dem_uniform_shear.csv")], ["phi_c", "beta"])  # doctest: +SKIP
>>> fit.value_dict(), fit.stderr                                                                    # doctest: +SKIP

Modules: :mod:`.residuals` (predictions, residuals, exact Jacobians), :mod:`.fit` (the driver and
the identifiability report), :mod:`.model_file` (the TOML files every command reads with
``--model-file``), :mod:`.crossval` (leave-one-state-out cross-validation), :mod:`.bands` (prediction
bands, delta method), :mod:`.validate` (a model against every DEM file), :mod:`.registry_fits` (the
registered models' fits and what they were fitted to).  The readers are :mod:`ktgf.data`.  See
``docs/calibration.md``.
"""

from ..data import CouetteCase, CouetteData, UniformShearData, read_couette, read_couette_case, read_data, read_uniform_shear
from .fit import FitResult, calibrate, fittable_parameters

__all__ = [
    "CouetteCase", "CouetteData", "FitResult", "UniformShearData", "calibrate", "fittable_parameters", "read_couette",
    "read_couette_case", "read_data", "read_uniform_shear",
]
