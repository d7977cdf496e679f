"""The flow cases of the 3D solver (cooling, uniform-shear, couette, chute), one module each.

A case is a :class:`~.registry.Case` subclass in its own module, decorated with
:func:`~.registry.register`: its config checks, base flow, body force, time-series columns and their
computation, steady monitors, reference (``verification.json``) and time-series file name.  The
numerics ask the case (:func:`get_case` of ``case.kind``) and never compare its name, so a new case
is one new module imported here.
"""

from __future__ import annotations

# each module registers its case; this order is the order the config errors list them in
from . import cooling, uniform_shear, couette, chute  # noqa: F401,I001
from .registry import CASES, Case, get_case, kinds, register

__all__ = ["CASES", "Case", "get_case", "kinds", "register"]
