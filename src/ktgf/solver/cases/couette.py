"""``couette``: Johnson–Jackson walls on one axis moving at ∓U/2 along the flow; start u_f = (U/L_a)(x_a −
L_a/2) + perturbation; reference: the 1D Couette solver (:func:`ktgf.couette.run.run`, same walls, inventory)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import InputError
from ..flows import profile_errors
from ..grid import Grid
from ..kinematics import gradient_axis
from ..physics import Physics
from .registry import WallCase, register


def couette_reference(phys: Physics, grid: Grid, phi0: float, n_cells: int = 400) -> Any:
    """Steady planar Couette profile of the 1D solver for the 3D cell (same model, walls, inventory, gap)."""
    from ...couette.geometry import PlanarCell
    from ...couette.run import Material, run

    a, f = gradient_axis(grid), grid.boundaries.flow
    lower, upper = grid.boundaries.walls[a]
    U = upper.velocity[f] - lower.velocity[f]
    material = Material(float(phys.diameter), float(phys.material_density), float(phys.restitution))
    return run(phys.model, PlanarCell(grid.lengths[a], U), lower.wall, upper.wall, phi0, material,
               n_cells=n_cells, stretch=1.5)


def compare_couette(history: dict[str, list], phys: Physics, grid: Grid, phi0: float) -> dict[str, Any]:
    """Max relative deviation of the last profiles from the 1D steady solution at the cell centres.

    u relative to the wall speed U/2 (u changes sign mid-gap), φ and θ pointwise.
    """
    ref = couette_reference(phys, grid, phi0)
    a, f = gradient_axis(grid), grid.boundaries.flow
    lower, upper = grid.boundaries.walls[a]
    y = grid.centres(a) - 0.5 * grid.lengths[a]  # the 1D cell spans −H/2 … H/2
    return {
        "reference": "1D steady planar Couette solver ktgf.couette (same model, walls, inventory and gap; 400 cells)",
        "max_rel_error": profile_errors(history, ref, y, 0.5 * (upper.velocity[f] - lower.velocity[f])),
        "wall_shear_stress_Pa": {"run": [history["wall_shear_stress_lower"][-1], history["wall_shear_stress_upper"][-1]],
                                 "reference": np.asarray(ref["wall_shear_stress"].values).tolist()},
        "wall_slip_m_per_s": {"run": [history["wall_slip_lower"][-1], history["wall_slip_upper"][-1]],
                              "reference": np.asarray(ref["wall_slip"].values).tolist()},
        "cells_across_gap": grid.cells[a],
    }


@register
class Couette(WallCase):
    name, label, imposed_shear = "couette", "Couette", True

    def check(self, cfg: Any, source: str, shear: str | None, wall: str | None) -> None:
        speed = getattr(cfg.boundaries, wall).wall_speed
        if not speed > 0:
            raise InputError(f"{source}: field boundaries.{wall}.wall_speed = {speed:g} is out of range: valid "
                             "wall_speed > 0 m/s for a Couette cell")

    def verification(self, history: dict[str, list], phys: Physics, grid: Grid, phi0: float) -> dict[str, Any]:
        return {**self.about(phys, phi0), **compare_couette(history, phys, grid, phi0)}
