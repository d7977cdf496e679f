"""The flow cases of the 3D solver (cooling, uniform-shear, couette, chute), one module each.

A case is a :class:`~.registry.Case` subclass in its own module, decorated with :func:`~.registry.register`.
The numerics ask it (:func:`get_case` of ``case.kind``), never compare its name: a new case is one new
module imported here.
"""

from __future__ import annotations

from .registry import CASES, Case, get_case, kinds, register

__all__ = ["CASES", "Case", "get_case", "kinds", "register"]

# each module registers its case; in this order the config errors list them
from . import cooling, uniform_shear, couette, chute  # noqa: F401, I001
