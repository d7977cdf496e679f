"""Homogeneous cooling state: Haff's law and the linear stability analysis (model.md §8).

Modules: :mod:`~ktgf.hcs.haff` (cooling), :mod:`~ktgf.hcs.stability` (the linearised equations and
their closed-form thresholds), :mod:`~ktgf.hcs.dispersion` (s(k*) for all modes),
:mod:`~ktgf.hcs.critical` (thresholds by root-finding on the eigenvalues) and
:mod:`~ktgf.hcs.stability_map` (vectorised (model, φ, e) sweeps).
"""

from .critical import NoCrossingError, NoCrossingWarning, critical_wavenumbers_eig, last_crossing
from .dispersion import Dispersion, dispersion_relation, expand_states
from .haff import cooling_rate, cooling_time, haff_history, haff_temperature, integrate_cooling
from .stability import (
    BOX_CONSTANT,
    box_wavenumber,
    critical_box_size,
    critical_wavenumbers,
    longitudinal_growth_rates,
    longitudinal_matrix,
    transverse_growth_rate,
)
from .stability_map import stability_map

__all__ = [
    "cooling_rate", "cooling_time", "haff_history", "haff_temperature", "integrate_cooling",
    "BOX_CONSTANT", "box_wavenumber", "critical_box_size", "critical_wavenumbers",
    "longitudinal_growth_rates", "longitudinal_matrix", "transverse_growth_rate",
    "Dispersion", "dispersion_relation", "expand_states",
    "NoCrossingError", "NoCrossingWarning", "critical_wavenumbers_eig", "last_crossing",
    "stability_map",
]
