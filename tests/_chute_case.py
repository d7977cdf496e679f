"""The 1D-grid chute config of the 3D solver's tests (RET, φ̄ 0.3, 25°, bumpy base, zero-flux lid)."""

from __future__ import annotations


def chute_case(cells: list[int], end: float, length_d: float = 10.0, outputs: int = 2,
               steady_tol: float | None = None) -> str:
    """TOML text of the chute on a 1D grid along x (the wall axis), flow along y, from a hot sheared start."""
    steady = f"\nsteady_tol = {steady_tol}" if steady_tol is not None else ""
    return f"""
[case]
kind = "chute"
inclination_deg = 25.0
[model]
name = "ret"
restitution = 0.9
[initial]
solid_fraction = 0.3
temperature = 0.03
shear_rate = 100.0
perturbation = "none"
[grid]
cells = {cells}
length_d = {length_d}
[boundaries]
x = {{ kind = "wall", flow = "y", wall_speed = 0.0, walls = {{ type = "johnson-jackson", specularity = 1.0, restitution = 0.9, top = {{ type = "zero-flux" }} }} }}
[time]
end = {end}
unit = "s"
outputs = {outputs}
scheme = "imex"{steady}
[output]
png = false
vtk = false
"""
