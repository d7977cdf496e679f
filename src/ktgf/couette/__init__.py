"""Steady Couette shear cells (planar and annular) for every closure model (model.md §§7, 9)."""

from .equations import Problem
from .geometry import AnnularCell, PlanarCell, stretched_nodes
from .solver import CouetteConvergenceError, solve
from .uniform_shear import UniformShear, uniform_shear
from .walls import Wall

__all__ = [
    "AnnularCell", "CouetteConvergenceError", "PlanarCell", "Problem", "UniformShear", "Wall",
    "solve", "stretched_nodes", "uniform_shear",
]
