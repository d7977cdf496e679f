"""Wall boundary conditions of the Couette cell (model.md §7).

Each wall has a momentum condition and an energy condition, chosen independently:

momentum
    ``johnson-jackson``  partial slip, η ∂u_t/∂n = (π√3/6) φ' (φ/φ_pk) ρ_s χ √θ u_sl
                         (Johnson & Jackson 1987, JFM 176, 67);
    ``prescribed``       the medium moves at the wall speed minus a prescribed lag (``slip``; 0 = no slip);
    ``free-slip``        zero shear stress;
    ``bumpy``            a wall of fixed spheres (diameter ``wall_sphere_diameter`` d_w/d, gap ``wall_sphere_gap``
                         s/d, hexagonal layer, rows along the slip): shear stress S = N F(u_sl/√θ), N the
                         flow's normal stress at the wall (:mod:`ktgf.closures.bumpy_wall`; no fitted parameter).
    A Johnson–Jackson wall with a wall friction angle δ_w > 0 (``friction_angle``) adds the frictional
    wall traction p_f tan δ_w in the direction of the slip (Johnson & Jackson 1987; :func:`jj_frictional_wall_stress`).
energy
    ``johnson-jackson``  q·n = G − D into the medium, with
                         D = (π√3/(4φ_pk)) (1 − e_w²) ρ_s φ χ θ^{3/2} (dissipation at the wall) and
                         G = (π√3/(6φ_pk)) φ' ρ_s φ χ √θ |u_sl|² (slip work);
    ``prescribed``       θ = ``temperature`` at the wall;
    ``adiabatic``        zero heat flux;
    ``bumpy``            q·n = N √θ G(u_sl/√θ, e_w) into the medium = S u_sl − D (slip work minus the collisional
                         dissipation at the wall spheres; :mod:`ktgf.closures.bumpy_wall`).

Choices made here (documented defaults, exposed as options):

* JJ write κ∂θ/∂n; our heat flux also has the ω∇φ term.  Option ``heat_flux``: ``"total"``
  (default) applies the condition to the whole flux q·n, so that the wall exchanges exactly
  G − D with the medium (the slip work τ·u_sl equals G: everything the walls do is either
  dissipated or conducted); ``"conductive"`` applies it literally to κ∂θ/∂n, the ω∂φ/∂n part
  (one-sided, second order) then passes through the wall in addition.  The two agree for
  models with ω = 0 (Enskog, Visc.div. by default).
* φ_pk in the JJ formulas is a wall parameter (``packing_limit``, default 0.64) rather than
  the model's RDF limit, so the same wall is applied to every model (the CS-based models have
  φ_max = 1).
* In the annular cell the shear stress is τ_rθ = η r d(u/r)/dr (the frame-invariant form).

The formulas below are pure functions of array arguments written with arithmetic operators only,
so the same code serves NumPy (the 1D Couette solver, :mod:`ktgf.couette.equations`) and JAX
(the walls of the 3D solver, :mod:`ktgf.solver.boundaries`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..closures.bumpy_wall import BumpyWall, wall_fluxes
from ..errors import InputError
from ..validation import check_positive, check_range

MOMENTUM_CONDITIONS = ("johnson-jackson", "prescribed", "free-slip", "bumpy")
ENERGY_CONDITIONS = ("johnson-jackson", "prescribed", "adiabatic", "bumpy")
HEAT_FLUX_FORMS = ("total", "conductive")
#: Preset wall types: (momentum, energy).
WALL_TYPES = {
    "johnson-jackson": ("johnson-jackson", "johnson-jackson"),
    "prescribed": ("prescribed", "prescribed"),
    "zero-flux": ("free-slip", "adiabatic"),
    "no-slip-adiabatic": ("prescribed", "adiabatic"),
    "bumpy": ("bumpy", "bumpy"),
}

SQRT3_PI = math.sqrt(3.0) * math.pi


@dataclass(frozen=True)
class Wall:
    """One wall of the cell.

    Parameters
    ----------
    momentum : {"johnson-jackson", "prescribed", "free-slip", "bumpy"}
    energy : {"johnson-jackson", "prescribed", "adiabatic", "bumpy"}
    specularity : float
        Johnson–Jackson specularity coefficient φ' (0 < φ' ≤ 1).
    restitution : float
        Particle–wall restitution e_w (0 < e_w ≤ 1).
    packing_limit : float
        φ_pk in the JJ formulas (default 0.64).
    slip : float
        Prescribed lag of the medium behind the wall [m/s] (``momentum="prescribed"``).
    temperature : float or None
        Prescribed granular temperature at the wall [m²/s²] (``energy="prescribed"``).
    heat_flux : {"total", "conductive"}
        Which flux the JJ energy condition sets (see the module notes).
    friction_angle : float
        Wall friction angle δ_w in degrees, 0 ≤ δ_w < 90 (default 0: the collisional JJ wall only).
        tan δ_w is the particle–wall friction coefficient (MFiX keyword ``PHI_W``: "phi_w = 11.31 means
        tan_phi_w = mu = 0.2").  It acts on the frictional normal stress p_f, so it needs a model with a
        frictional stress (friction option ``stress``).
    slip_regularisation : float
        ε_w of the frictional traction's direction u_sl/√(u_sl² + (ε_w U)²), U the cell's velocity
        difference (default 10⁻³, as the frictional viscosity's ``regularisation``).
    wall_sphere_diameter : float
        Bumpy wall: diameter of the wall spheres in units of the flowing particle diameter, d_w/d > 0 (default 1).
    wall_sphere_gap : float
        Bumpy wall: gap between neighbouring wall spheres in units of d, 0 ≤ s/d < √3 (1 + d_w/d)/2 − d_w/d
        (default 0, touching; above that bound a flowing sphere passes between them).
    """

    momentum: Literal["johnson-jackson", "prescribed", "free-slip", "bumpy"] = "johnson-jackson"
    energy: Literal["johnson-jackson", "prescribed", "adiabatic", "bumpy"] = "johnson-jackson"
    specularity: float = 0.5
    restitution: float = 0.9
    packing_limit: float = 0.64
    slip: float = 0.0
    temperature: float | None = None
    heat_flux: Literal["total", "conductive"] = "total"
    friction_angle: float = 0.0
    slip_regularisation: float = 1e-3
    wall_sphere_diameter: float = 1.0
    wall_sphere_gap: float = 0.0

    def __post_init__(self) -> None:
        if self.heat_flux not in HEAT_FLUX_FORMS:
            raise InputError(f"wall heat_flux {self.heat_flux!r} is unknown; valid: {', '.join(HEAT_FLUX_FORMS)}")
        if self.momentum not in MOMENTUM_CONDITIONS:
            raise InputError(f"wall momentum condition {self.momentum!r} is unknown; valid: {', '.join(MOMENTUM_CONDITIONS)}")
        if self.energy not in ENERGY_CONDITIONS:
            raise InputError(f"wall energy condition {self.energy!r} is unknown; valid: {', '.join(ENERGY_CONDITIONS)}")
        check_range("wall specularity coefficient specularity", self.specularity, low=0.0, high=1.0, low_open=True)
        check_range("wall restitution coefficient restitution", self.restitution, low=0.0, high=1.0, low_open=True)
        check_range("JJ packing limit packing_limit", self.packing_limit, low=0.0, high=1.0, low_open=True)
        check_range("prescribed wall slip slip", self.slip, why="m/s")
        check_range("wall friction angle friction_angle", self.friction_angle, low=0.0, high=90.0, high_open=True,
                    why="degrees")
        check_range("wall slip regularisation slip_regularisation", self.slip_regularisation, low=0.0, high=1.0,
                    low_open=True, why="fraction of the cell's velocity difference")
        check_range("bumpy wall sphere diameter wall_sphere_diameter", self.wall_sphere_diameter, low=0.0,
                    low_open=True, why="d_w/d, in units of the flowing particle diameter")
        largest_gap = math.sqrt(3.0) * 0.5 * (1.0 + self.wall_sphere_diameter) - self.wall_sphere_diameter
        check_range("bumpy wall sphere gap wall_sphere_gap", self.wall_sphere_gap, low=0.0, high=largest_gap,
                    high_open=True, why=f"s/d; at s/d >= {largest_gap:.4g} a flowing sphere passes between the wall "
                    f"spheres of d_w/d = {self.wall_sphere_diameter:g}")
        if self.energy == "prescribed":
            if self.temperature is None:
                raise InputError("wall temperature is required when the wall energy condition is 'prescribed'")
            check_positive("wall temperature temperature", self.temperature, "m^2/s^2")

    @classmethod
    def of_type(cls, wall_type: str, **params: object) -> Wall:
        """A wall from a preset name (``johnson-jackson``, ``prescribed``, ``zero-flux``, ``no-slip-adiabatic``)."""
        if wall_type not in WALL_TYPES:
            raise InputError(f"wall type {wall_type!r} is unknown; valid: {', '.join(WALL_TYPES)}")
        momentum, energy = WALL_TYPES[wall_type]
        return cls(momentum=momentum, energy=energy, **params)  # type: ignore[arg-type]

    def describe(self) -> dict[str, object]:
        """The wall's settings (the wall-sphere geometry only for a bumpy wall)."""
        out = dict(self.__dict__)
        if not self.is_bumpy:
            del out["wall_sphere_diameter"], out["wall_sphere_gap"]
        return out

    @property
    def is_bumpy(self) -> bool:
        return "bumpy" in (self.momentum, self.energy)

    @property
    def spheres(self) -> BumpyWall:
        """The wall-sphere layer of a bumpy wall (hexagonal, rows along the slip)."""
        return BumpyWall(d_w=self.wall_sphere_diameter, gap=self.wall_sphere_gap)


def jj_friction(wall: Wall, phi, chi, theta):
    """Coefficient c of the JJ shear stress τ_w = c u_sl (ρ_s = 1 units): (π√3/6) φ' (φ/φ_pk) χ √θ.

    Johnson & Jackson (1987), JFM 176, 67 (their momentum wall condition; model.md §7).
    """
    return (SQRT3_PI / 6.0) * wall.specularity * (phi / wall.packing_limit) * chi * theta**0.5


def jj_dissipation(wall: Wall, phi, chi, theta):
    """Collisional dissipation at the wall D = (π√3/(4φ_pk)) (1 − e_w²) φ χ θ^{3/2} (ρ_s = 1 units).

    Johnson & Jackson (1987), JFM 176, 67 (dissipation term of their energy wall condition; model.md §7).
    """
    return (SQRT3_PI / (4.0 * wall.packing_limit)) * (1.0 - wall.restitution**2) * phi * chi * theta**1.5


def jj_heat_loss(wall: Wall, phi, chi, theta, slip):
    """Heat flux out of the medium into the wall, D − G (ρ_s = 1 units): −q·n with n into the medium.

    G = c u_sl² is the slip work (c of :func:`jj_friction`), D the wall dissipation
    (:func:`jj_dissipation`); Johnson & Jackson (1987), model.md §7.  ``slip`` = u − u_wall (its square
    is used, so any tangential sign convention).
    """
    return jj_dissipation(wall, phi, chi, theta) - jj_friction(wall, phi, chi, theta) * slip * slip


def jj_frictional_wall_stress(wall: Wall, p_f, slip, slip_scale):
    """Frictional wall traction τ_w,f = p_f tan δ_w u_sl/√(u_sl² + s²), in the units of ``p_f``.

    Johnson & Jackson (1987), JFM 176, 67, wall condition for the tangential momentum: the frictional
    (enduring-contact) part of the wall shear stress is the frictional normal stress times the
    coefficient of wall friction tan δ_w, directed along the slip; the collisional part is
    :func:`jj_friction`.  (The equation is quoted as MFiX and OpenFOAM users know it, τ_w,f = p_f tan δ_w;
    the printed paper was not at hand to give its number.)  The slip direction u_sl/|u_sl| is
    regularised with s = ε_w U (``slip_scale``), as the rate-independent frictional viscosity is
    (``docs/friction.md`` §8).  Exactly 0 for δ_w = 0.
    """
    return p_f * math.tan(math.radians(wall.friction_angle)) * slip / (slip * slip + slip_scale * slip_scale) ** 0.5


def bumpy_wall_fluxes(wall: Wall, normal_stress, theta, slip):
    """(S, D − Q, D) of a bumpy wall: shear stress along the slip, heat flux out of the medium, wall dissipation.

    S = N F(v/√θ), Q = N √θ G(v/√θ, e_w) = S v − D with F, G of :func:`ktgf.closures.bumpy_wall.wall_fluxes` (the
    kinetics of Maxwellian spheres hitting the wall's spheres; derivation and tests there, ``docs/dense_physics.md``
    §6).  ``normal_stress`` N is the flow's normal stress at the wall, ``theta`` θ and ``slip`` v = u − u_wall
    in any consistent units (S in those of N; D − Q and D in N × velocity).  NumPy arrays; a non-finite state (a
    Newton trial point) gives NaN instead of an input error, so the solver's line search can reject it.
    """
    with np.errstate(all="ignore"):
        root = np.sqrt(theta)
        ratio = np.asarray(slip / root, dtype=float)
    if not np.all(np.isfinite(ratio)) or not np.all(np.isfinite(normal_stress)):
        nan = np.full(np.shape(ratio), np.nan)
        return nan, nan, nan
    f = wall_fluxes(wall.spheres, ratio, wall.restitution)
    return (normal_stress * f.shear_over_normal, -normal_stress * root * f.energy_over_normal,
            normal_stress * root * f.dissipation_over_normal)
