"""Exception types for user mistakes.

Every error raised at a public boundary (function argument, config file, CLI option)
names the quantity, the value given and the valid range, so that the message alone is
enough to fix the input.
"""

from __future__ import annotations


class KtgfError(Exception):
    """Base class of all ktgf errors."""


class InputError(KtgfError, ValueError):
    """A physical input is outside its valid range (e.g. φ ≥ packing limit, e ∉ (0, 1])."""


class UnknownModelError(KtgfError, KeyError):
    """A model name that is not in the registry."""

    def __str__(self) -> str:  # KeyError would print the repr with quotes
        return str(self.args[0]) if self.args else "unknown model"


class ConvergenceError(KtgfError, RuntimeError):
    """An iterative solver did not converge; carries its diagnosis."""


class DivergenceError(KtgfError, RuntimeError):
    """A time-dependent run left the physical state space (θ ≤ 0, φ ≥ φ_max, NaN)."""
