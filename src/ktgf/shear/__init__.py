"""Uniform shear flow beyond its closed form: the linear stability of the steady state (docs/uniform_shear_stability.md).

:mod:`.stability`: the linearised Navier–Stokes-order balances about u = γ̇ y e_x for every
registered model; normal modes for wavevectors (0, k_y, k_z) (:func:`shear_modes`) and Kelvin
modes with a sheared wavevector (:func:`kelvin_evolution`).
"""

from .stability import FIELDS, ShearBase, ShearModes, kelvin_evolution, shear_base_state, shear_matrix, shear_modes

__all__ = ["FIELDS", "ShearBase", "ShearModes", "kelvin_evolution", "shear_base_state", "shear_matrix", "shear_modes"]
