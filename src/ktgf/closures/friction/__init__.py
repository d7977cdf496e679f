"""Frictional particles: collisions, jamming, frictional stress, blends and dense rheology.

Each part is a frozen dataclass whose fields are its parameters (``params()``), with ``key``,
``label`` and ``reference``; every formula is a pure function of NumPy or JAX arrays.
Physics notes, defaults with their sources and the DEM comparison: ``docs/friction.md``.
"""

from .blending import BLENDS, SigmoidBlend, TanhBlend
from .collisions import (
    RESTITUTION_LAWS,
    ChialvoSundaresanRestitution,
    RoughSphereRestitution,
    WaltonRestitution,
    modified_cooling_rate,
)
from .jamming import (
    FrictionalChialvoSundaresan,
    JammingFraction,
    d_jamming_fraction_dmu,
    jamming_fraction,
    with_jamming_fraction,
)
from .rheology import DenseInertialTemperature, LinearDilatancy, MuIRheology, inertial_number
from .stress import JohnsonJacksonPressure, SchaefferViscosity, SrivastavaSundaresanViscosity

__all__ = [
    "BLENDS", "SigmoidBlend", "TanhBlend",
    "RESTITUTION_LAWS", "ChialvoSundaresanRestitution", "RoughSphereRestitution", "WaltonRestitution",
    "modified_cooling_rate",
    "FrictionalChialvoSundaresan", "JammingFraction", "d_jamming_fraction_dmu", "jamming_fraction",
    "with_jamming_fraction",
    "DenseInertialTemperature", "LinearDilatancy", "MuIRheology", "inertial_number",
    "JohnsonJacksonPressure", "SchaefferViscosity", "SrivastavaSundaresanViscosity",
]
