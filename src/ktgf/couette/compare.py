"""Four-model comparison and comparison with the DEM planar Couette profile.

The DEM case (``shared/data/dem_couette_e0.9_phi0.50.csv``, README there): frictionless spheres
(d = m = 1, ρ_s = 6/π), e = 0.9, bumpy walls with sphere centres at y = ±10 moving at ±U/2,
U = 10, mean φ = 0.50 over the slab |y| ≤ 9.5 between the planes tangent to the wall spheres.
The continuum cell is that slab: H = 19 d with walls at ±9.5 and the same inventory.

Wall calibration (stated in every output): Johnson–Jackson walls with e_w = e = 0.9 (the DEM's
particle–wall restitution) and the specularity φ' fitted **per model** so that the model's
velocity at the first occupied DEM bin (|y| = 9.25) equals the DEM value there (mean of both
walls, 3.137).  One scalar per model is fitted to one number; the profiles (u, φ, √θ) and the
stresses are predictions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..closures import PAPER_MODELS, get_model
from ..errors import InputError
from .geometry import PlanarCell
from .run import Material, run
from .walls import Wall

DEM_FILE = "dem_couette_e0.9_phi0.50.csv"
DEM_CASE = {"gap": 19.0, "wall_speed": 10.0, "mean_phi": 0.50, "e": 0.9, "d": 1.0, "rho_s": 6.0 / math.pi,
            "calibration_y": 9.25}


@dataclass
class DemProfile:
    """DEM Couette profile (bins with particles) and the header's wall stresses."""

    y: np.ndarray
    phi: np.ndarray
    u: np.ndarray
    theta: np.ndarray
    tau_wall: float
    p_wall: float
    path: Path


def load_dem_couette(path: str | Path) -> DemProfile:
    """Read the DEM Couette CSV (comment header with the wall stresses, then columns)."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"DEM data file {str(path)!r} does not exist")
    header = [ln for ln in path.read_text().splitlines() if ln.startswith("#")]
    tau = p = math.nan
    for ln in header:
        if "wall shear stress tau" in ln:
            parts = ln.replace(";", " ").split()
            tau = float(parts[parts.index("tau") + 2])
            p = float(parts[parts.index("p_yy") + 2])
    import io

    body = "\n".join(ln for ln in path.read_text().splitlines() if not ln.startswith("#"))
    data = np.genfromtxt(io.StringIO(body), delimiter=",", names=True)
    keep = (data["phi"] > 0.05) & (data["theta"] > 0)
    return DemProfile(data["y"][keep], data["phi"][keep], data["ux"][keep], data["theta"][keep], tau, p, path)


def dem_cell(specularity: float, model: Any, *, n_cells: int = 200, stretch: float = 1.5, start=None):
    """The continuum counterpart of the DEM cell with JJ walls of the given specularity."""
    c = DEM_CASE
    wall = Wall(specularity=specularity, restitution=c["e"])
    return run(model, PlanarCell(c["gap"], c["wall_speed"]), wall, wall, c["mean_phi"],
               Material(c["d"], c["rho_s"], c["e"]), n_cells=n_cells, stretch=stretch, start=start)


def _u_at(ds, y: float) -> float:
    return float(np.interp(y, ds["y"].values, ds["u"].values))


def calibrate_specularity(model: Any, target_u: float, *, n_cells: int = 200, bounds=(1e-3, 1.0)) -> tuple[float, Any]:
    """Specularity such that u(y = calibration_y) = target_u (bisection in ln φ'); returns (φ', Dataset)."""
    from scipy.optimize import brentq

    y = DEM_CASE["calibration_y"]
    cache: dict[float, Any] = {}

    def f(log_s: float) -> float:
        ds = dem_cell(math.exp(log_s), model, n_cells=n_cells)
        cache[log_s] = ds
        return _u_at(ds, y) - target_u

    lo, hi = math.log(bounds[0]), math.log(bounds[1])
    flo, fhi = f(lo), f(hi)
    if flo * fhi > 0:  # the target is out of reach: take the closer end and say so through the value
        best = lo if abs(flo) < abs(fhi) else hi
        return math.exp(best), cache[best]
    root = brentq(f, lo, hi, xtol=1e-4)
    ds = cache.get(root)
    return math.exp(root), ds if ds is not None else dem_cell(math.exp(root), model, n_cells=n_cells)


def profile_errors(ds, dem: DemProfile) -> dict[str, float]:
    """RMS differences over the DEM bins of u/U, φ and √θ/U (model interpolated to the bin centres)."""
    U = DEM_CASE["wall_speed"]
    y = ds["y"].values
    out = {}
    for name, model_v, dem_v in (
        ("u/U", ds["u"].values / U, dem.u / U),
        ("phi", ds["phi"].values, dem.phi),
        ("sqrt(theta)/U", np.sqrt(ds["theta"].values) / U, np.sqrt(dem.theta) / U),
    ):
        out[name] = float(np.sqrt(np.mean((np.interp(dem.y, y, model_v) - dem_v) ** 2)))
    return out


def compare_with_dem(dem_path: str | Path, models=PAPER_MODELS, *, n_cells: int = 200) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Calibrate each model's specularity on the DEM slip and report its profile errors.

    Returns (rows, datasets) with one row per model: fitted φ', RMS errors, wall shear stress,
    wall normal stress and their DEM values, max φ and validity.
    """
    dem = load_dem_couette(dem_path)
    y0 = DEM_CASE["calibration_y"]
    target = dem_slip_target(dem)
    rows, datasets = [], {}
    for name in models:
        m = get_model(name)
        spec, ds = calibrate_specularity(m, target, n_cells=n_cells)
        ds.attrs["calibration"] = (
            f"Johnson-Jackson walls, e_w = {DEM_CASE['e']}, specularity {spec:.4g} fitted so that u(|y| = {y0}) "
            f"= {target:.4f} (DEM {dem.path.name})"
        )
        err = profile_errors(ds, dem)
        rows.append({
            "model": m.label or m.name, "specularity": spec,
            "rms_u/U": err["u/U"], "rms_phi": err["phi"], "rms_sqrt(theta)/U": err["sqrt(theta)/U"],
            "tau_wall": float(ds["wall_shear_stress"].values[0]), "tau_wall_dem": dem.tau_wall,
            "p": float(ds["p"].values[0]), "p_dem": dem.p_wall,
            "max_phi": float(ds.attrs["max_phi"]), "valid": bool(ds.attrs["physically_valid"]),
        })
        datasets[name] = ds
    return rows, {"datasets": datasets, "dem": dem, "target_u": target}


def compare_uniform_shear(path: str | Path, models=PAPER_MODELS) -> list[dict[str, Any]]:
    """Uniform-shear closed forms (model.md §9) against ``dem_uniform_shear.csv`` (γ̇ = 1, d = m = 1).

    Rows per (model, φ): T = θ/(γ̇d)² of the energy balance, η* = η/η0 and p* = p/(nT) of the
    model at the DEM's (φ, e), with the DEM values and relative differences.  The DEM states have
    a* = γ̇/ν0 ≈ 0.19–0.29, beyond strict Navier–Stokes order (README).
    """
    import io

    path = Path(path)
    if not path.exists():
        raise InputError(f"DEM data file {str(path)!r} does not exist")
    body = "\n".join(ln for ln in path.read_text().splitlines() if not ln.startswith("#"))
    data = np.atleast_1d(np.genfromtxt(io.StringIO(body), delimiter=",", names=True))
    from .uniform_shear import uniform_shear

    rows = []
    for name in models:
        m = get_model(name)
        for rec in data:
            phi, e = float(rec["phi"]), float(rec["e"])
            r = m.reduced(phi, e)
            us = uniform_shear(m, phi, e)
            T, eta, p = float(us.temperature_ratio), float(r.eta), float(r.p)
            rows.append({
                "model": m.label or m.name, "phi": phi, "e": e,
                "T": T, "T_dem": float(rec["T"]), "dT": T / float(rec["T"]) - 1,
                "eta*": eta, "eta*_dem": float(rec["eta_over_eta0"]), "deta*": eta / float(rec["eta_over_eta0"]) - 1,
                "p*": p, "p*_dem": float(rec["p_over_nT"]), "dp*": p / float(rec["p_over_nT"]) - 1,
            })
    return rows


def dem_slip_target(dem: DemProfile) -> float:
    """|u| at |y| = calibration_y, averaged over both walls: the one DEM number the wall is fitted to."""
    y0 = DEM_CASE["calibration_y"]
    return 0.5 * (abs(np.interp(y0, dem.y, dem.u)) + abs(np.interp(-y0, dem.y, dem.u)))


def report_profiles(model: Any, *, phi_mean: float, e: float, height: float, wall_speed: float, d: float,
                    rho_s: float, n_cells: int, dem_path: str | Path | None = None,
                    specularity: float = 0.1) -> Any:
    """Steady planar profiles for the report's Couette section (entry point of :mod:`ktgf.report.couette`).

    Johnson–Jackson walls with e_w = e.  With ``dem_path`` (the DEM Couette file) and the DEM case's
    parameters, the specularity is fitted per model to the DEM slip as in :func:`compare_with_dem`;
    otherwise ``specularity`` is used.  ``attrs['wall']`` says which, ``attrs['valid']`` is 1 when
    max φ stays below φ_rcp.
    """
    c = DEM_CASE
    dem_case = (phi_mean, e, height, wall_speed, d, rho_s) == (c["mean_phi"], c["e"], c["gap"], c["wall_speed"], c["d"], c["rho_s"])
    if dem_path is not None and dem_case:
        target = dem_slip_target(load_dem_couette(dem_path))
        spec, ds = calibrate_specularity(get_model(model), target, n_cells=n_cells)
        wall = (f"Johnson–Jackson, e_w = {e:g}, specularity φ' = {spec:.3g} fitted so that u(|y| = {c['calibration_y']}) "
                f"= {target:.3f} (the DEM slip)")
    else:
        w = Wall(specularity=specularity, restitution=e)
        ds = run(model, PlanarCell(height, wall_speed), w, w, phi_mean, Material(d, rho_s, e), n_cells=n_cells, stretch=1.5)
        wall = f"Johnson–Jackson, e_w = {e:g}, specularity φ' = {specularity:g} (not calibrated)"
    ds.attrs.update(wall=wall, valid=int(bool(ds.attrs["physically_valid"])))
    return ds
