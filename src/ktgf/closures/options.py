"""Validation of model options, applied where closure parts are made (their ``__post_init__``).

Every check raises :class:`~ktgf.errors.InputError` with one line naming the option, the value
given and the valid range, e.g. ``option phi_c = 1.5 is out of range: valid 0.49 < phi_c <=
0.74048 (RDF torquato: phi_f < phi_c <= close packing pi/sqrt(18))``.  Booleans must be real booleans
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
    from ..validation import check_range

    if isinstance(value, bool) or not isinstance(value, Real):
        raise InputError(f"option {name} = {value!r}{_where(owner)} must be a real number")
    why = f"{owner}: {why}" if owner and why else owner or why
    check_range(f"option {name}", float(value), low=low, high=high, low_open=low_open, high_open=high_open, why=why)
    return float(value)


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
