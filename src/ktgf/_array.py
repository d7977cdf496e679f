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


def like(x: Any, ref: Any) -> Any:
    """A host constant x (NumPy) in the precision of a JAX array ``ref``: a NumPy float64 would promote
    float32 cell fields to float64.  JAX values and NumPy ``ref`` leave x unchanged."""
    if is_jax(ref) and not is_jax(x):
        return np.asarray(x, dtype=ref.dtype)
    return x


#: Largest |4b| for which :func:`power` multiplies instead of calling ``pow``.
_QUARTER_POWERS = 64


def power(x: Any, b: Any) -> Any:
    """x**b; a concrete exponent that is a multiple of 1/4 (|b| ≤ 16) by multiplications and square roots.

    Why: XLA evaluates a float64 ``pow`` on the CPU at ≈ 20 ns a value, more than all the other
    closure arithmetic of a cell (the β = 1.75 of the viscosity-divergence RDF made the Proposed
    model's closure pass 2× RET's, docs/solver.md, Speed).  x^(n/4) = x^⌊n/4⌋ · √x^[n mod 4 ≥ 2] ·
    ⁴√x^[n odd] is the same function (round-off differs by a few ulp: each factor is correctly
    rounded); NaN for x < 0 and ∞ for x = 0, b < 0, as ``pow``.  A traced exponent (a
    calibration differentiating with respect to it) or any other value keeps ``x**b``.
    """
    if is_tracer(b):
        return x**b
    try:
        n4 = float(b) * 4.0
    except (TypeError, ValueError):
        return x**b
    if n4 != round(n4) or abs(n4) > _QUARTER_POWERS:
        return x**b
    n = int(round(n4))
    whole, quarters = divmod(abs(n), 4)
    xp = namespace(x)
    r = x**whole  # an integer power: multiplications (jax.lax.integer_pow)
    if quarters & 2:
        r = r * xp.sqrt(x)
    if quarters & 1:
        r = r * xp.sqrt(xp.sqrt(x))
    return 1.0 / r if n < 0 else r
