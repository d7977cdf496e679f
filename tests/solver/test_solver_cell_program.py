"""The generated cell programs (:mod:`ktgf.solver.cell_program`) compute the XLA cell closures.

Oracle: :func:`~ktgf.solver.stepping.kernel_stage_inputs` of the model's closures, evaluated by XLA
in the same process — the fields the fused stage kernel took from its XLA closure pass.  Every
registered model, both precisions, at random dense states (φ 0.05–0.6, straddling the freezing
point and the C¹ junction window of the piecewise RDFs).  Also: where the program does not apply
(closures that need the velocity gradient) there is none.
"""

from __future__ import annotations

import ctypes

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.closures.models import list_models
from ktgf.solver import cell_program, cxx
from ktgf.solver.cases import get_case
from ktgf.solver.friction import cell_coefficients
from ktgf.solver.grid import Grid
from ktgf.solver.physics import Physics
from ktgf.solver.state import conservative_fields, primitive_fields
from ktgf.solver.cell_terms import kernel_stage_inputs

D, RHO_S = 1e-3, 2500.0
#: float64: the program does XLA's operations in XLA's order; XLA's fusion rounds a few differently
#: (its algebraic rewrites) — relative to the largest value of each field.
RTOL64 = 1e-13
#: float32: XLA's fused float32 closures and the program (the jaxpr's operations one by one) round
#: differently, by more than a few ulp where φ nears φ_c (χ ∝ (φ_c − φ)^−β amplifies the rounding of
#: φ_c − φ).  Both are held to the float64 closures at the same float32 state: measured 18–77 ε₃₂
#: for the program and 16–48 ε₃₂ for XLA over the registered models (largest: `dense`, β = 4.052).
TOL32 = 128 * float(np.finfo(np.float32).eps)


def _no_compiler() -> str | None:
    try:
        cxx.compiler()
    except RuntimeError as err:
        return str(err)
    return None


pytestmark = [pytest.mark.contract,
              pytest.mark.skipif(_no_compiler() is not None, reason=f"cell programs need a C++ compiler: {_no_compiler()}")]


def _states(phys: Physics, n: int, dtype) -> tuple:
    rng = np.random.default_rng(7)
    phi = rng.uniform(0.05, min(0.6, 0.98 * phys.model.phi_max), n)
    phi[:8] = [0.49, 0.4900001, 0.495, 0.4999999, 0.5, 0.5000001, 0.3, 0.55]  # the junction window ends
    u = rng.normal(0.0, 0.05, (3, n))
    theta = rng.uniform(1e-5, 1e-3, n)
    return tuple(np.asarray(f, dtype) for f in conservative_fields((RHO_S * phi, *u, theta)))


def _run(program: cell_program.CellProgram, phys: Physics, U: tuple) -> list[np.ndarray]:
    dtype = U[0].dtype
    ptr = ctypes.POINTER(np.ctypeslib.as_ctypes_type(dtype))
    outs = [np.empty_like(U[0]) for _ in cell_program.OUTPUTS]
    ins = (ptr * 5)(*(u.ctypes.data_as(ptr) for u in U))
    outp = (ptr * len(outs))(*(o.ctypes.data_as(ptr) for o in outs))
    leaf = np.asarray(cell_program.leaf_values(phys), np.float64)
    program.function(ctypes.c_long(U[0].size), leaf.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), ins, outp)
    return outs


def _physics(model: str, case: str = "cooling") -> Physics:
    m = get_model(model)
    grid = Grid((4, 4, 4), (4 * D,) * 3)
    return get_case(case).physics(Physics(m, 0.8, D, RHO_S, 0.99 * m.phi_max), grid)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("model", [m.name for m in list_models()])
def test_cell_program_computes_the_xla_closures(model: str, dtype) -> None:
    phys = _physics(model)
    program = cell_program.for_physics(phys, dtype)
    assert program is not None, "every registered model has a cell program in the cooling box"
    U = _states(phys, 4099, dtype)  # not a multiple of the vector width: the remainder loop too
    got = _run(program, phys, U)

    @jax.jit
    def xla(U: tuple) -> tuple:
        r = cell_coefficients(primitive_fields(U), None, phys)
        W, eos, transport, source = kernel_stage_inputs(U, r, phys)
        return tuple(jnp.asarray(f, U[0].dtype) for f in (*W, *eos, *transport, *source))

    want = [np.asarray(f, np.float64) for f in xla(tuple(jnp.asarray(u) for u in U))]
    if dtype == np.float32:  # the oracle: float64 closures of the same (float32) state
        exact = [np.asarray(f) for f in xla(tuple(jnp.asarray(u, jnp.float64) for u in U))]
    for name, g, w in zip(cell_program.OUTPUTS, got, want):
        assert g.dtype == dtype
        if dtype == np.float64:
            assert _error(g, w) < RTOL64, name
        else:
            truth = exact[cell_program.OUTPUTS.index(name)]
            assert _error(g, truth) < TOL32, (name, _error(g, truth), _error(w, truth))


def _error(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a − b| relative to the largest |b| (absolute where b is all zero)."""
    scale = float(np.max(np.abs(b)))
    return float(np.max(np.abs(np.asarray(a, np.float64) - b))) / (scale if scale > 0 else 1.0)


def test_physics_parameters_are_inputs_not_constants() -> None:
    """Another e, d, ρ_s: the same compiled program, and its closures follow the new values."""
    phys = _physics("ret")
    other = Physics(phys.model, 0.6, 2 * D, 1.5 * RHO_S, phys.phi_stop, hcs=True)
    program = cell_program.for_physics(phys, np.float64)
    assert cell_program.for_physics(other, np.float64) is program
    U = _states(other, 64, np.float64)
    got = _run(program, other, U)
    r = cell_coefficients(primitive_fields(U), None, other)
    want = kernel_stage_inputs(tuple(jnp.asarray(u) for u in U), r, other)[2]  # η, λ_b, κ, ω
    for g, w in zip(got[7:11], want):
        assert _error(g, np.asarray(w)) < RTOL64


def test_no_program_where_the_closures_need_the_velocity_gradient() -> None:
    """The frictional model's dissipation correction in a sheared case takes the local shear rate."""
    assert cell_program.for_physics(_physics("frictional", "uniform-shear"), np.float64) is None
    assert cell_program.for_physics(_physics("frictional", "cooling"), np.float64) is not None
