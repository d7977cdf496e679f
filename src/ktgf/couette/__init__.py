"""Steady Couette shear cells (planar and annular) for every closure model (model.md §§7, 9).

Modules: :mod:`.geometry` (cells, grids, metrics), :mod:`.walls` (Johnson–Jackson, bumpy, prescribed,
zero-flux walls), :mod:`.equations` (discrete balances), :mod:`.solver` (Newton, pseudo-transient
and homotopy continuation), :mod:`.run` (Dataset output),
:mod:`.config` (validated TOML configs), :mod:`.compare` (four models, DEM data), :mod:`.chute`
(steady gravity-driven inclined layer, :func:`solve_chute`).

Example::

    from ktgf.couette import PlanarCell, Wall
    from ktgf.couette.run import Material, run

    wall = Wall(specularity=0.1, restitution=0.9)                  # Johnson–Jackson
    ds = run("proposed", PlanarCell(gap=0.02, wall_speed=1.0), wall, wall,
             mean_phi=0.5, material=Material(d=1e-3, rho_s=2500.0, e=0.9))
    ds.attrs["validity"], ds["u"], ds["phi"], ds["theta"], ds["wall_shear_stress"]

Command line: ``ktgf couette run examples/couette_planar.toml``, ``ktgf couette compare``
(four models and the DEM profile; ``--wall bumpy``: the DEM's wall spheres, nothing fitted),
``ktgf couette sweep CONFIG --specularity 0.001:1:7 --wall-restitution 0.8,0.9 --workers 2``,
``ktgf plot couette out.nc``.
"""

from .chute import InclinedLayer, solve_chute
from .compare import report_profiles
from .equations import Problem
from .geometry import AnnularCell, PlanarCell, stretched_nodes
from .solver import CouetteConvergenceError, solve
from .walls import Wall

__all__ = [
    "AnnularCell", "CouetteConvergenceError", "InclinedLayer", "PlanarCell", "Problem", "report_profiles", "Wall",
    "solve", "solve_chute", "stretched_nodes",
]
