"""Steady, fully developed gravity-driven layer on an inclined bumpy base (chute flow).

A layer of column height H lies on a base inclined at ζ to the horizontal; x points down the
slope, y is normal to the base (y = 0 at the base, y = H at the top of the column).  Steady
fully developed flow depends on y only (model.md §1 balances with ρ g = ρ_s φ g (sin ζ, −cos ζ)):

    dτ/dy = −ρ_s φ g sin ζ,          τ = η du/dy                     (down-slope momentum)
    dp/dy = −ρ_s φ g cos ζ                                           (normal momentum)
    d/dy (κ dθ/dy + ω dφ/dy) + τ du/dy − (3/2) ρ_s φ θ ζ0 = 0        (fluctuation energy)

Gravity does no work on the velocity fluctuations, so the energy balance is the Couette one.
With zero shear stress at the top both stresses are weights of the material above,

    τ(y) = ρ_s g sin ζ ∫_y^H φ dy',      p(y) − p(H) = ρ_s g cos ζ ∫_y^H φ dy',

so τ/(p − p(H)) = tan ζ at every height: the first integral the tests check.

Boundary conditions (choices, exposed as the ``base`` and ``top`` walls):

* base: a Johnson–Jackson wall at rest (bumpy: large specularity), :mod:`ktgf.couette.walls`;
* top: a *free surface* with zero shear stress and zero flux of fluctuation energy (the
  ``zero-flux`` wall type, the default).  Zero energy flux is the free-surface condition of
  Johnson, Nott & Jackson (1990, JFM 210, 501) and Anderson & Jackson (1992, JFM 241, 145) as we
  recall them (their text is not in the project library);
  a prescribed small θ (``Wall(momentum="free-slip", energy="prescribed", temperature=…)``) is
  allowed but makes the surface an energy sink that has no physical counterpart.
  With θ finite at the top, p = ρ_s φ θ p* vanishes only where φ does: the continuum free
  surface is an isothermal atmosphere φ ∝ exp(−g cos ζ y/θ) that ends only asymptotically.
  The column height H is therefore a numerical parameter: the top node carries the pressure
  p(H) of the dilute material (reported as ``top_pressure_fraction`` = p(H)/p(0)), and H is
  tall enough when that fraction is small.  The same column with a free-slip adiabatic lid is
  what a 3D box of height H with a gravity body force computes, so the two compare exactly.

The inventory is held fixed as in the Couette cell (mean φ over the column, i.e. the solid
depth S = φ̄ H, mass per unit base area ρ_s S).

Discretisation: the Couette finite volumes of :mod:`ktgf.couette.equations` with two changes.
The down-slope momentum rows get the body force V_i φ_i g sin ζ; the normal momentum rows are
written as differences of p, p_{i+1} − p_i + g cos ζ Δy (φ_i + φ_{i+1})/2 = 0 (scaled by
p_i + p_{i+1}), so that the discrete column satisfies exactly (to the solver tolerance)

    base traction = ρ_s g sin ζ Σ V_i φ_i,     p_0 − p_N = ρ_s g cos ζ Σ V_i φ_i

(the trapezoidal mass of the column is its control-volume inventory).  Units inside the
solver: lengths in d, velocities in √(gH), ρ_s = 1, so gravity is (d/H)(sin ζ, cos ζ).

Bagnold scaling: where the local energy balance holds (deep layers, away from the base and the
surface), the interior is a uniform-shear state at the solid fraction φ* with
|P_xy|/p (φ*) = tan ζ (:func:`ktgf.shear.steady.steady_shear`), θ = T(φ*) (γ̇ d)²,
so γ̇ ∝ √(p) ∝ √(H − y) and u ∝ H^{3/2} (Bagnold 1954; Silbert et al. 2001).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from ..closures import get_model
from ..errors import ConvergenceError, InputError
from ..validation import check_positive, check_range
from .equations import N_VARS, Problem
from .geometry import stretched_nodes
from .run import Material, to_dataset
from .solver import newton, pseudo_transient
from ..shear.steady import steady_temperature
from .walls import Wall

#: Default base: bumpy (fully diffuse) Johnson–Jackson wall.
BUMPY_BASE = Wall(specularity=1.0, restitution=0.9)
#: Default top: free surface (zero shear stress, zero energy flux).
FREE_SURFACE = Wall.of_type("zero-flux")


@dataclass(frozen=True)
class InclinedLayer:
    """Column of height H on a base inclined at ``angle_deg`` to the horizontal (module docstring).

    Parameters
    ----------
    depth : float
        Column height H [m] from the base to the top boundary (> 0).
    angle_deg : float
        Inclination ζ of the base [degrees], 0 < ζ < 90.
    gravity : float
        Acceleration of gravity g [m/s²] (> 0).
    """

    depth: float
    angle_deg: float
    gravity: float = 9.81
    kind = "chute"
    coordinate = "y"

    def __post_init__(self) -> None:
        check_positive("column depth H", self.depth, "m")
        check_range("inclination angle_deg", self.angle_deg, low=0.0, high=90.0, low_open=True, high_open=True,
                    why="degrees")
        check_positive("gravity g", self.gravity, "m/s^2")

    @property
    def gap(self) -> float:
        return self.depth

    @property
    def angle(self) -> float:
        """ζ in radians."""
        return math.radians(self.angle_deg)

    def velocity_scale(self) -> float:
        """√(gH) [m/s]: the free-fall velocity of the column, the solver's velocity unit."""
        return math.sqrt(self.gravity * self.depth)

    def solver_gravity(self, d: float) -> tuple[float, float]:
        """(g sin ζ, g cos ζ) in solver units (lengths in d, velocities in √(gH)): (d/H)(sin ζ, cos ζ)."""
        scale = d / self.depth
        return scale * math.sin(self.angle), scale * math.cos(self.angle)

    def bounds(self, d: float) -> tuple[float, float]:
        return 0.0, self.depth / d

    def wall_velocities(self) -> tuple[float, float]:
        """The base is at rest; the top (free surface) velocity is not prescribed (0 is a placeholder)."""
        return 0.0, 0.0

    # planar metrics (dimensionless y)
    def angular(self, u: np.ndarray, x: np.ndarray) -> np.ndarray:
        return u

    def flux_metric(self, x: np.ndarray) -> np.ndarray:
        return np.ones_like(x)

    stress_metric = volume_metric = flux_metric

    def control_volumes(self, x: np.ndarray) -> np.ndarray:
        edges = np.concatenate([x[:1], 0.5 * (x[1:] + x[:-1]), x[-1:]])
        return np.diff(edges)

    def centripetal(self, u: np.ndarray, x: np.ndarray, phi: np.ndarray, p: np.ndarray) -> np.ndarray:
        return np.zeros_like(u)  # the normal-momentum rows are replaced in ChuteProblem

    def shear_rate(self, u: np.ndarray, x: np.ndarray) -> np.ndarray:
        return np.gradient(u, x, edge_order=2)

    def describe(self) -> dict[str, float | str]:
        return {"geometry": self.kind, "depth": self.depth, "angle_deg": self.angle_deg, "gravity": self.gravity}


@dataclass
class ChuteProblem(Problem):
    """The discrete inclined layer: the Couette :class:`Problem` plus gravity (module docstring).

    ``gravity`` is (g sin ζ, g cos ζ) in solver units; ``bottom`` is the base, ``top`` the free surface.
    """

    gravity: tuple[float, float] = (0.0, 0.0)

    def terms(self, X: np.ndarray) -> dict[str, np.ndarray]:
        t = super().terms(X)
        t["body_force"] = self.V * t["phi"] * self.gravity[0]
        return t

    def residual(self, X: np.ndarray, t: dict[str, np.ndarray] | None = None) -> np.ndarray:
        t = self.terms(X) if t is None else t
        batch = t["u"].shape[:-1]
        R = super().residual(X, t).reshape(*batch, self.n, N_VARS)
        free = np.ones(self.n, dtype=bool)
        for k, i in ((0, 0), (1, self.n - 1)):
            if self.walls[k].momentum == "prescribed":  # a Dirichlet row has no source
                free[i] = False
        R[..., free, 0] += t["body_force"][..., free]
        p, phi = t["p"], t["phi"]
        R[..., :-1, 2] = ((np.diff(p) + self.gravity[1] * self.dx * 0.5 * (phi[..., 1:] + phi[..., :-1]))
                          / (p[..., 1:] + p[..., :-1]))
        return R.reshape(*batch, self.n * N_VARS)

    def residual_scales(self, t: dict[str, np.ndarray]) -> np.ndarray:
        S = super().residual_scales(t).reshape(self.n, N_VARS)
        S[:, 0] = max(S[0, 0], float(np.abs(t["body_force"]).max()))
        return S.ravel()


def build_chute(model: Any, layer: InclinedLayer, mean_phi: float, material: Material, *,
                base: Wall = BUMPY_BASE, top: Wall = FREE_SURFACE, n_cells: int = 64,
                stretch: float = 0.0) -> ChuteProblem:
    """The discrete inclined layer in solver units (see :func:`solve_chute` for the parameters)."""
    model = get_model(model)
    check_range("mean solid fraction mean_phi", mean_phi, low=0.0, high=model.phi_max, low_open=True,
                high_open=True, why=f"packing limit of {model.label or model.name}")
    if top.momentum == "prescribed":
        raise InputError("top wall momentum condition 'prescribed' is not valid for a chute: the top is a free "
                         "surface (valid: free-slip, johnson-jackson)")
    x0, x1 = layer.bounds(material.d)
    if x1 - x0 < 4.0:
        raise InputError(f"column depth H = {layer.depth:g} m is out of range: valid H >= 4 particle diameters "
                         f"({4 * material.d:g} m)")
    x = stretched_nodes(x0, x1, n_cells, stretch)
    return ChuteProblem(model, layer, base, top, float(mean_phi), material.e, x, v_scale=layer.velocity_scale(),
                        gravity=layer.solver_gravity(material.d))


def bagnold_start(problem: ChuteProblem) -> np.ndarray:
    """Uniform φ̄ with the Bagnold profile of a uniform-shear interior as the Newton start.

    Shear stress τ = g sin ζ φ̄ (H − y) (weight above), and in uniform shear η = c γ̇ with
    c = η* η0/√θ · √T (T = θ/(γ̇d)²), so γ̇ = √(τ/c); u integrates γ̇ from a no-slip base;
    θ = T γ̇² with a floor near the top where γ̇ → 0.
    """
    x = problem.x
    e = min(problem.e, 0.999)
    phi = min(problem.mean_phi, 0.95 * problem.phi_max)
    ratio = float(steady_temperature(problem.model, phi, e))
    r = problem.model.reduced(phi, e)
    c = float(r.eta) * (5.0 * math.sqrt(math.pi) / 96.0) * math.sqrt(ratio)  # η/γ̇ with d = ρ_s = 1
    tau = problem.gravity[0] * phi * (x[-1] - x)
    gdot = np.sqrt(tau / c)
    u = np.concatenate([[0.0], np.cumsum(0.5 * (gdot[1:] + gdot[:-1]) * np.diff(x))])
    theta = np.maximum(ratio * gdot**2, 0.05 * ratio * gdot.max() ** 2)
    return problem.pack(u, theta, np.full(x.size, phi))


def solve_chute_problem(problem: ChuteProblem, X0: np.ndarray | None = None, *, tol: float = 1e-10,
                        max_iter: int = 80) -> tuple[np.ndarray, dict[str, Any]]:
    """Newton from the Bagnold start, pseudo-transient continuation if that fails."""
    start = bagnold_start(problem) if X0 is None else X0
    X, rep = newton(problem, start, tol=tol, max_iter=max_iter)
    history = list(rep.history)
    if rep.converged:
        return X, {"iterations": rep.iterations, "residual": rep.residual, "history": history, "method": "newton"}
    dt0 = 0.1 * (problem.x[-1] - problem.x[0]) / max(float(np.abs(problem.unpack(start)[0]).max()), 1e-6)
    X, rep2 = pseudo_transient(problem, start, dt0=dt0)
    history += rep2.history
    if rep2.converged:
        return X, {"iterations": rep.iterations + rep2.iterations, "residual": rep2.residual, "history": history,
                   "method": "pseudo-transient"}
    raise ConvergenceError(f"chute solver did not converge (Newton: {rep.message}; pseudo-transient: {rep2.message}); "
                           f"last relative residual {rep2.residual:.3g}")


def chute_dataset(problem: ChuteProblem, X: np.ndarray, material: Material, *, phi_rcp: float = 0.64,
                  info: dict[str, Any] | None = None) -> xr.Dataset:
    """The Couette Dataset (:func:`ktgf.couette.run.to_dataset`) with the chute's own wall and budget terms."""
    ds = to_dataset(problem, X, material, phi_rcp=phi_rcp, info=info)
    layer, d, rho = problem.geometry, material.d, material.rho_s
    V = layer.velocity_scale()
    t = problem.terms(X)
    stress_scale, flux_scale = rho * V**2, rho * V**3
    u, phi, p = t["u"], t["phi"], t["p"]
    # the base half-cell carries weight, so the base traction is the wall flux itself
    tau_wall = t["F_wall"].copy()
    ds["wall_shear_stress"] = ("wall", tau_wall * stress_scale, {"units": "Pa"})
    slip_work = np.array([tau_wall[0] * t["slip"][0], 0.0])
    power_in = float(problem.V @ (phi * u)) * problem.gravity[0]
    dissipation = float(problem.V @ t["gamma"])
    heat_in = ds["wall_heat_flux"].values / flux_scale
    budget = power_in - dissipation + float(np.sum(heat_in - slip_work))
    inventory = float(problem.V @ phi)
    mass_above = np.concatenate([np.cumsum((0.5 * (phi[1:] + phi[:-1]) * problem.dx)[::-1])[::-1], [0.0]])
    shear_stress = ds["shear_stress"].values
    ds["mass_above"] = ("y", mass_above * d, {"long_name": "solid depth above y, int_y^H phi dy'", "units": "m"})
    with np.errstate(divide="ignore", invalid="ignore"):
        ds["stress_ratio"] = ("y", shear_stress / (ds["p"].values - ds["p"].values[-1]),
                              {"long_name": "shear stress / (p - p(H)): tan(angle) for a steady layer", "units": "1"})
    ds.attrs.update({
        "power_in": power_in * flux_scale,
        "bulk_dissipation": dissipation * flux_scale,
        "energy_budget_relative_error": abs(budget) / abs(power_in),
        "angle_deg": layer.angle_deg,
        "tan_angle": math.tan(layer.angle),
        "solid_depth": inventory * d,
        "surface_velocity": float(u[-1] * V),
        "base_slip_velocity": float(t["slip"][0] * V),
        "top_pressure_fraction": float(p[-1] / p[0]),
        "weight_normal": rho * layer.gravity * math.cos(layer.angle) * inventory * d,
        "weight_tangential": rho * layer.gravity * math.sin(layer.angle) * inventory * d,
    })
    return ds


def solve_chute(model: Any, *, depth: float, angle_deg: float, mean_phi: float, material: Material,
                base: Wall = BUMPY_BASE, top: Wall = FREE_SURFACE, gravity: float = 9.81, n_cells: int = 64,
                stretch: float = 0.0, phi_rcp: float = 0.64, tol: float = 1e-10,
                start: xr.Dataset | None = None) -> xr.Dataset:
    """Steady fully developed inclined layer of ``model``: u(y), φ(y), θ(y) and diagnostics (SI units).

    Parameters
    ----------
    model : str or Model
        Registered model name or :class:`~ktgf.closures.Model`.
    depth : float
        Column height H [m] (base at y = 0, free surface at y = H).
    angle_deg : float
        Inclination of the base [degrees].
    mean_phi : float
        Mean solid fraction over the column (fixed inventory; solid depth φ̄ H).
    material : Material
        Particle diameter d [m], density ρ_s [kg/m³], restitution e.
    base, top : Wall
        Base wall (default bumpy Johnson–Jackson, specularity 1, e_w = 0.9) and top boundary
        (default free surface: zero shear stress, zero energy flux).
    gravity : float
        g [m/s²].
    n_cells, stretch : grid intervals and tanh clustering towards base and top.
    start : Dataset, optional
        A previous solution (any grid, any depth) to start Newton from (continuation): its
        profiles in units of √(gH) are mapped on y/H.

    Returns
    -------
    xarray.Dataset
        The Couette variables (``u``, ``phi``, ``theta``, ``p``, ``shear_rate``, ``shear_stress``,
        ``heat_flux``, ``wall_*`` with wall = bottom (base), top (surface)) plus ``mass_above``
        and ``stress_ratio`` = τ/(p − p(H)) (= tan ζ for a steady layer); attributes include
        ``solid_depth``, ``surface_velocity``, ``base_slip_velocity``, ``top_pressure_fraction``,
        ``weight_normal``/``weight_tangential`` [Pa] and ``energy_budget_relative_error``.

    Raises
    ------
    InputError
        Invalid parameters (one line naming the field, value and valid range).
    ConvergenceError
        Newton and pseudo-transient continuation both failed.
    """
    layer = InclinedLayer(depth, angle_deg, gravity)
    problem = build_chute(model, layer, mean_phi, material, base=base, top=top, n_cells=n_cells, stretch=stretch)
    X0 = None
    if start is not None:  # continuation: the previous profiles in solver units against y/H
        V, V0 = layer.velocity_scale(), float(start.attrs["velocity_scale"])
        s, s0 = problem.x / problem.x[-1], start["y"].values / start["y"].values[-1]
        u, theta, phi = (np.interp(s, s0, start[k].values) for k in ("u", "theta", "phi"))
        X0 = problem.pack(u / V0, theta / V0**2, np.minimum(phi, 0.999 * problem.phi_max))
    X, info = solve_chute_problem(problem, X0, tol=tol)
    return chute_dataset(problem, X, material, phi_rcp=phi_rcp, info=info)
