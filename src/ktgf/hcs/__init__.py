"""Homogeneous cooling state: Haff's law and the linear stability analysis (model.md §8)."""

from .haff import cooling_rate, cooling_time, haff_temperature
from .stability import (
    BOX_CONSTANT,
    critical_box_size,
    critical_wavenumbers,
    longitudinal_growth_rates,
    longitudinal_matrix,
    transverse_growth_rate,
)

__all__ = [
    "cooling_rate", "cooling_time", "haff_temperature", "BOX_CONSTANT", "critical_box_size",
    "critical_wavenumbers", "longitudinal_growth_rates", "longitudinal_matrix", "transverse_growth_rate",
]
