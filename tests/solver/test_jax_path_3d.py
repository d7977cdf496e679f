"""The pure-JAX path on 3D grids, verified on its own (issue 34, item 5): what GPUs, sharded runs and machines
without a C++ compiler run.  On a CPU with a compiler the periodic box would take the C++ kernel, so these tests
switch it off (``fluxes.FLUX_KERNEL``) and check from the compiled step that no kernel is called.

Oracles from outside the code: Haff's law (exact solution of the uniform gas), the eigenvalue of the vortex mode
of the linear stability analysis of the HCS (:mod:`ktgf.hcs.stability`), and the steady profile of the 1D Couette
solver (:mod:`ktgf.couette.run`).  Haff's law and the growth rate share one compiled step (same grid shape, model
and scheme; lengths, restitution and Courant numbers are traced), to keep the default suite quick.
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers.couette_case import couette_case
from helpers.growth import fourier_coefficient

from ktgf.closures import get_model
from ktgf.closures.coefficients import mean_free_path
from ktgf.hcs.haff import cooling_time, haff_temperature
from ktgf.solver import fluxes
from ktgf.solver.grid import Grid
from ktgf.solver.initial import single_mode, t_of_tau, uniform_fields
from ktgf.solver.physics import Physics
from ktgf.solver.state import conservative, primitive
from ktgf.solver.stepping import Numerics, advance

pytestmark = pytest.mark.analytic

E, D, RHO_S = 0.8, 1e-3, 2500.0
#: The 3D grid of the periodic tests: 32 cells along z (the contiguous axis), 4 along x and y.
CELLS = (4, 4, 32)
#: The JAX path's step loop, traced here (not shared with other tests' traces, which may hold the kernel).
_JAX_ADVANCE = jax.jit(advance.__wrapped__)


@pytest.fixture
def jax_path(monkeypatch):
    """Runs ``advance`` with the C++ kernel switched off, after checking that its compiled step calls no kernel."""
    monkeypatch.setattr(fluxes, "FLUX_KERNEL", False)

    def run(U, t, t_end, grid, phys, num):
        args = (U, jnp.asarray(t, jnp.float64), jnp.asarray(t_end, jnp.float64), jnp.asarray(10**6), grid, phys, num)
        if not run.checked:
            assert "ktgf_" not in _JAX_ADVANCE.lower(*args).as_text()
            run.checked = True
        return _JAX_ADVANCE(*args)

    run.checked = False
    return run


def _physics() -> Physics:
    m = get_model("ret")
    return Physics(m, E, D, RHO_S, 0.99 * m.phi_max)


def test_a_uniform_gas_on_a_3d_grid_follows_haff_at_third_order(jax_path) -> None:
    phi0, theta0 = 0.3, 1e-4
    phys = _physics()
    grid = Grid(CELLS, tuple(n * 2e-3 for n in CELLS))
    U0 = conservative(*uniform_fields(grid, phys, phi0, theta0))
    t0 = float(cooling_time("ret", phi0, E, theta0, d=D))  # the oracle: ktgf.hcs.haff
    errors = []
    for c in (0.2, 0.1, 0.05):
        U, t, _, status, _ = jax_path(U0, 0.0, 3.0 * t0, grid, phys,
                                      Numerics(cfl=c, cfl_diffusion=c, cfl_source=c, scheme="ssprk3"))
        assert int(status) == 0 and float(t) == 3.0 * t0
        theta = np.asarray(primitive(U))[4]
        assert np.ptp(theta) == 0.0  # stays exactly uniform in every cell of the 3D grid
        errors.append(abs(theta.flat[0] / float(haff_temperature(3.0 * t0, theta0, t0)) - 1.0))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(orders > 2.8), (errors, orders)


def test_a_vortex_mode_on_a_3d_grid_grows_at_the_eigenvalue(jax_path) -> None:
    """The unstable vortex mode at k* = 0.2 along z (velocity along y), 32 cells a wavelength, SSP-RK3: its
    amplitude, projected on the mode, grows at the eigenvalue of the linear analysis within 1 % (τ = 0 … 10)."""
    phi0, theta0, kstar, mode = 0.25, 1e-4, 0.2, (0, 0, 1)
    phys = _physics()
    L = 2.0 * math.pi * mean_free_path(phi0, D) / kstar  # |k| = 2π/L is k*/ℓ
    grid = Grid(CELLS, tuple(L * n / CELLS[2] for n in CELLS))
    U, s, vec = single_mode(grid, phys, phi0, theta0, mode, "transverse", 1e-6)
    assert s.real > 0.05 and s.imag == 0.0  # an unstable, non-oscillating mode
    taus = np.linspace(0.0, 10.0, 5)
    t, amplitude = 0.0, []
    for target in t_of_tau(taus, phys, phi0, theta0):
        U, t, _, status, _ = jax_path(U, t, float(target), grid, phys, Numerics(scheme="ssprk3"))
        assert int(status) == 0
        W = np.asarray(primitive(U))
        w = -W[2] / math.sqrt(2.0 * W[4].mean())  # the mode's velocity: along −y (ktgf.solver.initial)
        assert np.max(np.abs(W[1])) < 1e-12 * np.max(np.abs(W[2]))  # nothing along x
        amplitude.append(fourier_coefficient(w, grid, mode) / vec[2])
    log_a = np.log(np.abs(np.array(amplitude) / amplitude[0]))
    rate = np.polyfit(taus, log_a, 1)[0]
    assert abs(rate - s.real) <= 0.01 * abs(s), (rate, s)


def test_a_3d_couette_cell_keeps_the_1d_solver_profile(jax_path) -> None:
    """A 32 × 4 × 4 Couette cell (walls across x, RET, φ̄ 0.3, e = e_w = 0.9, φ' = 0.1, H = 10 d, U = 1 m/s)
    started from the 1D solver's steady profile keeps it over 2 strains (SSP-RK3): the plane averages of u, φ
    and θ stay within 1 % of the 1D profile (its own discretisation error at 32 cells is a few 0.1 %: docs/solver.md,
    Verification), and the mass is conserved."""
    import tomllib

    from ktgf.solver import Simulation, parse_config
    from ktgf.solver.cases.couette import couette_reference

    sim = Simulation(parse_config(tomllib.loads(COUETTE)))  # the config's grid, physics and numerics; not run
    grid, phys = sim.grid, sim.phys
    ref = couette_reference(phys, grid, 0.3)
    y = grid.centres(0) - 0.5 * grid.lengths[0]
    profile = {k: np.interp(y, ref["y"].values, ref[k].values) for k in ("u", "phi", "theta")}
    column = lambda f: np.broadcast_to(f[:, None, None], grid.cells)
    u = np.zeros((3, *grid.cells))
    u[1] = column(profile["u"])
    U0 = conservative(jnp.asarray(RHO_S * column(profile["phi"])), jnp.asarray(u),
                      jnp.asarray(column(profile["theta"])))
    U0 = U0 * (0.3 * RHO_S * U0[0].size / float(U0[0].sum()))  # the exact inventory (interpolation moved it)
    t_end = 2.0 * grid.lengths[0] / 1.0  # 2 strains at U/H
    U, t, steps, status, _ = jax_path(U0, 0.0, t_end, grid, phys, sim.num)
    assert int(status) == 0 and float(t) == pytest.approx(t_end, rel=1e-12) and int(steps) > 100
    W = np.asarray(primitive(U)).mean(axis=(2, 3))  # plane averages across the gap
    got = {"u": W[2], "phi": W[0] / RHO_S, "theta": W[4]}
    errors = {k: float(np.max(np.abs(got[k] - profile[k])) / np.max(np.abs(profile[k]))) for k in got}
    assert max(errors.values()) < 0.01, errors
    assert abs(float(jnp.sum(U[0])) / float(jnp.sum(U0[0])) - 1.0) < 1e-12


COUETTE = couette_case([32, 4, 4], 2.0, lengths="[10.0, 1.25, 1.25]").replace('scheme = "imex"', 'scheme = "ssprk3"')

