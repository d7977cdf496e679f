"""Validation of model options, applied where closure parts are made (their ``__post_init__``).

Every check raises :class:`~ktgf.errors.InputError` with one line naming the option, the value
given and the valid range, e.g. ``option phi_c = 1.5 of RDF torquato is out of range: valid
0.49 < phi_c <= 0.74048 (phi_f < phi_c <= close packing)``.  Booleans must be real booleans
(``sonine="no"`` is an error, not True) and numbers real finite numbers (not bools, strings, NaN).
"""

from __future__ import annotations

import math
from numbers import Real
from typing import Any

from ..errors import InputError

#: Densest packing of equal spheres, π/√18 (Kepler; Hales 2005): no φ_c may exceed it.
CLOSE_PACKING = math.pi / math.sqrt(18.0)


def _where(owner: str) -> str:
    return f" of {owner}" if owner else ""


def real_option(
    name: str,
    value: Any,
    *,
    owner: str = "",
    low: float | None = None,
    high: float | None = None,
    low_open: bool = True,
    high_open: bool = False,
    why: str = "",
) -> float:
    """Check that option ``name`` is a finite real number in the given range; return it as float."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise InputError(f"option {name} = {value!r}{_where(owner)} must be a real number")
    v = float(value)
    ok = math.isfinite(v)
    if ok and low is not None:
        ok = v > low if low_open else v >= low
    if ok and high is not None:
        ok = v < high if high_open else v <= high
    if not ok:
        lo = "" if low is None else f"{low:.6g} {'<' if low_open else '<='} "
        hi = "" if high is None else f" {'<' if high_open else '<='} {high:.6g}"
        rng = f"{lo}{name}{hi}" if (lo or hi) else f"{name} finite"
        tail = f" ({why})" if why else ""
        raise InputError(f"option {name} = {value!r}{_where(owner)} is out of range: valid {rng}{tail}")
    return v


def bool_option(name: str, value: Any, *, owner: str = "") -> bool:
    """Check that option ``name`` is a real boolean (True/False, not a string or a number)."""
    import numpy as np

    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"option {name} = {value!r}{_where(owner)} must be true or false")
    return bool(value)


def choice_option(name: str, value: Any, choices: tuple[str, ...], *, owner: str = "") -> str:
    """Check that option ``name`` is one of ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise InputError(f"option {name} = {value!r}{_where(owner)} is not valid; choose one of {', '.join(choices)}")
    return value
