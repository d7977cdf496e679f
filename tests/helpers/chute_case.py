"""The 1D-grid chute config of the 3D solver's tests (RET, φ̄ 0.3, bumpy base, zero-flux lid; 25° unless told)."""

from __future__ import annotations


def chute_case(cells: list[int], end: float, length_d: float | list[float] = 10.0, outputs: int = 2,
               steady_tol: float | None = None, inclination_deg: float = 25.0, temperature: float = 0.03,
               shear_rate: float = 100.0, scheme: str = "imex") -> str:
    """TOML text of the chute with the wall axis first (x), flow along y, from a hot sheared start
    u = ``shear_rate`` × height, θ = ``temperature`` [m²/s²]; ``cells``/``length_d`` of 1 or 3 axes."""
    steady = f"\nsteady_tol = {steady_tol}" if steady_tol is not None else ""
    return f"""
[case]
kind = "chute"
inclination_deg = {inclination_deg}
[model]
name = "ret"
restitution = 0.9
[initial]
solid_fraction = 0.3
temperature = {temperature}
shear_rate = {shear_rate}
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
scheme = "{scheme}"{steady}
[output]
png = false
vtk = false
"""


def bagnold_case(depth_d: float, inclination_deg: float = 18.0, cells_per_d: float = 1.0,
                 thin: bool = False, scheme: str = "imex") -> dict:
    """The chute at depth H (in d) from the 10 d start scaled with Bagnold's law, as a config dict.

    γ̇0 = 100/s (H/10d)^{1/2} and θ0 = 0.03 m²/s² (H/10d) (θ ∝ (γ̇d)²): a sheared start of the right
    size that is not the steady answer.  Outputs ≈ 0.1 s (H/10d)^{1.6} apart (the relaxation time:
    steady_tol 1e-4 was met at 2.3 s at 10 d and 7.0 s at 20 d, 25°), an end time 6 s (H/10d)² that
    ``steady_tol`` cuts short.  ``thin``: a 4 × N × 4 box (8 d along flow and span) instead of a 1D grid;
    ``scheme``: the time scheme (``time.scheme``).
    """
    import math
    import tomllib

    n = int(round(cells_per_d * depth_d))
    scale = depth_d / 10.0
    end = 6.0 * scale**2
    cells, lengths = ([n, 4, 4], [depth_d, 8.0, 8.0]) if thin else ([n], depth_d)
    return tomllib.loads(chute_case(cells, end, length_d=lengths, outputs=max(2, int(round(end / (0.1 * scale**1.6)))),
                                    steady_tol=1e-4, inclination_deg=inclination_deg, temperature=0.03 * scale,
                                    shear_rate=100.0 * math.sqrt(scale), scheme=scheme))
