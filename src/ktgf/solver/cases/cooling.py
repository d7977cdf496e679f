"""``cooling``: a periodic box cooling freely (the homogeneous cooling state, model.md §8)."""

from __future__ import annotations

from typing import Any

from ...errors import InputError
from .registry import Case, register


@register
class Cooling(Case):
    name, label, hcs = "cooling", "HCS", True

    def check(self, cfg: Any, source: str, shear: str | None, wall: str | None) -> None:
        if cfg.time.steady_tol is not None:
            raise InputError(f"{source}: field time.steady_tol applies to the sheared cases only (a cooling box has no "
                             "steady state)")
        if shear or wall:
            raise InputError(f"{source}: field boundaries.{shear or wall}.kind = "
                             f"{getattr(cfg.boundaries, shear or wall).kind!r} needs case.kind = 'uniform-shear' or "
                             "'couette' (the cooling case is a periodic box)")

    def clock(self, t: float, tau: float | None = None, shear_rate: float = 0.0) -> str:
        """``t = … s  τ = …`` (τ = ∫ν dt, collisions per particle)."""
        return f"t = {t:.4g} s  τ = {tau:.3g}"
