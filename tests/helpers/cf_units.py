"""A small check of CF/UDUNITS unit strings (what the netCDF tests accept), independent of ktgf."""

from __future__ import annotations

import re

#: UDUNITS symbols ktgf may use (SI base and derived units; "1" for dimensionless).
SYMBOLS = {"1", "m", "s", "kg", "K", "Pa", "W", "J", "N", "rad", "mol"}
_TOKEN = re.compile(r"^(?P<sym>[A-Za-z]+|1)(?P<exp>-?\d+)?$")


def valid_units(text: str) -> bool:
    """True for strings such as ``1``, ``m``, ``m2 s-2``, ``m/s``, ``W/m2``, ``1/s``, ``kg m-3``.

    Rejects what UDUNITS reads differently from what was meant (``d`` = day, ``reduced``...).
    """
    if not isinstance(text, str) or not text.strip():
        return False
    for part in text.replace("/", " ").split():
        m = _TOKEN.match(part)
        if m is None or m["sym"] not in SYMBOLS:
            return False
    return True
