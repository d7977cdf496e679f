"""Cell geometries of the Couette problem: planar and annular, with their 1D grids and metrics.

The steady fully developed Couette flow is one-dimensional in the wall-normal coordinate x
(y for the planar cell, r for the annular one).  Both cells are written in one conservative
form (model.md §9),

    d/dx [A η dω/dx] = 0                      (tangential momentum: uniform shear/torque flux)
    d/dx [B Q] + A η (dω/dx)² − B Γ = 0       (energy, Q = κ dθ/dx + ω_φ dφ/dx = −q_x, Γ = (3/2)ρθζ0)
    d ln p/dx = K                             (normal / radial momentum)

with the geometry supplying the metrics:

=========== ======== ========= ========= ================== ==================
cell        ω        A (flux)  B (vol.)  wall stress factor K (centripetal)
=========== ======== ========= ========= ================== ==================
planar      u        1         1         1                  0
annular     u/r      r³        r         r²                 ρ u²/(r p)
=========== ======== ========= ========= ================== ==================

so that A η dω/dx is the shear stress (planar) or the torque per unit length and per 2π,
r²τ_rθ (annular).  Lengths are in particle diameters and velocities in the wall-speed scale
inside the solver (see :mod:`ktgf.couette.equations`); these classes hold SI inputs and the
dimensionless grid.

Glossary: ``x`` wall-normal coordinate, ``n_cells`` number of intervals (n_cells + 1 nodes,
one on each wall), ``stretch`` tanh clustering strength of the grid towards the walls.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..validation import check_positive, check_range


def stretched_nodes(x0: float, x1: float, n_cells: int, stretch: float = 0.0) -> np.ndarray:
    """Nodes x0 … x1 clustered towards both ends by a tanh map of a uniform parameter ξ.

    x = x0 + L (1 + tanh(s(2ξ − 1))/tanh s)/2.  Because the map is smooth and ξ uniform,
    grids with n and 2n cells are nested (every other node of the finer grid), which the
    mesh-refinement study relies on.  ``stretch = 0`` gives a uniform grid.
    """
    if int(n_cells) != n_cells or n_cells < 8:
        raise InputError(f"number of cells n_cells = {n_cells} is out of range: valid integer n_cells >= 8")
    check_range("grid stretching stretch", stretch, low=0.0, high=5.0)
    xi = np.linspace(0.0, 1.0, int(n_cells) + 1)
    if stretch == 0.0:
        t = xi
    else:
        t = 0.5 * (1.0 + np.tanh(stretch * (2.0 * xi - 1.0)) / math.tanh(stretch))
    x = x0 + (x1 - x0) * t
    x[0], x[-1] = x0, x1
    return x


@dataclass(frozen=True)
class PlanarCell:
    """Planar Couette cell: walls at y = ∓H/2 moving at ∓U/2 (model.md §9).

    Parameters
    ----------
    gap : float
        Wall-to-wall distance H [m] (> 0).
    wall_speed : float
        Relative wall speed U [m/s] (> 0); the bottom wall moves at −U/2, the top at +U/2.
    """

    gap: float
    wall_speed: float
    kind = "planar"
    coordinate = "y"

    def __post_init__(self) -> None:
        check_positive("gap H", self.gap, "m")
        check_positive("wall speed U", self.wall_speed, "m/s")

    def velocity_scale(self) -> float:
        return float(self.wall_speed)

    def bounds(self, d: float) -> tuple[float, float]:
        """Wall positions in particle diameters."""
        return -0.5 * self.gap / d, 0.5 * self.gap / d

    def wall_velocities(self) -> tuple[float, float]:
        """Tangential wall velocities in units of the velocity scale."""
        return -0.5, 0.5

    # metrics (dimensionless x)
    def angular(self, u: np.ndarray, x: np.ndarray) -> np.ndarray:
        return u

    def flux_metric(self, x: np.ndarray) -> np.ndarray:
        return np.ones_like(x)

    def stress_metric(self, x: np.ndarray) -> np.ndarray:
        return np.ones_like(x)

    def volume_metric(self, x: np.ndarray) -> np.ndarray:
        return np.ones_like(x)

    def control_volumes(self, x: np.ndarray) -> np.ndarray:
        """∫ B dx over each node's control volume (half intervals at the walls)."""
        xf = 0.5 * (x[1:] + x[:-1])
        edges = np.concatenate([x[:1], xf, x[-1:]])
        return np.diff(edges)

    def centripetal(self, u: np.ndarray, x: np.ndarray, phi: np.ndarray, p: np.ndarray) -> np.ndarray:
        return np.zeros_like(u)

    def shear_rate(self, u: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Shear rate du/dy at the nodes (second-order differences on a non-uniform grid)."""
        return np.gradient(u, x, edge_order=2)

    def describe(self) -> dict[str, float | str]:
        return {"geometry": self.kind, "gap": self.gap, "wall_speed": self.wall_speed}


@dataclass(frozen=True)
class AnnularCell:
    """Annular Couette cell: inner cylinder R_i rotating at Ω, outer cylinder R_o at rest (model.md §9).

    Torque balance r²τ_rθ = const, radial balance dp/dr = ρu_θ²/r and energy with
    (1/r) d(r q_r)/dr.  Velocities are scaled by ΩR_i.

    Parameters
    ----------
    inner_radius, outer_radius : float
        R_i < R_o [m].
    omega : float
        Angular velocity of the inner cylinder Ω [rad/s] (> 0).
    """

    inner_radius: float
    outer_radius: float
    omega: float
    kind = "annular"
    coordinate = "r"

    def __post_init__(self) -> None:
        check_positive("inner radius R_i", self.inner_radius, "m")
        check_positive("outer radius R_o", self.outer_radius, "m")
        check_positive("angular velocity omega", self.omega, "rad/s")
        if not self.outer_radius > self.inner_radius:
            raise InputError(
                f"outer radius R_o = {self.outer_radius:g} is out of range: valid R_o > R_i = {self.inner_radius:g} m"
            )

    @property
    def gap(self) -> float:
        return self.outer_radius - self.inner_radius

    def velocity_scale(self) -> float:
        return float(self.omega * self.inner_radius)

    def bounds(self, d: float) -> tuple[float, float]:
        return self.inner_radius / d, self.outer_radius / d

    def wall_velocities(self) -> tuple[float, float]:
        return 1.0, 0.0

    def angular(self, u: np.ndarray, x: np.ndarray) -> np.ndarray:
        return u / x

    def flux_metric(self, x: np.ndarray) -> np.ndarray:
        return x**3

    def stress_metric(self, x: np.ndarray) -> np.ndarray:
        return x**2

    def volume_metric(self, x: np.ndarray) -> np.ndarray:
        return x

    def control_volumes(self, x: np.ndarray) -> np.ndarray:
        xf = 0.5 * (x[1:] + x[:-1])
        edges = np.concatenate([x[:1], xf, x[-1:]])
        return 0.5 * np.diff(edges**2)

    def centripetal(self, u: np.ndarray, x: np.ndarray, phi: np.ndarray, p: np.ndarray) -> np.ndarray:
        """d ln p/dr = ρu²/(r p) (ρ_s = 1 in solver units)."""
        return phi * u**2 / (x * p)

    def shear_rate(self, u: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Shear rate r d(u/r)/dr at the nodes."""
        return x * np.gradient(u / x, x, edge_order=2)

    def describe(self) -> dict[str, float | str]:
        return {
            "geometry": self.kind,
            "inner_radius": self.inner_radius,
            "outer_radius": self.outer_radius,
            "omega": self.omega,
        }


Geometry = PlanarCell | AnnularCell
