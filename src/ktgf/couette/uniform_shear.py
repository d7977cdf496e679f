"""Uniform simple shear: the closed forms of model.md §9 (the far-from-wall / Lees–Edwards limit).

In uniform shear at rate γ̇ the energy balance η γ̇² = (3/2)ρθζ0 fixes the temperature:

    γ̇/ν0 = √(3ζ0*/(2η*)),   |P_xy|/p = √(3η*ζ0*/2)/p*,   θ/(γ̇d)² = 25π η*/(13824 φ² ζ0*).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np


class UniformShear(NamedTuple):
    """Dimensionless uniform-shear state: a* = γ̇/ν0, stress ratio |P_xy|/p and θ/(γ̇d)²."""

    shear_rate_ratio: Any
    stress_ratio: Any
    temperature_ratio: Any


def uniform_shear(model: Any, phi: Any, e: Any) -> UniformShear:
    """Closed-form uniform-shear state of ``model`` at solid fraction φ and restitution e < 1."""
    r = model.reduced(phi, e)
    zeta0 = np.asarray(r.zeta0, dtype=float)
    eta = np.asarray(r.eta, dtype=float)
    phi = np.asarray(phi, dtype=float)
    return UniformShear(
        shear_rate_ratio=np.sqrt(1.5 * zeta0 / eta),
        stress_ratio=np.sqrt(1.5 * eta * zeta0) / np.asarray(r.p, dtype=float),
        temperature_ratio=25.0 * math.pi * eta / (13824.0 * phi**2 * zeta0),
    )
