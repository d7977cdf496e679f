"""Mixed precision (``numerics.precision = "mixed"``): float32 state and explicit arithmetic, float64
Krylov inner products and diagnostics.  The same oracles as in float64: Haff's law and its
order (ktgf.hcs.haff), a linear growth rate (ktgf.hcs.stability), and conservation of mass.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.growth import measure_rate

from ktgf.closures import get_model, list_models
from ktgf.closures.coefficients import mean_free_path
from ktgf.errors import InputError
from ktgf.hcs.haff import cooling_time, haff_temperature
from ktgf.solver.config import NumericsSection
from ktgf.solver.grid import Grid
from ktgf.solver.initial import random_velocity, uniform_fields
from ktgf.solver.physics import Physics
from ktgf.solver.state import conservative, primitive
from ktgf.solver.stepping import Numerics, advance, explicit_rhs

EPS32 = float(np.finfo(np.float32).eps)


def _physics(model: str) -> Physics:
    """The gas of test_solver_accuracy: e = 0.7, d = 1 mm, ρ_s = 2500 kg/m³."""
    m = get_model(model)
    return Physics(m, 0.7, 1e-3, 2500.0, 0.99 * m.phi_max)


@pytest.mark.contract
def test_precision_option_is_validated() -> None:
    assert NumericsSection(precision="mixed").precision == "mixed"
    with pytest.raises((ValueError, InputError), match="precision"):
        NumericsSection(precision="float16")


@pytest.mark.analytic
@pytest.mark.slow  # 43 s under load (compilation of the mixed IMEX step)
def test_mixed_uniform_gas_follows_haff_at_second_order() -> None:
    phys = _physics("ret")
    phi0, theta0 = 0.3, 1e-4
    grid = Grid((4,), (0.05,))
    U0 = conservative(*uniform_fields(grid, phys, phi0, theta0)).astype(np.float32)
    t0 = float(cooling_time("ret", phi0, phys.restitution, theta0, d=phys.diameter))
    errors = []
    for c in (0.2, 0.1, 0.05):
        U, t, _, status, _ = advance(U0, 0.0, 3.0 * t0, 10**6, grid, phys,
                                     Numerics(cfl=c, cfl_diffusion=c, cfl_source=c, mixed=True))
        assert int(status) == 0 and U.dtype == np.float32
        theta = np.asarray(primitive(U.astype(np.float64)))[4]
        errors.append(abs(theta[0] / float(haff_temperature(3.0 * t0, theta0, t0)) - 1.0))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    print("mixed Haff errors", errors, "orders", orders)
    assert np.all(orders > 1.8), orders


@pytest.mark.analytic
@pytest.mark.slow  # 80 s under load
def test_mixed_dense_box_conserves_mass_to_float32_round_off() -> None:
    """φ = 0.5, Δx = ℓ, 8³, 20 IMEX steps whose stage solves use float64 inner products: every solve
    converges (status 0) and Σρ (summed in float64) drifts at the float32 round-off of the state,
    ε₃₂ per cell and stage as a random walk, far below a step's worth of flux."""
    phys = _physics("ret")
    n, ell = 8, mean_free_path(0.5, phys.diameter)
    grid = Grid((n, n, n), (n * ell,) * 3)
    U64 = np.asarray(random_velocity(grid, phys, 0.5, 1e-4, 0.01, 0))
    U, _, steps, status, _ = advance(U64.astype(np.float32), 0.0, 1e30, 20, grid, phys, Numerics(mixed=True))
    assert int(status) == 0 and int(steps) == 20
    m0, m1 = U64[0].sum(), np.asarray(U[0], np.float64).sum()
    m32 = U64[0].astype(np.float32).astype(np.float64).sum()  # the initial state's own rounding
    drift = abs(m1 - m32) / m0
    print("mass drift (float64 sums of the float32 state)", drift, "initial rounding", abs(m32 - m0) / m0)
    assert drift < 4.0 * EPS32 * math.sqrt(2 * 20 / grid.size) + 1e-12


@pytest.mark.analytic
@pytest.mark.slow
def test_mixed_growth_rate_of_a_vortex_mode() -> None:
    """The k* = 0.2 vortex mode of tests/solver/test_solver_linear.py, 2 % of the eigenvalue, in mixed precision.

    Amplitude 1e-3 (not 1e-6): a float32 state resolves 1e-6 of the mean only to ≈ 10 %."""
    measured, theory = measure_rate("ret", (64,), (1,), 0.2, "transverse", mixed=True, amplitude=1e-3)
    print(f"relative error {abs(measured - theory) / abs(theory):.4f}", measured, theory)
    assert abs(measured - theory) <= 0.02 * abs(theory), (measured, theory)


@pytest.mark.analytic
def test_float64_inner_product_krylov_solvers_solve_float32_systems() -> None:
    """_bicgstab64 and _cg64 (float32 vectors, float64 scalars) against a dense NumPy solve in float64:
    a non-symmetric diagonally dominant system and a symmetric positive definite one, Jacobi-preconditioned."""
    import jax.numpy as jnp

    from ktgf.solver.imex import _bicgstab64, _cg64

    rng = np.random.default_rng(1)
    n = 40
    N = np.eye(n) * 4.0 + 0.3 * rng.standard_normal((n, n))
    S = N @ N.T / n + np.eye(n)
    b = rng.standard_normal(n)
    for mat, solver in ((N, _bicgstab64), (S, _cg64)):
        A32 = jnp.asarray(mat, jnp.float32)
        d = jnp.asarray(np.diag(mat), jnp.float32)
        x = solver(lambda v: A32 @ v, jnp.asarray(b, jnp.float32), tol=jnp.float64(1e-6), atol=0.0,
                   maxiter=200, M=lambda r: r / d)
        assert x.dtype == jnp.float32
        exact = np.linalg.solve(mat.astype(np.float32).astype(np.float64), b.astype(np.float32).astype(np.float64))
        err = np.linalg.norm(np.asarray(x, np.float64) - exact) / np.linalg.norm(exact)
        print(solver.__name__, "relative error", err)
        assert err < 1e-5, err


@pytest.mark.contract
@pytest.mark.slow  # 18 s under load (two compiled runs)
def test_mixed_run_follows_the_float64_run(tmp_path) -> None:
    """The whole run (config → Simulation → history) in mixed precision: float32 state, and the
    diagnostics agree with the float64 run's to float32 accuracy."""
    from helpers.tiny_case import tiny_case

    from ktgf.solver.config import parse_config
    from ktgf.solver.run import Simulation

    try:
        import tomllib
    except ImportError:  # pragma: no cover
        import tomli as tomllib
    out = {}
    for precision in ("float64", "mixed"):
        cfg = tomllib.loads(tiny_case(end=2.0))
        cfg["numerics"] = {"precision": precision}
        sim = Simulation(parse_config(cfg), tmp_path / precision)
        out[precision] = sim.run(progress=False, write_files=False)
        assert np.asarray(sim.state).dtype == (np.float64 if precision == "float64" else np.float32)
    a, b = (np.asarray(out[p]["theta_mean"]) for p in ("float64", "mixed"))
    print("theta_mean relative difference", np.max(np.abs(b / a - 1.0)))
    assert np.allclose(b, a, rtol=1e-5), (a, b)


def _float64_cell_ops(jaxpr) -> list[str]:
    """Operations of a jaxpr (and of its sub-jaxprs) whose result is a float64 cell field (rank ≥ 3)."""
    found = []
    for eqn in jaxpr.eqns:
        found += [str(eqn.primitive) for v in eqn.outvars
                  if getattr(v.aval, "dtype", None) == np.float64 and v.aval.ndim >= 3]
        for p in eqn.params.values():
            for sub in (p if isinstance(p, (tuple, list)) else (p,)):
                inner = getattr(sub, "jaxpr", None)
                if inner is not None:
                    found += _float64_cell_ops(getattr(inner, "jaxpr", inner))
    return found


@pytest.mark.contract
@pytest.mark.parametrize("model", [m.name for m in list_models()])
def test_float32_right_hand_side_computes_no_float64_cell_field(model: str) -> None:
    """A float32 state is stepped in float32: no closure promotes a cell field to float64 (a NumPy
    float64 constant in a closure would, and cost the float32 speed-up: Proposed's C¹ junction did,
    1.6× RET's step time against 1.0× in float64)."""
    import jax

    phys = _physics(model)
    grid = Grid((4, 4, 4), (0.01,) * 3)
    U = tuple(np.asarray(random_velocity(grid, phys, 0.5, 1e-4, 0.01, 0), np.float32))
    jaxpr = jax.make_jaxpr(lambda U: explicit_rhs(U, grid, phys, Numerics(), viscous=True))(U).jaxpr
    assert _float64_cell_ops(jaxpr) == []
