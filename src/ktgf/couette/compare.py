"""Model comparison with a DEM planar Couette profile, the case read from the DEM file's header.

The DEM format (``shared/data/dem_couette_e0.9_phi0.50.csv``, README there; read by
:func:`ktgf.data.read_couette`): frictionless spheres (d = m = 1, ρ_s = 6/π), bumpy walls
with sphere centres at y = ±H/2 moving at ±U/2; the header states e, the mean φ over the slab
between the planes tangent to the wall spheres, H, U and the wall stresses.  The continuum cell is
that slab: gap H − d with the same inventory.

Wall calibration (stated in every output): Johnson–Jackson walls with e_w = e (the DEM's
particle–wall restitution) and the specularity φ' fitted **per model** so that the model's
velocity at the outermost occupied DEM bins (|y| = 9.25 in the shared file) equals the DEM value
there (mean of both walls).  One scalar per model is fitted to one number; the profiles (u, φ, √θ)
and the wall stresses are predictions.  A model read from a model file that holds walls
(``ktgf calibrate`` on Couette data) keeps them instead.

Bumpy walls (``wall="bumpy"``): the DEM's own walls, a layer of fixed spheres whose diameter and gap the
file's header states (:func:`dem_bumpy_wall`), with e_w = e and the conditions of
:func:`ktgf.couette.walls.bumpy_wall_fluxes`: nothing is fitted, so every number is a prediction.  The
continuum cell is then the layer the sphere centres can reach, |y| ≤ H/2 − h with h the height of a sphere
resting in a hollow of the wall, holding the same particles (:func:`bumpy_dem_case`): the kinetic theory's
fields are those of the centres, and the wall condition is written for the centres in contact with the wall
spheres.  (The Johnson–Jackson cell keeps the slab between the planes tangent to the wall spheres; the
wall stresses are sensitive to this choice, ``docs/dense.md`` §5.1.)
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..data import CouetteCase, CouetteData, read_couette
from ..closures import PAPER_MODELS, get_model
from ..errors import ConvergenceError, InputError
from .geometry import PlanarCell
from .run import Material, run
from .walls import Wall


#: The profile and case of a DEM Couette file (header fields checked, one-line errors).
DemProfile = CouetteData


WALL_KINDS = ("johnson-jackson", "bumpy")


def dem_bumpy_wall(case: CouetteCase, name: str = "the DEM file") -> Wall:
    """The DEM cell's wall as a bumpy wall: wall-sphere diameter and gap from the header, e_w = e (nothing fitted)."""
    if case.wall_sphere_diameter is None or case.wall_sphere_gap is None:
        raise InputError(f"{name}: the header does not state the wall spheres (a line like '# geometry: ... walls = one "
                         "hexagonal close-packed layer of 168 touching spheres each (d = 1, ...)'), needed by wall = bumpy")
    return Wall.of_type("bumpy", restitution=case.e, wall_sphere_diameter=case.wall_sphere_diameter,
                        wall_sphere_gap=case.wall_sphere_gap)


def bumpy_dem_case(case: CouetteCase, wall: Wall) -> CouetteCase:
    """The DEM case on the layer the sphere centres can reach between bumpy walls: gap H − 2h, same particles.

    h = √(σ² − a²/3) (:attr:`ktgf.closures.bumpy_wall.BumpyWall.resting_height`, in d) is the height of the
    centre of a sphere resting in a hollow of the wall above the wall-sphere centres, the farthest a centre
    can go; the header's mean φ is over the slab H − d (``case.gap``), so φ̄' = φ̄ (H − d)/(H − 2h).
    """
    gap = case.gap + case.d - 2.0 * wall.spheres.resting_height * case.d
    return dataclasses.replace(case, gap=gap, mean_phi=case.mean_phi * case.gap / gap)


def dem_cell(specularity: float, model: Any, case: CouetteCase, *, wall_restitution: float | None = None,
             n_cells: int = 200, stretch: float = 1.5, start=None, wall: Wall | None = None):
    """The continuum counterpart of a DEM cell with JJ walls of the given specularity (e_w = e by default), or ``wall``."""
    if wall is None:
        wall = Wall(specularity=specularity, restitution=case.e if wall_restitution is None else wall_restitution)
    return run(model, PlanarCell(case.gap, case.wall_speed), wall, wall, case.mean_phi,
               Material(case.d, case.rho_s, case.e), n_cells=n_cells, stretch=stretch, start=start)


def _u_at(ds, y: float) -> float:
    return float(np.interp(y, ds["y"].values, ds["u"].values))


def calibrate_specularity(model: Any, dem: CouetteData, *, n_cells: int = 200, bounds=(1e-3, 1.0)) -> tuple[float, Any]:
    """Specularity such that u(y = slip_y) = the DEM's (bisection in ln φ'); returns (φ', Dataset)."""
    from scipy.optimize import brentq

    y, target = dem.slip_y, dem.slip_speed()
    cache: dict[float, Any] = {}

    def f(log_s: float) -> float:
        ds = dem_cell(math.exp(log_s), model, dem.case, n_cells=n_cells)
        cache[log_s] = ds
        return _u_at(ds, y) - target

    lo, hi = math.log(bounds[0]), math.log(bounds[1])
    flo, fhi = f(lo), f(hi)
    if flo * fhi > 0:  # the target is out of reach: take the closer end and say so through the value
        best = lo if abs(flo) < abs(fhi) else hi
        return math.exp(best), cache[best]
    root = brentq(f, lo, hi, xtol=1e-4)
    ds = cache.get(root)
    return math.exp(root), ds if ds is not None else dem_cell(math.exp(root), model, dem.case, n_cells=n_cells)


def profile_errors(ds, dem: CouetteData) -> dict[str, float]:
    """RMS differences over the DEM bins of u/U, φ and √θ/U (model interpolated to the bin centres)."""
    U = dem.case.wall_speed
    y = ds["y"].values
    out = {}
    for name, model_v, dem_v in (
        ("u/U", ds["u"].values / U, dem.u / U),
        ("phi", ds["phi"].values, dem.phi),
        ("sqrt(theta)/U", np.sqrt(ds["theta"].values) / U, np.sqrt(dem.theta) / U),
    ):
        out[name] = float(np.sqrt(np.mean((np.interp(dem.y, y, model_v) - dem_v) ** 2)))
    return out


def wall_stresses(ds) -> tuple[float, float]:
    """|wall shear stress| and pressure at the walls (means of both walls) of a planar Couette Dataset."""
    return float(np.mean(np.abs(ds["wall_shear_stress"].values))), float(0.5 * (ds["p"].values[0] + ds["p"].values[-1]))


def compare_with_dem(dem_path: str | Path, models=PAPER_MODELS, *, n_cells: int = 200,
                     walls: dict[str, dict[str, float]] | None = None,
                     wall: str = "johnson-jackson") -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Each model in the DEM file's case: specularity calibrated on the DEM slip (or ``walls[name]``), errors, wall stresses.

    ``models`` are registry names or :class:`~ktgf.closures.Model` objects.  Returns (rows, extra)
    with one row per model: φ', RMS profile errors, wall shear stress ``tau_wall`` and pressure
    ``p`` with the DEM's ``tau_wall_dem``, ``p_dem`` and relative errors, max φ and ``valid``
    (converged and max φ below φ_rcp).  A model whose solve fails gets a row saying so.
    ``wall="bumpy"``: every model between the DEM's bumpy walls (:func:`dem_bumpy_wall`; φ' is then NaN and
    ``walls`` is not used) on the layer of the centres (:func:`bumpy_dem_case`; ``extra["cell"]``), nothing fitted.
    """
    if wall not in WALL_KINDS:
        raise InputError(f"wall = {wall!r} is unknown; valid: {', '.join(WALL_KINDS)}")
    dem = read_couette(dem_path)
    bumpy = dem_bumpy_wall(dem.case, dem.path.name) if wall == "bumpy" else None
    cell = dem.case if bumpy is None else bumpy_dem_case(dem.case, bumpy)
    walls = walls or {}
    rows, datasets = [], {}
    for item in models:
        m = get_model(item)
        row: dict[str, Any] = {"model": m.label or m.name}
        try:
            if bumpy is not None:
                spec = math.nan
                ds = dem_cell(spec, m, cell, n_cells=n_cells, wall=bumpy)
                how = (f"bumpy walls of the DEM ({dem.path.name}: spheres d_w = {bumpy.wall_sphere_diameter:g} d, gap "
                       f"{bumpy.wall_sphere_gap:g} d), e_w = {bumpy.restitution:g}, on the layer of the centres (gap "
                       f"{cell.gap:.4g} d, mean phi {cell.mean_phi:.4g}); nothing fitted")
            elif m.name in walls:
                w = walls[m.name]
                spec = float(w.get("specularity", math.nan))
                ds = dem_cell(spec, m, dem.case, wall_restitution=w.get("wall_restitution"), n_cells=n_cells)
                how = f"Johnson-Jackson walls from the model file: specularity {spec:.4g}, e_w = {w.get('wall_restitution', dem.case.e):.4g}"
            else:
                spec, ds = calibrate_specularity(m, dem, n_cells=n_cells)
                how = (f"Johnson-Jackson walls, e_w = {dem.case.e:g}, specularity {spec:.4g} fitted so that u(|y| = {dem.slip_y:g}) "
                       f"= {dem.slip_speed():.4f} (DEM {dem.path.name})")
        except ConvergenceError as exc:
            rows.append({**row, "specularity": math.nan, "rms_u/U": math.nan, "rms_phi": math.nan, "rms_sqrt(theta)/U": math.nan,
                         "tau_wall": math.nan, "tau_wall_dem": dem.tau_wall, "tau_error": math.nan, "p": math.nan,
                         "p_dem": dem.p_wall, "p_error": math.nan, "max_phi": math.nan, "valid": False,
                         "message": str(exc)[:120]})
            continue
        ds.attrs["calibration"] = how
        err = profile_errors(ds, dem)
        tau, p = wall_stresses(ds)
        rows.append({
            **row, "specularity": spec,
            "rms_u/U": err["u/U"], "rms_phi": err["phi"], "rms_sqrt(theta)/U": err["sqrt(theta)/U"],
            "tau_wall": tau, "tau_wall_dem": dem.tau_wall, "tau_error": tau / dem.tau_wall - 1.0,
            "p": p, "p_dem": dem.p_wall, "p_error": p / dem.p_wall - 1.0,
            "max_phi": float(ds.attrs["max_phi"]), "valid": bool(ds.attrs["physically_valid"]), "message": "",
        })
        datasets[m.name] = ds
    return rows, {"datasets": datasets, "dem": dem, "target_u": dem.slip_speed(), "case": dem.case, "cell": cell}


def dem_slip_target(dem: CouetteData) -> float:
    """|u| at the outermost occupied bins, averaged over both walls: the one DEM number the wall is fitted to."""
    return dem.slip_speed()


def report_profiles(model: Any, *, phi_mean: float, e: float, height: float, wall_speed: float, d: float,
                    rho_s: float, n_cells: int, dem_path: str | Path | None = None,
                    specularity: float = 0.1) -> Any:
    """Steady planar profiles for the report's Couette section (entry point of :mod:`ktgf.report.couette`).

    Johnson–Jackson walls with e_w = e.  With ``dem_path`` (a DEM Couette file) whose header
    describes this case, the specularity is fitted per model to the DEM slip as in
    :func:`compare_with_dem`; otherwise ``specularity`` is used.  ``attrs['wall']`` says which,
    ``attrs['valid']`` is 1 when max φ stays below φ_rcp.
    """
    dem = read_couette(dem_path) if dem_path is not None else None
    c = dem.case if dem is not None else None
    same = c is not None and all(math.isclose(a, b, rel_tol=1e-9) for a, b in
                                 ((phi_mean, c.mean_phi), (e, c.e), (height, c.gap), (wall_speed, c.wall_speed), (d, c.d), (rho_s, c.rho_s)))
    if same:
        spec, ds = calibrate_specularity(get_model(model), dem, n_cells=n_cells)
        wall = (f"Johnson–Jackson, e_w = {e:g}, specularity φ' = {spec:.3g} fitted so that u(|y| = {dem.slip_y:g}) "
                f"= {dem.slip_speed():.3f} (the DEM slip)")
    else:
        w = Wall(specularity=specularity, restitution=e)
        ds = run(model, PlanarCell(height, wall_speed), w, w, phi_mean, Material(d, rho_s, e), n_cells=n_cells, stretch=1.5)
        wall = f"Johnson–Jackson, e_w = {e:g}, specularity φ' = {specularity:g} (not calibrated)"
    ds.attrs.update(wall=wall, valid=int(bool(ds.attrs["physically_valid"])))
    return ds
