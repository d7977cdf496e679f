"""Bumpy walls (a layer of fixed spheres) in the 1D Couette solver: limits, energy balance, bad input, DEM validation.

The wall conditions are S = N F(v/√θ) and q·n = N √θ G(v/√θ, e_w) of :mod:`ktgf.closures.bumpy_wall` (tested
there against a Monte Carlo of single collisions), N the model's pressure at the wall.  Shared file for the
validation: dem_couette_e0.9_phi0.50.csv (README: walls of touching spheres of the particles' size, e = 0.9 for
particle-wall contacts, τ = 0.65518, p_yy = 2.6588); it chooses nothing here — the wall geometry comes from its
header, e_w = e, and no parameter is fitted.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.calibration_synthetic import couette_header, with_header
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.closures.bumpy_wall import BumpyWall, wall_fluxes
from ktgf.couette import PlanarCell, Wall
from ktgf.couette.compare import bumpy_dem_case, compare_with_dem, dem_bumpy_wall, dem_cell
from ktgf.couette.config import parse_config
from ktgf.couette.run import Material, run
from ktgf.data import read_couette
from ktgf.errors import InputError

U = 10.0  # DEM units: d = 1, ρ_s = 6/π, walls at ±U/2
DEM_UNITS = Material(1.0, 6.0 / math.pi, 0.9)


@pytest.fixture(scope="module")
def dem_path(data_dir):
    return data_dir / "dem_couette_e0.9_phi0.50.csv"


def _cell(model: str, wall: Wall, mean_phi: float = 0.3):
    return run(model, PlanarCell(19.0, U), wall, wall, mean_phi, DEM_UNITS, n_cells=100)


@pytest.mark.analytic
def test_tiny_wall_spheres_are_a_frictionless_wall():
    """d_w/d → 0: the wall is flat and smooth, it cannot drag the flow: τ_w/p_w → 0, the flow comes to rest
    (u uniform) and each wall slides past it by U/2.  The traction never exceeds the wall's geometric
    limit F(∞) = lim S/N at large slip (the closure's own bound, ∝ d_w)."""
    lag, ratio = [], []
    for d_w in (0.1, 0.03, 0.01):
        ds = _cell("enskog", Wall.of_type("bumpy", restitution=1.0, wall_sphere_diameter=d_w))
        assert ds.attrs["physically_valid"], ds.attrs["validity"]
        tau, p = float(ds["wall_shear_stress"].values[0]), float(ds["p"].values[0])
        slip = ds["wall_slip"].values
        assert slip[0] == pytest.approx(-slip[1], rel=1e-9)  # symmetric cell
        lag.append(1.0 - abs(slip[0]) / (U / 2))
        ratio.append(abs(tau) / p)
        assert ratio[-1] < wall_fluxes(BumpyWall(d_w=d_w), 1e3, 1.0).shear_over_normal
        assert np.ptp(ds["u"].values) / U == pytest.approx(lag[-1], rel=1e-6)  # the part of U the walls do not slip
    assert lag[0] > lag[1] > lag[2] > 0.0 and lag[2] < 1e-3
    assert ratio[0] > ratio[1] > ratio[2] and ratio[2] < 0.01


@pytest.mark.analytic
@pytest.mark.parametrize("e_w", [1.0, 0.9])
def test_wall_work_equals_bulk_and_wall_dissipation(e_w):
    """Energy conservation of a converged cell between bumpy walls: the power of the walls τ_w U equals the
    dissipation by collisions in the bulk plus the collisional loss D at the two walls (D = 0 for e_w = 1),
    D taken from the closure at the solution's wall state; and the wall stress and heat flux are the
    closure's S = N F(v/√θ), Q = N √θ G at that state."""
    wall = Wall.of_type("bumpy", restitution=e_w)
    ds = _cell("dense", wall, mean_phi=0.5)
    assert ds.attrs["physically_valid"], ds.attrs["validity"]
    tau, p = ds["wall_shear_stress"].values, ds["p"].values[[0, -1]]
    theta, slip = ds["wall_theta"].values, ds["wall_slip"].values
    f = wall_fluxes(BumpyWall(), slip / np.sqrt(theta), e_w)
    np.testing.assert_allclose(np.abs(tau), p * np.abs(f.shear_over_normal), rtol=1e-9)
    np.testing.assert_allclose(ds["wall_heat_flux"].values, p * np.sqrt(theta) * f.energy_over_normal, rtol=1e-6)
    wall_loss = float(np.sum(p * np.sqrt(theta) * f.dissipation_over_normal))
    if e_w == 1.0:
        assert wall_loss == 0.0
    work = float(np.mean(np.abs(tau))) * U
    assert work == pytest.approx(ds.attrs["bulk_dissipation"] + wall_loss, rel=1e-8)


@pytest.mark.contract
def test_bad_bumpy_wall_input_is_one_line():
    with pytest.raises(InputError, match=r"wall_sphere_diameter = 0 is out of range: valid 0 < wall_sphere_diameter"):
        Wall.of_type("bumpy", wall_sphere_diameter=0.0)
    with pytest.raises(InputError, match=r"wall_sphere_gap = 0.8 is out of range: valid 0 <= wall_sphere_gap < 0.73"):
        Wall.of_type("bumpy", wall_sphere_gap=0.8)  # a sphere of the flow would fall between touching-size spheres
    with pytest.raises(InputError, match=r"wall_sphere_gap = -0.1 is out of range"):
        Wall(momentum="bumpy", energy="adiabatic", wall_sphere_gap=-0.1)
    with pytest.raises(InputError, match=r"wall momentum condition 'bumpy-ish' is unknown; valid: .*bumpy"):
        Wall(momentum="bumpy-ish")
    with pytest.raises(InputError, match=r"field 'walls.wall_sphere_diameter': Input should be greater than 0"):
        parse_config({"model": "ret", "mean_solid_fraction": 0.5, "restitution": 0.9, "particle_diameter": 1e-3,
                      "particle_density": 2500.0, "geometry": {"kind": "planar", "gap": 0.02, "wall_speed": 1.0},
                      "walls": {"type": "bumpy", "wall_sphere_diameter": -1.0}})


@pytest.mark.contract
def test_a_config_with_bumpy_walls_builds_them():
    cfg = parse_config({"model": "ret", "mean_solid_fraction": 0.5, "restitution": 0.9, "particle_diameter": 1e-3,
                        "particle_density": 2500.0, "geometry": {"kind": "planar", "gap": 0.02, "wall_speed": 1.0},
                        "walls": {"type": "bumpy", "restitution": 0.8, "wall_sphere_diameter": 2.0,
                                  "top": {"type": "johnson-jackson", "specularity": 0.2}}})
    bottom, top = cfg.walls.build_pair()
    assert (bottom.momentum, bottom.energy, bottom.restitution) == ("bumpy", "bumpy", 0.8)
    assert bottom.spheres == BumpyWall(d_w=2.0, gap=0.0)
    assert (top.momentum, top.specularity) == ("johnson-jackson", 0.2)
    assert "wall_sphere_diameter" not in top.describe()  # JJ walls keep their metadata


@pytest.mark.contract
def test_the_dem_walls_come_from_the_header(dem_path, tmp_path):
    """The shared file's header states touching wall spheres of d = 1; a header that does not state them is a
    one-line error for bumpy walls (exit 2 on the command line), and an unknown wall kind too."""
    wall = dem_bumpy_wall(read_couette(dem_path).case)
    assert (wall.momentum, wall.energy, wall.restitution) == ("bumpy", "bumpy", 0.9)
    assert wall.spheres == BumpyWall(d_w=1.0, gap=0.0)
    # the continuum cell is the layer the centres reach: H − 2√(2/3) d for touching equal spheres, same particles
    case = read_couette(dem_path).case
    cell = bumpy_dem_case(case, wall)
    assert cell.gap == pytest.approx(20.0 - 2.0 * math.sqrt(2.0 / 3.0), rel=1e-12)
    assert cell.mean_phi * cell.gap == pytest.approx(case.mean_phi * 19.0, rel=1e-12)
    other = with_header(dem_path, tmp_path / "gap.csv", couette_header().replace(
        "# geometry: walls of spheres,", "# geometry: walls = one hexagonal layer of 100 spheres each (d = 0.5, gap = 0.2),"))
    assert dem_bumpy_wall(read_couette(other).case).spheres == BumpyWall(d_w=0.5, gap=0.2)
    bare = with_header(dem_path, tmp_path / "bare.csv", couette_header())
    with pytest.raises(InputError, match="bare.csv: the header does not state the wall spheres"):
        compare_with_dem(bare, ["ret"], n_cells=40, wall="bumpy")
    with pytest.raises(InputError, match="wall = 'flat' is unknown; valid: johnson-jackson, bumpy"):
        compare_with_dem(dem_path, ["ret"], n_cells=40, wall="flat")
    r = CliRunner().invoke(app, ["couette", "compare", "--dem", str(bare), "--models", "ret", "--cells", "40",
                                 "-o", str(tmp_path / "c.png"), "--wall", "bumpy"])
    assert r.exit_code == 2 and "does not state the wall spheres" in r.output


@pytest.mark.dem
@pytest.mark.parametrize("model", ["dense", "proposed"])
def test_bumpy_walls_predict_the_dem_wall_layer(dem_path, model):
    """Nothing fitted: between the DEM's own bumpy walls the first occupied bin (|y| = 9.25) has the DEM's
    temperature within 15 % and the wall stress ratio τ/p within 10 % (the issue's uniform-shear goals for
    T and τ/p).  Johnson–Jackson walls fitted to the slip miss the first-bin temperature by 16 % on the same
    cell and 26 % on the slab to the tangent planes (dense; docs/dense.md §5.1), so this can fail."""
    dem = read_couette(dem_path)
    wall = dem_bumpy_wall(dem.case)
    ds = dem_cell(math.nan, model, bumpy_dem_case(dem.case, wall), n_cells=100, wall=wall)
    assert ds.attrs["physically_valid"], ds.attrs["validity"]
    y, theta = ds["y"].values, ds["theta"].values
    for i in (0, -1):
        assert np.interp(dem.y[i], y, theta) == pytest.approx(dem.theta[i], rel=0.15)
    ratio = float(np.mean(np.abs(ds["wall_shear_stress"].values))) / float(ds["p"].values[0])
    assert ratio == pytest.approx(dem.tau_wall / dem.p_wall, rel=0.10)
