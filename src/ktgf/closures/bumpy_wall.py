"""A wall of fixed spheres (a "bumpy" wall): its geometry, and the stress and energy flux of its collisions.

Wall: fixed spheres of diameter d_w whose centres form a plane hexagonal (triangular) lattice of spacing
a = d_w + s (s ≥ 0 the gap; s = 0 touching, the wall of ``shared/data/dem_couette_e0.9_phi0.50.csv``).
Flow: smooth spheres of diameter d, normal restitution e_w with the wall spheres.  Contact distance
σ = (d + d_w)/2; the unit normal k of a collision points from the wall sphere's centre to the flowing
sphere's centre, θ is its angle from the wall normal ẑ (into the flow) and ψ its azimuth from the slip.

Geometry (exact, :class:`BumpyWall`):

* a flowing sphere touching wall sphere i cannot overlap a neighbour j (in-plane direction ψ_j, at
  distance a): k·ê_j ≤ a/(2σ) =: c0 for the six neighbours, i.e. sin θ cos(ψ − ψ_j) ≤ c0.  The accessible
  normals form a cap θ ≤ θ_max(ψ) = arcsin(min(1, c0/max_j cos(ψ − ψ_j))).
* toward a neighbour (the saddle between two wall spheres) θ_max = arcsin(c0): the wall "bumpiness"
  angle of Jenkins & Richman's plane-flow boundary conditions, sin θ_w = (d_w + s)/(d + d_w) (30° for
  equal touching spheres); above a triangular hollow θ = arccos(h/σ) with h = √(σ² − a²/3) the height
  of a sphere resting in the hollow (h = √(2/3) d = 0.8165 d for equal touching spheres).

Kinetics (our derivation, :func:`wall_fluxes`; not the printed equations of Richman, Acta Mech. 75, 227
(1988) or Jenkins & Askari (1991), which could not be read here — ``docs/dense_physics.md`` §6): the
flowing spheres that reach the wall have a Maxwellian velocity distribution of temperature T (per unit
mass, θ) and mean velocity v x̂ relative to the wall (the slip), and their centres are spread uniformly,
with a number density n_w, over the accessible caps (no extra correlation).  A collision with normal k
and relative velocity g (w = g·k < 0) changes the velocity by −(1 + e_w) w k and happens at the rate
n_w σ² (−w) per unit solid angle of k per wall sphere.  With ν_w = 2/(√3 a²) wall spheres per unit
area, the forces per unit wall area on the wall and the flux of fluctuation energy ½m|c − u|² into the
flow are

    N = K ∫ M2(k) cos θ dΩ,     S = −K ∫ M2(k) k_x dΩ,     Q = S v − D,     D = K (1 − e_w)/2 ∫ M3(k) dΩ,
    K = ν_w n_w σ² m (1 + e_w),  M2 = E[w² ; w < 0],  M3 = E[|w|³ ; w < 0],  w ~ N(v k_x, T),

(N the normal stress the flow exerts on the wall, S the shear stress along the slip, S v the slip work,
D the collisional dissipation at the wall).  Only the ratios are needed by a continuum boundary
condition at a wall where the normal stress N and T are known: S/N = F(v/√T) and Q/(N√T) = G(v/√T, e_w);
:func:`wall_fluxes` returns them.  Exact limits (tested): no slip gives S = 0 and Q = −D ≤ 0, with D = 0
for e_w = 1; tiny wall spheres (d_w/d → 0) give the flat frictionless wall, S/N → 0 and
Q/(N√T) → −(1 − e_w)√(2/π); a Monte Carlo of single collisions reproduces F and G.  :func:`wall_fluxes`
takes NumPy or JAX slip ratios (``jax.grad`` gives dF/d(v/√T) for a Newton solve); the geometry is NumPy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np
from scipy.special import ndtr

from .._array import asarray, is_jax, like, namespace
from ..validation import check_range

#: In-plane directions of the six neighbours of a wall sphere (hexagonal layer; one row along ψ = 0).
NEIGHBOUR_ANGLES = np.arange(6) * (math.pi / 3.0)


@dataclass(frozen=True)
class BumpyWall:
    """A hexagonal layer of fixed spheres: wall-sphere diameter ``d_w`` and gap ``gap`` in units of the flowing d.

    ``row_angle`` is the angle (radians) between the slip and a row of the lattice (0: slip along a row).
    The layer must hold the flowing spheres: a sphere resting in a triangular hollow must stay above the
    plane of the wall-sphere centres (a/√3 < σ).
    """

    d_w: float = 1.0
    gap: float = 0.0
    row_angle: float = 0.0

    def __post_init__(self) -> None:
        check_range("wall-sphere diameter d_w", self.d_w, low=0.0, low_open=True, why="in units of the flowing d")
        check_range("wall-sphere gap", self.gap, low=0.0, why="in units of the flowing d")
        check_range("lattice row angle row_angle", self.row_angle, low=-math.pi, high=math.pi, why="radians")
        check_range("wall-sphere gap", self.gap, high=math.sqrt(3.0) * self.sigma - self.d_w, high_open=True,
                    why="a flowing sphere would pass between the wall spheres")

    @property
    def sigma(self) -> float:
        """Contact distance σ = (1 + d_w)/2 (in units of d)."""
        return 0.5 * (1.0 + self.d_w)

    @property
    def spacing(self) -> float:
        """Centre spacing a = d_w + gap."""
        return self.d_w + self.gap

    @property
    def bumpiness(self) -> float:
        """θ_w = arcsin(a/(2σ)) = arcsin((d_w + s)/(d + d_w)): the largest θ toward a neighbour (radians)."""
        return math.asin(min(1.0, self.spacing / (2.0 * self.sigma)))

    @property
    def resting_height(self) -> float:
        """h = √(σ² − a²/3): height of the centre of a flowing sphere resting in a hollow, above the centre plane."""
        return math.sqrt(self.sigma**2 - self.spacing**2 / 3.0)

    @property
    def spheres_per_area(self) -> float:
        """ν_w = 2/(√3 a²), wall spheres per unit area."""
        return 2.0 / (math.sqrt(3.0) * self.spacing**2)

    def theta_max(self, psi: Any) -> Any:
        """θ_max(ψ) = arcsin(min(1, c0/max_j cos(ψ + row_angle − ψ_j))), c0 = a/(2σ)."""
        c0 = self.spacing / (2.0 * self.sigma)
        psi = np.asarray(psi, dtype=float)
        cmax = np.max(np.cos(psi[..., None] + self.row_angle - NEIGHBOUR_ANGLES), axis=-1)
        return np.arcsin(np.minimum(1.0, c0 / cmax))

    def accessible(self, k: np.ndarray) -> np.ndarray:
        """True where a unit normal k (last axis: x along the slip, y, z out of the wall) is reachable.

        Written from the distances to the neighbour centres (not from :meth:`theta_max`), so that the
        two can check each other.
        """
        centre = self.sigma * k
        ok = k[..., 2] >= 0.0
        r = self.row_angle
        a1 = self.spacing * np.array([math.cos(-r), math.sin(-r), 0.0])
        a2 = self.spacing * np.array([math.cos(math.pi / 3.0 - r), math.sin(math.pi / 3.0 - r), 0.0])
        for i in range(-2, 3):
            for j in range(-2, 3):
                if i or j:  # every other wall sphere of the first two shells
                    ok &= np.linalg.norm(centre - (i * a1 + j * a2), axis=-1) >= self.sigma
        return ok


class WallFluxes(NamedTuple):
    """Ratios of the bumpy-wall fluxes (module docstring): S/N, Q/(N√T), D/(N√T), and N/(ν_w n_w σ² m(1 + e_w) T)."""

    shear_over_normal: Any
    energy_over_normal: Any
    dissipation_over_normal: Any
    normal_scale: Any


def _moments(z: Any) -> tuple[Any, Any]:
    """E[w²; w < 0] and E[|w|³; w < 0] for w ~ N(z, 1): with y = −w ~ N(m, 1), m = −z,
    E[y²; y > 0] = (1 + m²)Φ(m) + m φ(m),  E[y³; y > 0] = (m³ + 3m)Φ(m) + (m² + 2)φ(m)."""
    xp = namespace(z)
    if is_jax(z):
        from jax.scipy.special import ndtr as cdf_of
    else:
        cdf_of = ndtr
    m = -z
    cdf = cdf_of(m)
    pdf = xp.exp(-0.5 * m * m) / math.sqrt(2.0 * math.pi)
    return (1.0 + m * m) * cdf + m * pdf, (m**3 + 3.0 * m) * cdf + (m * m + 2.0) * pdf


@lru_cache(maxsize=64)
def _nodes(wall: BumpyWall, n_psi: int, n_theta: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Quadrature nodes on the accessible cap: (k_x, cos θ, weight dΩ) with ψ in 2π/n_psi midpoint panels
    (the cap boundary has kinks at the neighbour directions; panels of 60°/m put them on panel edges) and
    Gauss–Legendre in θ ∈ [0, θ_max(ψ)]."""
    panels = 6 * max(1, n_psi // 6)
    xg, wg = np.polynomial.legendre.leggauss(8)
    edges = np.linspace(0.0, 2.0 * math.pi, panels + 1) - wall.row_angle
    psi = (0.5 * (edges[1:] + edges[:-1])[:, None] + 0.5 * np.diff(edges)[:, None] * xg).ravel()
    wpsi = (0.5 * np.diff(edges)[:, None] * wg).ravel()
    tmax = wall.theta_max(psi)
    xt, wt = np.polynomial.legendre.leggauss(n_theta)
    theta = 0.5 * tmax[:, None] * (xt + 1.0)
    weight = wpsi[:, None] * 0.5 * tmax[:, None] * wt * np.sin(theta)
    kx = np.sin(theta) * np.cos(psi)[:, None]
    return kx.ravel(), np.cos(theta).ravel(), weight.ravel(), psi


def wall_fluxes(wall: BumpyWall, slip_ratio: Any, restitution: float, *, n_psi: int = 24,
                n_theta: int = 24) -> WallFluxes:
    """S/N, Q/(N√T) and D/(N√T) of the bumpy wall at slip ratio v/√T (NumPy or JAX array) and wall restitution e_w.

    Quadrature of the module's integrals (error below 1e-10 at the defaults for the shared wall, tested
    against doubled node counts).
    """
    check_range("wall restitution coefficient restitution", restitution, low=0.0, high=1.0, low_open=True)
    s = asarray(slip_ratio)
    check_range("slip ratio v/sqrt(T)", s)
    xp = namespace(s)
    kx, cos_t, weight = (like(x, s) for x in _nodes(wall, n_psi, n_theta)[:3])
    m2, m3 = _moments(s[..., None] * kx)
    normal = xp.sum(m2 * cos_t * weight, axis=-1)
    shear = -xp.sum(m2 * kx * weight, axis=-1)
    dissipation = 0.5 * (1.0 - restitution) * xp.sum(m3 * weight, axis=-1)
    return WallFluxes(shear / normal, (s * shear - dissipation) / normal, dissipation / normal, normal)


def wall_conditions(wall: BumpyWall, normal_stress: Any, temperature: Any, slip: Any,
                    restitution: float) -> tuple[Any, Any]:
    """(S, Q): shear stress of the flow on the wall along the slip, and flux of fluctuation energy into the flow.

    ``normal_stress`` N [Pa] and ``temperature`` θ [m²/s²] at the wall, ``slip`` v [m/s] the mean velocity of
    the flow relative to the wall (signed, along the wall).  S = N F(v/√θ) [Pa], Q = N √θ G(v/√θ) [W/m²];
    the wall drags the flow with −S.  NumPy or JAX arrays (broadcast together).
    """
    xp = namespace(normal_stress, temperature, slip)
    root = xp.sqrt(temperature)
    f = wall_fluxes(wall, slip / root, restitution)
    return normal_stress * f.shear_over_normal, normal_stress * root * f.energy_over_normal
