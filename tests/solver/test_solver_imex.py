"""The IMEX time stepping (ARS(2,2,2), :mod:`ktgf.solver.imex`): order, stiff steps, stage solver failure.

* A finite-amplitude shear wave at φ = 0.5 decays by viscosity while viscous heating, conduction
  and the sound it launches couple all equations (η, κ ∝ √θ vary): the error against a
  16× finer step must fall with the second power of Δt, with Δt up to the acoustic limit,
  many times the explicit diffusive limit.  The oracle is the convergence order of the scheme.
* A stage solve that cannot reach its tolerance stops the run with a diagnosis and keeps the
  last good state (like a diverging explicit step).
"""

from __future__ import annotations

import math

import jax.numpy as jnp
import numpy as np
import pytest
from helpers.growth import temporal_orders

from ktgf.closures import get_model
from ktgf.closures.coefficients import mean_free_path
from ktgf.errors import DivergenceError
from ktgf.solver.config import parse_config
from ktgf.solver.grid import Grid
from ktgf.solver.initial import single_mode, t_of_tau
from ktgf.solver.physics import Physics
from ktgf.solver.run import CHECKPOINT, Simulation
from ktgf.solver.stepping import Numerics, limits

PHI0, E, D, RHO_S, THETA0 = 0.5, 0.7, 1e-3, 2500.0, 1e-4


@pytest.mark.analytic
def test_imex_is_second_order_in_time_beyond_the_diffusive_limit() -> None:
    m = get_model("ret")
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max)
    ell = mean_free_path(PHI0, D)
    grid = Grid((64,), (2.0 * math.pi * ell / 0.5,))  # k* = 0.5: a damped shear mode, Δx = 0.2 ℓ
    U0, _, _ = single_mode(grid, phys, PHI0, THETA0, (1,), "transverse", 0.3)
    lim = np.asarray(limits(U0, grid, phys, Numerics()))
    dt_diffusive = min(lim[1], lim[2])
    t_end = float(t_of_tau(1.0, phys, PHI0, THETA0))
    n0 = math.ceil(t_end / (0.9 * lim[0]))  # the coarsest step: 0.9 of the acoustic limit
    errors, orders = temporal_orders(U0, grid, phys, t_end, n0, [0, 2, 4], THETA0, scheme="imex")
    ratio = t_end / n0 / dt_diffusive
    print("dt / diffusive limit", ratio, "errors", errors, "orders", orders)
    assert ratio > 10.0
    assert np.all(orders > 1.9), orders


def _base(**numerics: float) -> dict:
    return {
        "model": {"name": "ret", "restitution": 0.7},
        "initial": {"solid_fraction": 0.3, "temperature": 1e-4, "perturbation": "mode", "mode": [1, 0],
                    "kind": "transverse", "amplitude": 0.5},
        "grid": {"cells": [16, 8], "length_d": 10.0},
        "time": {"end": 2.0, "outputs": 2, "scheme": "imex"},
        "numerics": numerics,
    }


@pytest.mark.contract
def test_unconverged_stage_solve_stops_with_diagnosis(tmp_path, monkeypatch) -> None:
    # Strong density variation on a fine grid (η varies several-fold between cells, Δt ≫ the
    # diffusive limit): one Krylov iteration per solve cannot reach a relative residual of 1e-12.
    from ktgf.solver import imex

    monkeypatch.setattr(imex, "RESTART", 1)
    cfg = _base(implicit_tol=1e-12, implicit_maxiter=1)
    cfg["initial"] = {"solid_fraction": 0.3, "temperature": 1e-4, "perturbation": "random", "amplitude": 0.25}
    cfg["grid"] = {"cells": [32, 32], "length_d": 5.0}
    sim = Simulation(parse_config(cfg), tmp_path)
    with pytest.raises(DivergenceError) as exc:
        sim.run(progress=False)
    err = exc.value
    assert err.status == 6 and err.field == "implicit_residual_over_tolerance" and err.value > 10.0
    assert "implicit" in str(err) and str(tmp_path / CHECKPOINT) in str(err)
    ck = np.load(tmp_path / CHECKPOINT)
    assert float(ck["t"]) == err.time


@pytest.mark.contract
def test_auto_scheme_follows_the_step_limits() -> None:
    dense = Simulation(parse_config({**_base(), "time": {"end": 1.0, "scheme": "auto"},
                                     "initial": {"solid_fraction": 0.5, "temperature": 1e-4},
                                     "grid": {"cells": [64], "length_d": 5.0}}))
    dilute = Simulation(parse_config({**_base(), "time": {"end": 1.0, "scheme": "auto"},
                                      "initial": {"solid_fraction": 0.05, "temperature": 1e-4},
                                      "grid": {"cells": [16], "length_d": 500.0}}))
    assert dense.num.scheme == "imex" and dilute.num.scheme == "ssprk3"


@pytest.mark.contract
def test_auto_scheme_weighs_the_cost_of_the_explicit_step() -> None:
    """``auto`` takes IMEX where its step is more than twice the break-even longer than SSP-RK3's: 2 × 3 for the
    SSP-RK3 of the JAX path (a 1D grid), 2 × IMEX_COST_CELLS where SSP-RK3's stages run on cell programs (a 3D
    periodic grid on the CPU; measured costs, stepping.IMEX_COST*).  A 32³ box of 4 d at φ = 0.5 (Δx ≈ ℓ/2) has
    the IMEX step 10.7× longer: SSP-RK3 with cell programs, IMEX without them."""
    from ktgf.solver import fluxes
    from ktgf.solver.stepping import IMEX_COST, IMEX_COST_CELLS, Numerics, auto_ratio

    cfg = {**_base(), "time": {"end": 1.0, "scheme": "auto"}, "initial": {"solid_fraction": 0.5, "temperature": 1e-4},
           "grid": {"cells": [32, 32, 32], "length_d": 4.0}}
    line = Simulation(parse_config({**cfg, "grid": {"cells": [64], "length_d": 5.0}}))
    assert auto_ratio(line.grid, line.phys, line.num, jnp.float64) == 2.0 * IMEX_COST
    box = Simulation(parse_config(cfg))
    if auto_ratio(box.grid, box.phys, box.num, jnp.float64) != 2.0 * IMEX_COST_CELLS:
        pytest.skip("SSP-RK3 on cell programs does not apply here (no C++ compiler, or not the CPU)")
    assert box.num.scheme == "ssprk3"
    implicit = Numerics(scheme="imex", acoustics="implicit", sink="implicit")  # any numerics: SSP-RK3's is explicit
    assert auto_ratio(box.grid, box.phys, implicit, jnp.float64) == 2.0 * IMEX_COST_CELLS
    saved = fluxes.CELL_PROGRAM
    try:
        fluxes.CELL_PROGRAM = False  # SSP-RK3 without cell programs: its step costs a third of IMEX's
        assert Simulation(parse_config(cfg)).num.scheme == "imex"
    finally:
        fluxes.CELL_PROGRAM = saved
