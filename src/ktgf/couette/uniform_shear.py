"""Uniform simple shear: the closed forms of model.md §9 (the far-from-wall / Lees–Edwards limit).

In uniform shear at rate γ̇ the energy balance η γ̇² = (3/2)ρθζ0 fixes the temperature.  With
a* = γ̇/ν0 and the reduced coefficients (ρθ/η0 = ν0):

    a*² = 3ζ0*/(2η*),   |P_xy|/p = η* a*/p*,   θ/(γ̇d)² = 25π/(9216 φ² a*²) = 25π η*/(13824 φ² ζ0*).

With a dissipation correction of extended kinetic theory (:mod:`ktgf.closures.dissipation`),
ζ0* → ζ0* d/L with L/d = max(1, Λ s) and s = dγ̇/√θ = k a*, k = (96/5) φ/√π.  The energy
balance is then solved consistently: a*² = 3ζ0*/(2η* max(1, Λ k a*)), whose root is

    a* = a0                        if Λ k a0 ≤ 1   (L = d, the standard theory),
    a* = (a0²/(Λ k))^(1/3)         otherwise,       a0 = √(3ζ0*/(2η*)).

The DEM file's columns (``shared/data/dem_uniform_shear.csv`` header, d = m = 1):
T = θ/(γ̇d)², η_star = η d²/√(mT) = (5/(16√π)) η*, eta_over_eta0 = η*, p_over_nT = p*,
astar = γ̇/ν0 with ν0 = (16/5)√π n √T (= model.md's ν0).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from .._array import asarray, namespace

#: η0 d²/√(mT) = 5/(16√π): converts η* = η/η0 to the DEM file's η d²/√(mT).
ETA0_DEM = 5.0 / (16.0 * math.sqrt(math.pi))
#: s = dγ̇/√θ = SHEAR_PER_ASTAR · φ · a*, from ν0 = (96/5)(φ/d)√(θ/π).
SHEAR_PER_ASTAR = 96.0 / (5.0 * math.sqrt(math.pi))


class UniformShear(NamedTuple):
    """Dimensionless uniform-shear state: a* = γ̇/ν0, stress ratio |P_xy|/p and θ/(γ̇d)²."""

    shear_rate_ratio: Any
    stress_ratio: Any
    temperature_ratio: Any


class ShearState(NamedTuple):
    """Uniform-shear steady state in the DEM file's dimensionless columns (plus a*, L/d)."""

    phi: Any
    T: Any
    eta_star: Any
    eta_over_eta0: Any
    p_over_nT: Any
    astar: Any
    stress_ratio: Any
    L_over_d: Any


def _solve(model: Any, phi: Any, e: Any, check: bool = True) -> tuple[Any, Any, Any, Any]:
    """(reduced coefficients without shear, a*, L/d, η*) of the steady uniform shear.

    NumPy in, NumPy out; JAX values pass through, so with ``check=False`` (options that are JAX
    tracers have no value to check) ``jax.jacfwd`` differentiates it exactly (used by calibration).
    """
    phi, e = asarray(phi), asarray(e)
    xp = namespace(phi, e)
    r = model.reduced(phi, e, check=check)
    a0 = (1.5 * r.zeta0 / r.eta) ** 0.5
    lam = model.dissipation.coefficient(phi, e, model.chi(phi))
    k = SHEAR_PER_ASTAR * phi
    x = lam * k * a0
    correlated = xp.isfinite(x) & (x > 1.0)
    safe = xp.where(correlated, lam * k, 1.0)
    a = xp.where(correlated, (a0**2 / safe) ** (1.0 / 3.0), a0)
    length = xp.where(correlated, lam * k * a, 1.0)
    return r, a, length, r.eta


def uniform_shear(model: Any, phi: Any, e: Any, *, check: bool = True) -> UniformShear:
    """Closed-form uniform-shear state of ``model`` at solid fraction φ and restitution e < 1."""
    r, a, _, eta = _solve(model, phi, e, check)
    phi = asarray(phi)
    return UniformShear(
        shear_rate_ratio=a,
        stress_ratio=eta * a / r.p,
        temperature_ratio=25.0 * math.pi / (9216.0 * phi**2 * a**2),
    )


def shear_state(model: Any, phi: Any, e: Any, *, check: bool = True) -> ShearState:
    """Uniform-shear steady state of ``model`` in the DEM file's columns (module docstring)."""
    r, a, length, eta = _solve(model, phi, e, check)
    phi = asarray(phi)
    p = r.p
    return ShearState(
        phi=phi, T=25.0 * math.pi / (9216.0 * phi**2 * a**2), eta_star=ETA0_DEM * eta, eta_over_eta0=eta,
        p_over_nT=p, astar=a, stress_ratio=eta * a / p, L_over_d=length,
    )


#: Columns the uniform-shear DEM files must have (``shared/data/dem_uniform_shear*.csv``).
DEM_COLUMNS: tuple[str, ...] = ("phi", "e", "T", "eta_over_eta0", "p_over_nT")


def load_uniform_shear(path: Any, *, where: dict[str, float] | None = None) -> np.ndarray:
    """Rows of a uniform-shear DEM CSV (comment header, then named columns) as a record array.

    ``where`` keeps only rows whose columns equal the given values (e.g. ``{"mu": 0.0}`` for the
    frictionless row of ``dem_uniform_shear_friction.csv``).  The file is parsed and checked by
    the calibration readers (:mod:`ktgf.calibration.data`): a missing file, missing columns or
    non-finite values raise :class:`~ktgf.errors.InputError`.
    """
    from ..calibration.data import _columns, _split

    _, names, table = _split(path)
    keep = np.ones(table.shape[0], dtype=bool)
    for key, value in (where or {}).items():
        keep &= _columns(path, names, table, (key,))[key] == value
    cols = _columns(path, names, table, tuple(dict.fromkeys((*DEM_COLUMNS, *names))), np.flatnonzero(keep))
    return np.rec.fromarrays(list(cols.values()), names=list(cols))
