"""Particle data on demand: LAMMPS runs (a separate program, never linked) written in the shared DEM formats.

:mod:`.lammps` finds and runs ``lmp``; :mod:`.contact` holds the contact law and its restitution
calibration; :mod:`.shear` runs and analyses Lees–Edwards shear; :mod:`.sweep` runs many states
on an executor, resumably; :mod:`.output` writes the shared CSV formats.
"""

from .contact import Restitution, calibrate_restitution, collision_frequency, spring_dashpot, two_body_restitution
from .lammps import Lammps, LammpsError, find_lammps, lammps_available
from .shear import ShearRun, ShearState, check_state, run_shear
from .sweep import shear_sweep, stiffness_change

__all__ = ["Lammps", "LammpsError", "Restitution", "ShearRun", "ShearState", "calibrate_restitution", "check_state",
           "collision_frequency", "find_lammps", "lammps_available", "run_shear", "shear_sweep", "spring_dashpot",
           "stiffness_change", "two_body_restitution"]
