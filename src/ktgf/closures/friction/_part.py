"""Shared base of the frictional closure parts: parameters as dataclass fields, one-line input errors."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, ClassVar

from ...validation import check_range


@dataclass(frozen=True)
class FrictionPart:
    """A registry-ready closure part: its fields are its parameters (see :meth:`params`)."""

    key: ClassVar[str] = ""
    label: ClassVar[str] = ""
    reference: ClassVar[str] = ""

    def params(self) -> dict[str, Any]:
        """The parameters of this part (its dataclass fields)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def options(self) -> dict[str, Any]:
        """Same as :meth:`params` (the name :class:`ktgf.closures.models.Model` uses for parts)."""
        return self.params()

    def describe(self) -> str:
        """Short text: key and parameters, e.g. ``johnson-jackson(Fr=0.05, ...)``."""
        return f"{self.key}(" + ", ".join(f"{k}={v}" for k, v in self.params().items()) + ")"


def check_friction_coefficient(mu: Any) -> None:
    """Raise :class:`~ktgf.errors.InputError` unless the particle friction coefficient is finite and ≥ 0."""
    check_range("particle friction coefficient mu", mu, low=0.0)


__all__ = ["FrictionPart", "check_friction_coefficient", "check_range"]
