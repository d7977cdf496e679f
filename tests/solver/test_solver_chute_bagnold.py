"""Deep inclined layers (the Bagnold regime) in the 1D solver and in the 3D solver.

Oracle: Bagnold's u(H) ∝ H^{3/2} (Bagnold 1954; Silbert et al. 2001, Phys. Rev. E 64, 051302),
which the model predicts where the interior can be a uniform-shear state, i.e. where tan ζ lies
in the range of the uniform-shear stress ratio |P_xy|/p of the model (docs/chute.md).  For RET at
e = 0.9 that range is tan 15.3° … tan 19.3°, so the 3D checks run at 18° (the shallow 3D depth
series of test_solver_chute_depth.py runs at 25°, outside it).  ``benchmarks/chute_bagnold.py``
prints the figures quoted in docs/chute.md.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.chute_case import bagnold_case

from ktgf.closures import get_model
from ktgf.couette.chute import solve_chute
from ktgf.couette.run import Material
from ktgf.shear.steady import steady_shear

MAT = Material(d=1e-3, rho_s=2500.0, e=0.9)
ANGLE = 18.0


pytestmark = pytest.mark.analytic


def _series(angle: float, depths: list[float]) -> list:
    """1D layers at the depths (in d), each continued from the previous one, 2 cells per d (≥ 256)."""
    out, ds = [], None
    for H in depths:
        ds = solve_chute("ret", depth=H * MAT.d, angle_deg=angle, mean_phi=0.3, material=MAT,
                         n_cells=int(max(256, 2 * H)), start=ds)
        out.append(ds)
    return out


def test_angle_admits_a_uniform_shear_interior():
    """tan 18° lies inside RET's uniform-shear stress-ratio range at e = 0.9 (tan 25° does not)."""
    ratios = [float(steady_shear(get_model("ret"), p, MAT.e).tau_over_p) for p in np.linspace(0.002, 0.6, 120)]
    assert min(ratios) < math.tan(math.radians(ANGLE)) < max(ratios)
    assert max(ratios) < math.tan(math.radians(25.0))


def test_1d_depth_exponent_falls_to_three_halves():
    """d ln u(H)/d ln H of the 1D layer at 18° falls monotonically to 3/2 beyond 25 d and is within
    0.005 of 3/2 beyond 180 d (about 3 s)."""
    depths = [25.0 * 1.25**k for k in range(11)]  # 25 … 233 d
    uh = np.array([ds.attrs["surface_velocity"] for ds in _series(ANGLE, depths)])
    slopes = np.diff(np.log(uh)) / np.diff(np.log(depths))
    assert np.all(np.diff(slopes) < 0), slopes
    assert np.all(slopes > 1.5), slopes
    assert slopes[0] > 1.7 and slopes[-1] - 1.5 < 0.005, slopes


def _deep_run(depth_d: float) -> dict:
    from ktgf.solver.cases.chute import chute_reference, compare_chute
    from ktgf.solver.config import parse_config
    from ktgf.solver.run import Simulation

    cfg = bagnold_case(depth_d, ANGLE, scheme="ssprk3")
    sim = Simulation(parse_config(cfg))
    sim.run(progress=False, write_files=False)
    h = sim.history
    change = sim.case.steady_change(h)
    assert change is not None and change < cfg["time"]["steady_tol"], (depth_d, sim.time, change)
    fine = int(4 * depth_d)  # the 1D solver on 4 cells per d: its own u error is then < 2e-4
    u = np.asarray(h["u_profile"][-1])
    return {"u_surface": 1.5 * u[-1] - 0.5 * u[-2],
            "u_surface_1d": float(chute_reference(sim.phys, sim.grid, sim.phi0, n_cells=fine)["u"].values[-1]),
            "err": compare_chute(h, sim.phys, sim.grid, sim.phi0, n_cells=fine)["max_rel_error"]}


@pytest.mark.slow(minutes=2.6)
def test_deep_3d_layers_follow_the_1d_solver_towards_bagnold():
    """3D runs (1D grid, 1 cell per d, SSP-RK3, steady_tol 1e-4) at 57.6 and 72 d, 18°, from a
    Bagnold-scaled linear start: u(H) within 0.5 % and the u profile within 1 % of the 1D solver
    (its own error at 1 cell per d: 0.16 %), the depth exponent within 0.01 of the 1D solver's and
    between 3/2 and 3/2 + 0.05 (the 1D exponent there is 1.545, falling to 3/2 with depth: test
    above).  φ and θ are not resolved at 1 cell per d in these layers (docs/chute.md: φ 4–5 % in
    the bulk, second order with the spacing), so they are not asserted here.  SSP-RK3 is what
    ``scheme = "auto"`` picks on this grid: it reaches the IMEX run's steady state (docs/chute.md) at
    a fifth of its cost; the chute with IMEX is tested in test_solver_chute_depth.py.  About 2 min
    wall (4 min CPU) on the idle 2-core machine."""
    depths = (57.6, 72.0)
    runs = [_deep_run(H) for H in depths]
    for H, r in zip(depths, runs):
        assert abs(r["u_surface"] / r["u_surface_1d"] - 1.0) < 0.005, (H, r)
        assert r["err"]["u"] < 0.01, (H, r)
    dl = math.log(depths[1] / depths[0])
    s3 = math.log(runs[1]["u_surface"] / runs[0]["u_surface"]) / dl
    s1 = math.log(runs[1]["u_surface_1d"] / runs[0]["u_surface_1d"]) / dl
    assert abs(s3 - s1) < 0.01, (s3, s1)
    assert 1.5 < s3 < 1.55, s3
