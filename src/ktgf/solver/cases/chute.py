"""``chute``: a layer on a base wall at rest (x_a = 0) under a lid (x_a = H, default zero-flux) with
g = g(sin ζ e_f − cos ζ e_a); start u_f = ``initial.shear_rate`` · x_a + perturbation; reference: the 1D
inclined-layer solver (:func:`ktgf.couette.chute.solve_chute`, same column and walls)."""

from __future__ import annotations

import math
from typing import Any

from ...errors import InputError
from ..boundaries import AXES
from ..flows import profile_errors
from ..grid import Grid
from ..kinematics import gradient_axis
from ..physics import Physics
from .registry import WallCase, register


def chute_reference(phys: Physics, grid: Grid, phi0: float, n_cells: int = 256) -> Any:
    """Steady inclined layer of the 1D solver for the 3D column (same model, base, lid, inventory, depth)."""
    from ...couette.chute import solve_chute
    from ...couette.run import Material

    a, f = gradient_axis(grid), grid.boundaries.flow
    g = phys.gravity
    gmag = math.hypot(g[a], g[f])
    angle = math.degrees(math.atan2(g[f], -g[a]))
    base, lid = grid.boundaries.walls[a]
    material = Material(float(phys.diameter), float(phys.material_density), float(phys.restitution))
    return solve_chute(phys.model, depth=grid.lengths[a], angle_deg=angle, mean_phi=phi0, material=material,
                       base=base.wall, top=lid.wall, gravity=gmag, n_cells=n_cells)


def compare_chute(history: dict[str, list], phys: Physics, grid: Grid, phi0: float,
                  n_cells: int = 256) -> dict[str, Any]:
    """Max relative deviation of the last profiles from the 1D steady layer on ``n_cells`` (u relative to its maximum)."""
    ref = chute_reference(phys, grid, phi0, n_cells=n_cells)
    a = gradient_axis(grid)
    return {
        "reference": "1D steady inclined layer ktgf.couette.chute.solve_chute (same model, base, lid, inventory "
                     f"and depth; {n_cells} cells)",
        "max_rel_error": profile_errors(history, ref, grid.centres(a)),
        "base_shear_stress_Pa": {"run": history["wall_shear_stress_lower"][-1],
                                 "reference": float(ref["wall_shear_stress"].values[0])},
        "base_slip_m_per_s": {"run": history["wall_slip_lower"][-1], "reference": float(ref["wall_slip"].values[0])},
        "cells_across_depth": grid.cells[a],
    }


@register
class Chute(WallCase):
    name, label, inclined = "chute", "chute", True

    def check(self, cfg: Any, source: str, shear: str | None, wall: str | None) -> None:
        speed = getattr(cfg.boundaries, wall).wall_speed
        if speed != 0:
            raise InputError(f"{source}: field boundaries.{wall}.wall_speed = {speed:g} is out of range: valid "
                             "wall_speed = 0 for a chute (the base is at rest)")
        if cfg.case.inclination_deg is None:
            raise InputError(f"{source}: field case.inclination_deg is missing: a chute needs the base inclination "
                             "(0 < inclination_deg < 90 degrees)")
        if cfg.time.unit == "strain":
            raise InputError(f"{source}: field time.unit = 'strain': a chute has no imposed shear rate; valid 's'")

    def gravity(self, cfg: Any) -> tuple[float, float, float]:
        """g(sin ζ e_flow − cos ζ e_normal) [m/s²], ζ = ``case.inclination_deg``."""
        axis = cfg.boundaries.wall_axis()
        a, f = AXES.index(axis), AXES.index(getattr(cfg.boundaries, axis).flow)
        z = math.radians(cfg.case.inclination_deg)
        g = [0.0, 0.0, 0.0]
        g[f], g[a] = cfg.case.gravity * math.sin(z), -cfg.case.gravity * math.cos(z)
        return tuple(g)

    def verification(self, history: dict[str, list], phys: Physics, grid: Grid, phi0: float) -> dict[str, Any]:
        return {**self.about(phys, phi0), **compare_chute(history, phys, grid, phi0)}
