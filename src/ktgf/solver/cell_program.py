"""The cell closures of the fused SSP-RK3 stage as compiled C++, generated from the Python physics.

:func:`.cell_terms.kernel_stage_inputs` of the model's :meth:`.Physics.reduced` — nothing rewritten — is
traced once with scalar inputs, and its jaxpr (elementwise arithmetic only) is printed as a C++ loop over a
row of cells, which :func:`.flux_kernel.ssprk_stage_cells` calls as its sweep goes: a stage reads the five
conservative fields and writes none of the 13 cell fields to memory (an XLA pass writing them, read back and
padded by the kernel, was a third of the stage).

Physics stays in one place: the generated code is the jaxpr of the Python closures, operation for
operation in the same precision (each jaxpr variable keeps its dtype; ``integer_pow`` is expanded as
XLA expands it), so it agrees with the XLA evaluation to round-off
(tests/solver/test_solver_cell_program.py checks every registered model, both precisions).  The parameters
of :class:`.Physics` (e, d, ρ_s, …) are runtime inputs, not constants, so changing them does not
recompile; a model is compiled once per precision (≈ 1 s, cached like the kernel in
``$KTGF_CACHE_DIR`` by :mod:`.cxx`).  A program that cannot be built (the compiler fails) is said once, at
WARNING on the ``ktgf`` logger, with what it costs: the stage then evaluates the closures in an XLA pass.

It applies where the closures depend on the cell's own state only (no velocity gradient:
:func:`.friction.needs_rate` false) and the jaxpr has only the primitives of :data:`_EXPRESSIONS`;
otherwise :func:`for_physics` returns None and the stage keeps its XLA closure pass.
``fluxes.CELL_PROGRAM`` (environment ``KTGF_CELL_PROGRAM``, ``0`` off) switches it.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import logging
from dataclasses import dataclass
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
from jax.extend.core import Literal

from .cxx import shared_library, warn_once

log = logging.getLogger(__name__)
#: Outputs of a cell program, in the order the kernel stores them (its Field enum, then s0, s1); a
#: step-start program (``limits``) adds :data:`.stepping.LIMIT_TERMS` and :data:`.stepping.STATUS_TERMS`, which the
#: kernel reduces to maxima.
OUTPUTS = ("rho", "u_x", "u_y", "u_z", "theta", "p_star", "g", "eta", "lambda_b", "kappa", "omega", "s0", "s1")
#: What the XLA closure pass costs where a program would run, for the one-line warning when it cannot be built:
#: the A/B of ``benchmarks/bench_solver.py --ab`` (docs/solver.md, "Fallbacks").
FALLBACK_COST = "1.1-1.5x the time per SSP-RK3 step"
SYMBOL = "ktgf_cells"
_CTYPES = {np.dtype(np.float64): "double", np.dtype(np.float32): "float", np.dtype(np.bool_): "bool",
           np.dtype(np.int32): "int32_t", np.dtype(np.int64): "int64_t"}


class Unsupported(Exception):
    """The jaxpr holds something the generator does not print (the XLA closure pass is used instead)."""


@dataclass(frozen=True)
class CellProgram:
    """A compiled cell program: its source, its key in the stage kernel's registry, its state precision,
    its C function ``(long n, const double* leaf, const T* const* in, T* const* out)`` (ctypes) and the
    number of limit terms among its outputs (0 for a stage program)."""

    source: str
    key: int
    dtype: Any
    function: Any
    nlim: int = 0

    @property
    def address(self) -> int:
        return ctypes.cast(self.function, ctypes.c_void_p).value


def _binary(op: str):
    return lambda a, eqn: f"{a[0]} {op} {a[1]}"


def _call(fn: str):
    return lambda a, eqn: f"{fn}({', '.join(a)})"


def _select(a: list[str], eqn: Any) -> str:
    pred, *cases = a
    if len(cases) == 2 and eqn.invars[0].aval.dtype == np.bool_:
        return f"{pred} ? {cases[1]} : {cases[0]}"
    expr = cases[-1]
    for i in range(len(cases) - 2, -1, -1):
        expr = f"({pred} == {i} ? {cases[i]} : {expr})"
    return expr


#: C++ expressions of the elementwise primitives (a: the operand names).
_EXPRESSIONS = {
    "add": _binary("+"), "sub": _binary("-"), "mul": _binary("*"), "div": _binary("/"),
    "lt": _binary("<"), "le": _binary("<="), "gt": _binary(">"), "ge": _binary(">="), "eq": _binary("=="),
    "ne": _binary("!="), "and": _binary("&"), "or": _binary("|"),
    "neg": lambda a, eqn: f"-{a[0]}", "not": lambda a, eqn: f"!{a[0]}",
    "max": lambda a, eqn: f"{a[0]} > {a[1]} ? {a[0]} : {a[1]}",
    "min": lambda a, eqn: f"{a[0]} < {a[1]} ? {a[0]} : {a[1]}",
    "sqrt": _call("std::sqrt"), "exp": _call("std::exp"), "log": _call("std::log"), "log1p": _call("std::log1p"),
    "expm1": _call("std::expm1"), "tanh": _call("std::tanh"), "abs": _call("std::fabs"), "pow": _call("std::pow"),
    "cbrt": _call("std::cbrt"),
    "rsqrt": lambda a, eqn: f"1 / std::sqrt({a[0]})",
    "square": lambda a, eqn: f"{a[0]} * {a[0]}",
    "copy": lambda a, eqn: a[0], "copy_p": lambda a, eqn: a[0],
    "select_n": _select,
    "convert_element_type": lambda a, eqn: f"static_cast<{_ctype(eqn.outvars[0].aval.dtype)}>({a[0]})",
}
#: Primitives whose body is a sub-jaxpr, inlined.
_CALLS = ("jit", "pjit", "custom_jvp_call", "custom_vjp_call", "custom_vjp_call_jaxpr", "closed_call")


def _ctype(dtype: Any) -> str:
    try:
        return _CTYPES[np.dtype(dtype)]
    except KeyError:
        raise Unsupported(f"dtype {dtype}") from None


def _literal(value: Any, dtype: Any) -> str:
    dtype = np.dtype(dtype)
    value = np.asarray(value)
    if value.shape != ():
        raise Unsupported("an array constant")
    ctype = _ctype(dtype)
    if dtype == np.bool_:
        return "true" if bool(value) else "false"
    if dtype.kind in "iu":
        return f"{ctype}({int(value)})"
    v = float(value)
    if np.isnan(v):
        return f"std::numeric_limits<{ctype}>::quiet_NaN()"
    if np.isinf(v):
        return f"{'-' if v < 0 else ''}std::numeric_limits<{ctype}>::infinity()"
    return f"{ctype}({v.hex()})"  # hexadecimal: exact


class _Printer:
    """Prints a jaxpr as C++ statements, one ``const`` variable per jaxpr variable."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.count = 0

    def fresh(self, dtype: Any, expr: str) -> str:
        name = f"v{self.count}"
        self.count += 1
        self.lines.append(f"const {_ctype(dtype)} {name} = {expr};")
        return name

    def jaxpr(self, jaxpr: Any, consts: list[Any], args: list[str]) -> list[str]:
        env: dict[Any, str] = {}

        def read(atom: Any) -> str:
            return _literal(atom.val, atom.aval.dtype) if isinstance(atom, Literal) else env[atom]

        for var, c in zip(jaxpr.constvars, consts):
            env[var] = _literal(c, var.aval.dtype)
        for var, name in zip(jaxpr.invars, args):
            env[var] = name
        for eqn in jaxpr.eqns:
            for v in (*eqn.invars, *eqn.outvars):
                if getattr(v.aval, "shape", None) != ():
                    raise Unsupported(f"{eqn.primitive.name} on a non-scalar")
            a = [read(v) for v in eqn.invars]
            name = eqn.primitive.name
            if name in _CALLS:
                sub = next((eqn.params[k] for k in ("jaxpr", "call_jaxpr", "fun_jaxpr") if k in eqn.params), None)
                if sub is None:
                    raise Unsupported(name)
                inner = getattr(sub, "jaxpr", sub)
                outs = self.jaxpr(inner, list(getattr(sub, "consts", [])), a[len(a) - len(inner.invars):])
                env.update(zip(eqn.outvars, outs))
            elif name == "integer_pow":
                env[eqn.outvars[0]] = self._integer_pow(a[0], eqn.params["y"], eqn.outvars[0].aval.dtype)
            elif name in _EXPRESSIONS:
                env[eqn.outvars[0]] = self.fresh(eqn.outvars[0].aval.dtype, _EXPRESSIONS[name](a, eqn))
            else:
                raise Unsupported(name)
        return [read(v) for v in jaxpr.outvars]

    def _integer_pow(self, x: str, y: int, dtype: Any) -> str:
        """x**y by squaring, in the order of JAX's lowering of ``integer_pow`` (so the same rounding)."""
        ctype = _ctype(dtype)
        if y == 0:
            return self.fresh(dtype, f"{ctype}(1)")
        reciprocal, y = y < 0, abs(y)
        acc = None
        while y > 0:
            if y & 1:
                acc = x if acc is None else self.fresh(dtype, f"{acc} * {x}")
            y >>= 1
            if y > 0:
                x = self.fresh(dtype, f"{x} * {x}")
        return self.fresh(dtype, f"{ctype}(1) / {acc}") if reciprocal else acc


def _avals(leaves: list[Any]) -> tuple:
    avals = []
    for leaf in leaves:
        a = jax.typeof(leaf)
        if a.shape != ():
            raise Unsupported("a non-scalar physics parameter")
        avals.append(jax.ShapeDtypeStruct((), a.dtype, weak_type=a.weak_type))
    return tuple(avals)


def source_for(treedef: Any, avals: tuple, dtype: Any, limits: str | None = None) -> str:
    """C++ source of the cell program for a state of ``dtype``, of the physics with pytree structure
    ``treedef`` and parameter types ``avals`` (raises :class:`Unsupported`).

    ``limits`` (the acoustics, ``"explicit"`` or ``"implicit"``): a step-start program, whose outputs add the
    :data:`.stepping.LIMIT_TERMS` of a 3D grid and the :data:`.stepping.STATUS_TERMS` of the state (together
    :data:`.stepping.START_TERMS`); its parameters then end with the three cell sizes Δx_a,
    traced as Python floats are (weakly typed), so the terms round as in :func:`.stepping.step_limits`.
    """
    from .friction import cell_coefficients, needs_rate
    from .physics import is_frictional
    from .state import primitive_fields
    from .cell_terms import START_TERMS, kernel_stage_inputs, limit_terms, status_terms

    phys = jax.tree_util.tree_unflatten(treedef, avals)
    if needs_rate(phys):
        raise Unsupported("the closures need the velocity gradient")
    nleaf = len(avals)
    if limits is not None:
        avals = (*avals, *(jax.ShapeDtypeStruct((), jnp.float64, weak_type=True) for _ in range(3)))

    def cells(U: tuple, leaves: list) -> tuple:
        ph = jax.tree_util.tree_unflatten(treedef, leaves[:nleaf])
        r = cell_coefficients(primitive_fields(U), None, ph)
        if is_frictional(r):
            raise Unsupported("a frictional stress")
        W, eos, transport, source = kernel_stage_inputs(U, r, ph)
        extra = () if limits is None else (*limit_terms(W, r, ph, limits, leaves[nleaf:]), *status_terms(U, W))
        return (*W, *eos, *transport, *source, *extra)

    nout = len(OUTPUTS) + (0 if limits is None else len(START_TERMS))
    state = tuple(jax.ShapeDtypeStruct((), dtype) for _ in range(5))
    closed = jax.make_jaxpr(cells)(state, list(avals))
    ctype = _ctype(dtype)
    p = _Printer()
    loads = [f"const {ctype} u{v} = in[{v}][i];" for v in range(5)]
    params = [f"const {_ctype(a.dtype)} leaf{k} = static_cast<{_ctype(a.dtype)}>(leaf[{k}]);"
              for k, a in enumerate(avals)]
    outs = p.jaxpr(closed.jaxpr, list(closed.consts), [f"u{v}" for v in range(5)] + [f"leaf{k}" for k in range(len(avals))])
    if len(outs) != nout:
        raise Unsupported(f"{len(outs)} outputs")
    stores = [f"out[{k}][i] = static_cast<{ctype}>({name});" for k, name in enumerate(outs)]
    body = "\n".join("    " + line for line in (*loads, *p.lines, *stores))
    return (
        f"// Cell program of {phys.model.name} ({np.dtype(dtype).name}), generated by ktgf.solver.cell_program\n"
        "// from the jaxpr of stepping.kernel_stage_inputs: outputs " + ", ".join(OUTPUTS)
        + ("" if limits is None else f", then the step limit terms ({limits} acoustics)") + ".\n"
        "#include <cmath>\n#include <cstdint>\n#include <limits>\n\n"
        f'extern "C" void {SYMBOL}(long n, const double* leaf, const {ctype}* const* in, {ctype}* const* out) {{\n'
        + "".join(f"  {line}\n" for line in params)
        + "#pragma omp simd\n  for (long i = 0; i < n; ++i) {\n" + body + "\n  }\n}\n"
    )


@functools.lru_cache(maxsize=None)
def _compiled(source: str, dtype: Any, nlim: int, what: str) -> CellProgram:
    function = getattr(ctypes.cdll.LoadLibrary(str(shared_library("cells", source, (), what, "1 s"))), SYMBOL)
    key = int(hashlib.sha256(source.encode()).hexdigest()[:15], 16)  # < 2^60: an int64 attribute
    return CellProgram(source, key, np.dtype(dtype), function, nlim)


@functools.lru_cache(maxsize=None)
def _program(treedef: Any, avals: tuple, dtype: Any, limits: str | None) -> CellProgram | None:
    from .cell_terms import START_TERMS

    model = jax.tree_util.tree_unflatten(treedef, avals).model.name
    what = f"the {np.dtype(dtype).name} {'step-start ' if limits else ''}cell program of {model}"
    try:
        source = source_for(treedef, avals, dtype, limits)
    except Unsupported:  # does not apply (module docstring): nothing lost that this configuration could have had
        return None
    try:
        return _compiled(source, dtype, 0 if limits is None else len(START_TERMS), what)
    except (RuntimeError, OSError) as err:
        warn_once(log, f"{what} could not be built ({err}); the fused stage evaluates the closures in an XLA pass "
                       f"instead, {FALLBACK_COST} (docs/solver.md, Fallbacks)", key="cell program build")
        return None


def for_physics(phys: Any, dtype: Any, limits: str | None = None) -> CellProgram | None:
    """The compiled cell program of ``phys`` for a ``dtype`` state, or None where it does not apply
    (see the module docstring).  The program depends on the physics' structure (model, static
    options) and the types of its parameters only, so traced parameters are fine.  ``limits``: the
    step-start program of that acoustics (:func:`source_for`)."""
    leaves, treedef = jax.tree_util.tree_flatten(phys)
    try:
        avals = _avals(leaves)
    except Unsupported:
        return None
    return _program(treedef, avals, np.dtype(dtype), limits)


def leaf_values(phys: Any, grid: Any = None) -> Any:
    """The physics parameters a program takes at run time, as a float64 vector (traced or not), then
    (``grid``: for a step-start program) the grid's cell sizes."""
    leaves = [*jax.tree_util.tree_leaves(phys), *(() if grid is None else grid.spacing)]
    if not leaves:
        return jnp.zeros((1,), jnp.float64)
    return jnp.stack([jnp.asarray(v, jnp.float64) for v in leaves])
