"""Uniform simple shear: the closed forms of model.md §9 (the far-from-wall / Lees–Edwards limit).

In uniform shear at rate γ̇ the energy balance η γ̇² = (3/2)ρθζ0 fixes the temperature:

    γ̇/ν0 = √(3ζ0*/(2η*)),   |P_xy|/p = √(3η*ζ0*/2)/p*,   θ/(γ̇d)² = 25π η*/(13824 φ² ζ0*).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from .._array import asarray


class UniformShear(NamedTuple):
    """Dimensionless uniform-shear state: a* = γ̇/ν0, stress ratio |P_xy|/p and θ/(γ̇d)²."""

    shear_rate_ratio: Any
    stress_ratio: Any
    temperature_ratio: Any


def uniform_shear(model: Any, phi: Any, e: Any, *, check: bool = True) -> UniformShear:
    """Closed-form uniform-shear state of ``model`` at solid fraction φ and restitution e < 1.

    NumPy in, NumPy out; JAX values pass through, so with ``check=False`` (options that are JAX
    tracers have no value to check) ``jax.jacfwd`` differentiates it exactly (used by calibration).
    """
    r = model.reduced(phi, e, check=check)
    phi = asarray(phi)
    return UniformShear(
        shear_rate_ratio=(1.5 * r.zeta0 / r.eta) ** 0.5,
        stress_ratio=(1.5 * r.eta * r.zeta0) ** 0.5 / r.p,
        temperature_ratio=25.0 * math.pi * r.eta / (13824.0 * phi**2 * r.zeta0),
    )
