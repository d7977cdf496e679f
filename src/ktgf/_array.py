"""Array-namespace helpers: the closures run unchanged on NumPy and on JAX arrays.

A closure calls :func:`namespace` on its inputs and uses the returned module
(``numpy`` or ``jax.numpy``) for the few functions that are not plain arithmetic
(``sqrt``, ``where``).  JAX is imported only when a JAX array is passed in, so
NumPy users never pay for it.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np


def is_jax(x: Any) -> bool:
    """True if ``x`` is a JAX array or tracer (checked without importing JAX)."""
    return type(x).__module__.split(".", 1)[0] in ("jax", "jaxlib")


def is_tracer(x: Any) -> bool:
    """True if ``x`` is an abstract JAX value (inside ``jit``/``grad``), whose values are unknown."""
    if not is_jax(x):
        return False
    import jax

    return isinstance(x, jax.core.Tracer)


def namespace(*arrays: Any) -> ModuleType:
    """Return ``jax.numpy`` if any argument is a JAX array, else ``numpy``."""
    if any(is_jax(a) for a in arrays):
        import jax.numpy as jnp

        return jnp
    return np


def asarray(x: Any) -> Any:
    """Pass JAX values through; turn anything else into a float NumPy array."""
    if is_jax(x):
        return x
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        from .errors import InputError

        raise InputError(f"{x!r:.60} is not a number or an array of numbers") from None
