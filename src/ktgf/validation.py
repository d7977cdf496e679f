"""Range checks for physical inputs, applied at public boundaries.

Closures themselves never check (so they can run under ``jax.jit``); public functions call
:func:`check_state` first.  Abstract JAX values (tracers) are skipped, since their values
are unknown at trace time.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._array import is_tracer
from .errors import InputError


def _values(name: str, x: Any) -> np.ndarray | None:
    """The values of ``x`` as floats, None for a tracer; InputError for anything that is not numbers."""
    if is_tracer(x):
        return None
    if x is None or isinstance(x, (str, bytes, bool, np.bool_)) or (isinstance(x, np.ndarray) and x.dtype == bool):
        raise InputError(f"{name} = {x!r} is not a number")
    try:
        v = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {x!r:.60} is not a number or an array of numbers") from None
    if v.size == 0:
        raise InputError(f"{name} is empty: give at least one value")
    return v


def _first_bad(v: np.ndarray, ok: np.ndarray) -> str:
    bad = v[~ok]
    n = bad.size
    more = f" (and {n - 1} more)" if n > 1 else ""
    return f"{bad.flat[0]:g}{more}"


def check_range(
    name: str,
    x: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    why: str = "",
) -> None:
    """Raise :class:`InputError` if any value of ``x`` is NaN or outside [low, high].

    The message names the quantity, the offending value and the valid range, e.g.
    ``solid fraction phi = 0.7 is out of range: valid 0 <= phi < 0.64 (packing limit of torquato)``.
    """
    v = _values(name, x)
    if v is None:
        return
    ok = np.isfinite(v)
    if low is not None:
        ok &= (v > low) if low_open else (v >= low)
    if high is not None:
        ok &= (v < high) if high_open else (v <= high)
    if ok.all():
        return
    lo = "" if low is None else f"{low:g} {'<' if low_open else '<='} "
    hi = "" if high is None else f" {'<' if high_open else '<='} {high:g}"
    short = name.split()[-1]
    rng = f"{lo}{short}{hi}" if (lo or hi) else f"{short} finite"
    tail = f" ({why})" if why else ""
    raise InputError(f"{name} = {_first_bad(v, ok)} is out of range: valid {rng}{tail}")


def check_state(phi: Any, e: Any, theta: Any = None, *, phi_max: float = 1.0, rdf_name: str = "") -> None:
    """Check 0 ≤ φ < φ_max, 0 < e ≤ 1 and θ > 0 (if given); raise :class:`InputError` otherwise."""
    why = f"packing limit of RDF {rdf_name}" if rdf_name else "packing limit"
    shapes = [np.shape(x) for x in (phi, e, theta) if x is not None]
    try:
        np.broadcast_shapes(*shapes)
    except ValueError:
        names = ("phi", "e", "theta")[:len(shapes)]
        raise InputError("arrays of shapes " + ", ".join(f"{n} {s}" for n, s in zip(names, shapes))
                         + " do not broadcast together: give arrays of one shape, or scalars") from None
    check_range("solid fraction phi", phi, low=0.0, high=phi_max, high_open=True, why=why)
    check_range("restitution coefficient e", e, low=0.0, high=1.0, low_open=True)
    if theta is not None:
        check_range("granular temperature theta", theta, low=0.0, low_open=True, why="m^2/s^2")


def check_positive(name: str, x: Any, unit: str = "") -> None:
    """Check that ``x`` is finite and > 0 (a diameter, a density, a length)."""
    check_range(name, x, low=0.0, low_open=True, why=unit)


#: Physical bounds of SI inputs at the command line (beyond them products overflow or underflow and
#: the numbers describe no granular material): particles of 1 nm to 1 m, thermal speeds of 1e-10 m/s to
#: 10 km/s, material densities of 1e-3 to 1e5 kg/m^3 (osmium: 2.26e4).
DIAMETER_RANGE, TEMPERATURE_RANGE, DENSITY_RANGE = (1e-9, 1.0), (1e-20, 1e8), (1e-3, 1e5)


def check_material(d: Any = None, theta: Any = None, rho_s: Any = None) -> None:
    """Check d, theta and rho_s (those given) against the physical ranges above."""
    for name, x, (lo, hi), unit in (("particle diameter d", d, DIAMETER_RANGE, "m"),
                                    ("granular temperature theta", theta, TEMPERATURE_RANGE, "m^2/s^2"),
                                    ("material density rho_s", rho_s, DENSITY_RANGE, "kg/m^3")):
        if x is not None:
            check_range(name, x, low=lo, high=hi, why=unit)
