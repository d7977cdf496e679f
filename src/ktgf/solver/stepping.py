"""Time integration: the right-hand side, the adaptive stable step, IMEX ARS(2,2,2) and SSP-RK3.

``advance`` runs whole steps inside one compiled ``lax.while_loop`` until a target time, a
step budget, or the first step that leaves the physical state space — that step is not
accepted, so the returned state is the last good one and ``status`` says what went wrong
(a key of :data:`STATUS_MESSAGES`, 0: fine).

Schemes (``Numerics.scheme``):

* ``imex`` (default): ARS(2,2,2), convection and sink explicit, viscous stress and heat
  conduction implicit (:mod:`.imex`); Δt from the acoustic CFL and cooling limits only.
* ``ssprk3``: third-order strong-stability-preserving Runge–Kutta (Shu & Osher 1988),
  U1 = U + Δt L(U);  U2 = 3/4 U + 1/4 (U1 + Δt L(U1));  U' = 1/3 U + 2/3 (U2 + Δt L(U2)),
  with the diffusive limits added.

One Δt per step from the limits at the step start.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import jax
import jax.numpy as jnp

from .friction import cell_coefficients, explicit_part
from .fluxes import (LIMITERS, RIEMANN_SOLVERS, cell_divergence, flux_divergence, kernel_fields,
                     materialise, pad_fields)
from .grid import Grid, periodic
from .acoustics import MODES as ACOUSTICS
from .acoustics import AcousticStage, advective_divergence, enthalpy
from .imex import EXPLICIT_WEIGHTS, GAMMA, IMPLICIT_WEIGHTS, implicit_stage
from .physics import Physics
from .sources import add_body_force, cooling_source
from .state import primitive_fields
from .cell_terms import LIMIT_TERMS, kernel_stage_inputs, limit_terms, status_terms

STATUS_MESSAGES = {
    0: "ok",
    1: "non-finite value (NaN or inf)",
    2: "granular temperature theta <= 0",
    3: "solid fraction reached phi_stop (near the packing limit)",
    4: "density <= 0",
    5: "stable time step collapsed",
    6: "implicit (IMEX) stage solve did not converge",
}
SCHEMES = ("imex", "ssprk3")
SINKS = ("explicit", "implicit")
#: Largest ζ0Δt of an implicit sink.  ARS(2,2,2) keeps a decaying θ positive only for ζΔt < 1/(1 − 2γ)
#: = 1 + √2 ≈ 2.41: its stability function R(−x) = (1 − (1 − 2γ)x)/(1 + γx)² changes sign there, and
#: the predictor of the last stage, θⁿ − (1 − γ)Δt ζθ₂, does too (measured: a cooling box stepped at
#: ζ0Δt = 4 gave NaN, at 2 a positive θ).  2.0 keeps a margin (ζ0 ∝ √θ changes within a step).
SINK_COURANT = 2.0
#: Names of the step limits of :func:`step_limits`, in order.
LIMIT_NAMES = ("cfl", "viscous", "conductive", "cooling")


@jax.tree_util.register_pytree_node_class
@dataclass(frozen=True)
class Numerics:
    """Numerical options: a pytree whose Courant numbers are traced and whose scheme choices are static.

    Parameters
    ----------
    cfl : float
        Acoustic Courant number: Δt ≤ cfl / max Σ_a (|u_a| + c)/Δx_a.
    cfl_diffusion : float
        Explicit scheme only: Δt ≤ cfl_diffusion / (2 max D Σ_a Δx_a⁻²) for both D = (4η/3 + λ_b)/ρ
        (viscous) and D = κ/(3ρ/2) (conductive).
    cfl_source : float
        Δt ≤ cfl_source / max|ζ| (must be < 1 for the positivity argument of :mod:`.sources`).
    limiter : str
        MUSCL slope limiter, one of ``minmod``, ``vanleer``, ``mc``, ``none``.
    riemann : str
        ``hll`` or ``rusanov``.
    dt_max : float
        Upper bound on Δt [s] (``inf``: none).
    scheme : str
        ``imex`` (ARS(2,2,2), viscous and heat fluxes implicit: :mod:`.imex`) or ``ssprk3``
        (everything explicit).
    implicit_tol : float
        Relative residual of the implicit stage solves (BiCGSTAB, CG).
    implicit_maxiter : int
        Krylov iterations of each stage solve, in units of :data:`~ktgf.solver.imex.RESTART` (10).
    sweeps : int
        Picard passes updating the frozen θ of the implicit coefficients (2 keeps second order).
    acoustics : str
        ``explicit`` (the HLL convective flux, Courant limit on |u| + c) or ``implicit`` (IMEX
        only: the pressure waves in the implicit part, :mod:`.acoustics`; Courant limit on |u|).
    sink : str
        ``explicit`` (the collisional sink −(3/2)ρθζ0 with the convective flux; Δt ≤ cfl_source/ζ) or
        ``implicit`` (IMEX only: ζ0 in the energy stage solve, linearised in θ, :func:`.imex.implicit_stage`;
        the cooling limit keeps only |ζ_U∇·u|).
    mixed : bool
        IMEX with a float32 state: solve the stages with float32 vectors and float64 inner
        products and norms (:func:`~ktgf.solver.imex.implicit_stage`), instead of casting the
        stage to float64 (``numerics.precision = "mixed"``).
    """

    cfl: float = 0.4
    cfl_diffusion: float = 0.4
    cfl_source: float = 0.5
    limiter: str = "vanleer"
    riemann: str = "hll"
    dt_max: float = float("inf")
    scheme: str = "imex"
    implicit_tol: float = 1e-6
    implicit_maxiter: int = 5
    sweeps: int = 1
    mixed: bool = False
    acoustics: str = "explicit"
    sink: str = "explicit"

    _LEAVES = ("cfl", "cfl_diffusion", "cfl_source", "dt_max", "implicit_tol")
    _STATIC = ("limiter", "riemann", "scheme", "implicit_maxiter", "sweeps", "mixed", "acoustics", "sink")

    def tree_flatten(self) -> tuple[tuple, tuple]:
        return tuple(getattr(self, k) for k in self._LEAVES), tuple(getattr(self, k) for k in self._STATIC)

    @classmethod
    def tree_unflatten(cls, aux: tuple, leaves: tuple) -> Numerics:
        obj = object.__new__(cls)
        for name, v in zip(cls._LEAVES + cls._STATIC, (*leaves, *aux)):
            object.__setattr__(obj, name, v)
        return obj

    def __post_init__(self) -> None:
        from ..errors import InputError

        options = {"limiter": (self.limiter, LIMITERS), "riemann solver": (self.riemann, RIEMANN_SOLVERS),
                   "time scheme": (self.scheme, SCHEMES), "acoustics": (self.acoustics, ACOUSTICS),
                   "sink": (self.sink, SINKS)}
        for what, (value, valid) in options.items():
            if value not in valid:
                raise InputError(f"{what} {value!r} is not valid: choose one of {valid}")
        for what in ("acoustics", "sink"):
            if getattr(self, what) == "implicit" and self.scheme != "imex":
                raise InputError(f"{what} 'implicit' needs the imex scheme (got scheme {self.scheme!r})")


def explicit_coefficients(r: Any, num: Numerics) -> Any:
    """The cell coefficients of the IMEX scheme's explicit part: without the frictional work
    (:func:`.friction.explicit_part`) and, with ``num.sink = "implicit"``, without ζ0 (both are in
    the implicit stage solve); ζ_U∇·u stays explicit."""
    r = explicit_part(r)
    return r._replace(zeta0=jnp.zeros_like(r.zeta0)) if num.sink == "implicit" else r


def explicit_rhs(U: Any, grid: Grid, phys: Physics, num: Numerics, viscous: bool, r: Any = None,
                 t: Any = 0.0, h0: Any = None) -> list[Any]:
    """−∇·F + S: the convective flux, sink and body force (+ viscous and heat flux if ``viscous``).

    ``r``: cell coefficients of ρ already evaluated (the closures run once per cell and stage);
    ``t``: the time (of the moving boundaries); ``h0``: implicit acoustics, the frozen enthalpy
    of the step start — the convective flux is then the explicit part of :mod:`.acoustics`.
    """
    W = materialise(primitive_fields(U))
    if r is None:
        r = cell_coefficients(W, grid, phys, t)
    eos = phys.eos(W[0], W[4], r)
    if h0 is not None:
        dU, divu = advective_divergence(W, eos, h0, grid, num.limiter, t)
    else:
        transport = phys.transport(W[0], W[4], r) if viscous else ()
        dU, divu = flux_divergence(W, (eos, transport), grid, phys, num.limiter, num.riemann, viscous=viscous, t=t)
    source, _ = cooling_source(W, divu, phys, r)
    dU[4] = dU[4] + source
    return add_body_force(dU, W, phys)


def rhs(U: Any, grid: Grid, phys: Physics, num: Numerics, t: Any = 0.0) -> Any:
    """dU/dt = −∇·F(U) + S(U) (all terms)."""
    return tuple(explicit_rhs(U, grid, phys, num, viscous=True, t=t))


def divu_bound(maxima: Any, grid: Grid) -> Any:
    """A bound of the central ∇·u on a periodic grid from the maxima of :data:`LIMIT_TERMS`:
    |∇·u| ≤ Σ_a (max u_a − min u_a)/(2Δx_a), with −min u_a = max(−u_a).

    Plain reductions only, since a stencil inside XLA's CPU reduction loop makes it an order of
    magnitude slower."""
    return sum((maxima[5 + a] + maxima[8 + a]) * (0.5 / grid.spacing[a]) for a in range(grid.ndim))


def limits_of_maxima(maxima: Any, grid: Grid, num: Numerics, divu_max: Any) -> Any:
    """The four step limits (acoustic CFL, viscous, conductive, cooling) [s] from the maxima of
    :data:`LIMIT_TERMS` over the cells and a bound ``divu_max`` of |∇·u|: max |ζ| ≤ max ζ0 + max |ζ_U| max |∇·u|."""
    inv_dx2 = sum(1.0 / h**2 for h in grid.spacing)
    viscous = num.cfl_diffusion / (2.0 * inv_dx2 * maxima[1])
    conductive = num.cfl_diffusion / (2.0 * inv_dx2 * maxima[2])
    cooling = num.cfl_source / (maxima[3] + maxima[4] * divu_max)
    return jnp.stack([num.cfl / maxima[0], viscous, conductive, cooling])


def step_limits(U: Any, grid: Grid, phys: Physics, num: Numerics, r: Any = None) -> Any:
    """The four step limits (acoustic CFL, viscous, conductive, cooling) of :class:`Numerics` [s]."""
    W = primitive_fields(U)
    rho, u, theta = W[0], W[1:4], W[4]
    if r is None:
        r = cell_coefficients(W, grid, phys)
    maxima = [jnp.max(f) for f in limit_terms(W, r, phys, num.acoustics, grid.spacing)]
    divu_max = divu_size(u, maxima, grid)
    lim = limits_of_maxima(maxima, grid, num, divu_max)
    if num.sink == "implicit":  # ζ0 in the implicit part: SINK_COURANT/ζ0 for it, cfl_source/ζ for the rest
        r_e = r._replace(zeta0=jnp.zeros_like(r.zeta0))
        zeta0 = jnp.max(phys.cooling_rate(rho, theta, 0.0, r) - phys.cooling_rate(rho, theta, 0.0, r_e))
        zeta_e = jnp.max(phys.cooling_rate(rho, theta, 0.0, r_e)) + maxima[4] * divu_max
        lim = lim.at[3].set(jnp.minimum(SINK_COURANT / zeta0, num.cfl_source / zeta_e))
    return lim


def divu_size(u: Any, maxima: Any, grid: Grid) -> Any:
    """A bound of |∇·u| over the cells: :func:`divu_bound` on a periodic grid; elsewhere, where a mean shear makes
    max u − min u large, the largest central ∇·u itself (at any time: only its size matters)."""
    if periodic(grid):
        return divu_bound(maxima, grid)
    return jnp.max(jnp.abs(cell_divergence(pad_fields(u, grid, velocity=0), grid)))


def kernel_step_limits(maxima: Any, u: Any, grid: Grid, num: Numerics) -> Any:
    """:func:`step_limits` from the maxima the kernel reduced (:func:`.flux_kernel.cell_limits`) and the velocity."""
    return limits_of_maxima(maxima[:len(LIMIT_TERMS)], grid, num, divu_size(u, maxima, grid))


def dt_of_limits(lim: Any, num: Numerics) -> Any:
    """The step of the scheme from the limits of :func:`step_limits` (the IMEX scheme has no diffusive ones)."""
    dt = jnp.minimum(lim[0], lim[3])
    if num.scheme == "ssprk3":
        dt = jnp.minimum(dt, jnp.minimum(lim[1], lim[2]))
    return jnp.minimum(dt, num.dt_max)


def stage_kernel_applies(grid: Grid, phys: Physics, num: Numerics, dtype: Any) -> bool:
    """Whether an SSP-RK3 stage runs as one C++ kernel call (:func:`.flux_kernel.ssprk_stage`): where the
    flux kernel's stage variant of ``num``'s limiter and Riemann solver applies (CPU, one device, 3D; built
    now if needed).  It adds the body force and the corrections of boundaries other than periodic itself."""
    from . import flux_kernel, fluxes

    return (fluxes.FLUX_KERNEL and fluxes.STAGE_KERNEL
            and flux_kernel.applies(grid, dtype, "stage", num.limiter, num.riemann))


def cell_programs_apply(grid: Grid) -> bool:
    """Whether the stage kernel may evaluate the closures itself (:mod:`.cell_program`): on a periodic grid
    (its ghost cells' closures are those of the cells they image) or with its boundaries along y or z, whose
    ghost cells' fields it then takes from :func:`cell_boundary_terms`."""
    from . import fluxes

    return fluxes.CELL_PROGRAM and (periodic(grid) or (grid.ndim == 3 and fluxes.boundary_axis(grid) in (1, 2)))


def cell_boundary_terms(Uk: Any, grid: Grid, phys: Physics, num: Numerics, t: Any) -> tuple:
    """The ghost planes and boundary correction (:func:`.fluxes.boundary_terms`) of a stage at Uk whose closures a
    cell program evaluates in the kernel: the closures of the cells next to the boundary only, here; (None, None)
    on a periodic grid."""
    from .fluxes import boundary_terms, grid_ends

    if periodic(grid):
        return None, None
    ends = grid_ends(Uk, grid)
    W = primitive_fields(ends.fields)
    r = cell_coefficients(W, ends.grid, phys, t)
    ends.fields = [*W, *phys.eos(W[0], W[4], r), *phys.transport(W[0], W[4], r)]
    return boundary_terms(ends, grid, phys, num.limiter, num.riemann, True, t)


def checks_program(grid: Grid, phys: Physics, num: Numerics, dtype: Any) -> Any:
    """The step-start cell program whose kernel reduction (:func:`.flux_kernel.cell_limits`) gives the step limits
    and the state checks of SSP-RK3 steps on the stage kernel, or None where those come from XLA reductions (no
    stage kernel, closures without a cell program, another scheme, or the implicit sink, whose cooling limit is not
    :func:`limits_of_maxima`'s)."""
    from .cell_program import for_physics

    if not (num.scheme == "ssprk3" and num.sink == "explicit" and stage_kernel_applies(grid, phys, num, dtype)):
        return None
    return for_physics(phys, dtype, limits=num.acoustics)


def ssprk3_step(U: Any, dt: Any, grid: Grid, phys: Physics, num: Numerics, t: Any = 0.0, r0: Any = None) -> Any:
    """One SSP-RK3 step of size dt (``r0``: the cell coefficients of U, if already evaluated).

    Written as three stages U_{k+1} = a_k U + (1 − a_k)(U_k + Δt L(U_k)), a = (0, 3/4, 1/3),
    in a ``fori_loop`` so the right-hand side is traced (and compiled) once, not three times.
    Where :func:`stage_kernel_applies`, each stage is the closures (XLA) and one kernel call, or
    only the kernel call where the closures have a cell program (:mod:`.cell_program`, :func:`cell_programs_apply`);
    with boundaries, the kernel takes the ghost planes of their axis and the boundary planes' corrections, and it
    adds the body force.
    """
    coef = jnp.asarray([0.0, 0.75, 1.0 / 3.0], dtype=U[0].dtype)
    when = jnp.asarray([0.0, 1.0, 0.5], dtype=jnp.result_type(t, float))  # stage times / Δt

    if stage_kernel_applies(grid, phys, num, U[0].dtype):
        from .cell_program import for_physics, leaf_values
        from .flux_kernel import ssprk_stage, ssprk_stage_cells

        program = for_physics(phys, U[0].dtype) if cell_programs_apply(grid) else None
        if program is not None:  # the closures inside the kernel: each stage is one call
            leaf = leaf_values(phys)

            def cells_stage(k: int, Uk: tuple, write_over: str) -> tuple:
                ghosts, fix = cell_boundary_terms(Uk, grid, phys, num, t + when[k] * dt)
                return ssprk_stage_cells(U, Uk, program, leaf, coef[k], dt, grid, phys.material_density, num.limiter,
                                         num.riemann, write_over, ghosts=ghosts, fix=fix, gravity=phys.gravity)

            U = tuple(U)
            # The first stage writes new buffers (U is still needed), the later ones over their input (the boundary
            # terms, read from it, are the kernel's inputs: no copy, measured with walls and Lees–Edwards).
            return cells_stage(2, cells_stage(1, cells_stage(0, U, "new"), "uk"), "uk")

        def kernel_stage(k: Any, Uk: tuple, r: Any) -> tuple:
            W, eos, transport, source = kernel_stage_inputs(Uk, r, phys)
            *fields, ghosts, fix = kernel_fields(W, eos, transport, grid, phys, num.limiter, num.riemann, True,
                                                 t + when[k] * dt)
            return ssprk_stage(U, Uk, *fields, source, coef[k], dt, grid, phys.material_density, num.limiter,
                               num.riemann, ghosts, fix, phys.gravity)

        if r0 is None:
            r0 = cell_coefficients(primitive_fields(U), grid, phys, t)
        U1 = kernel_stage(0, tuple(U), r0)  # the closures of U are the step limits' (advance)
        return jax.lax.fori_loop(1, 3, lambda k, Uk: kernel_stage(
            k, Uk, cell_coefficients(primitive_fields(Uk), grid, phys, t + when[k] * dt)), U1)

    def stage(k: Any, Uk: tuple) -> tuple:
        a = coef[k]
        L = rhs(Uk, grid, phys, num, t + when[k] * dt)
        return tuple(a * u + (1.0 - a) * (uk + dt * l) for u, uk, l in zip(U, Uk, L))

    return jax.lax.fori_loop(0, 3, stage, tuple(U))


def imex_step(U: Any, dt: Any, grid: Grid, phys: Physics, num: Numerics, t: Any = 0.0,
              r0: Any = None) -> tuple[Any, Any]:
    """One ARS(2,2,2) step (:mod:`.imex`); returns the state and the worst solve residual / tolerance.

    ``r0``: the cell coefficients of U, if already evaluated (the step limits' in :func:`advance`).

    The two implicit stages run in a ``fori_loop`` (traced once); the closures are evaluated
    once per stage, at the stage density, and shared by the implicit solve and the next
    explicit evaluation.
    """
    dtype = U[0].dtype
    wE = jnp.asarray(EXPLICIT_WEIGHTS, dtype)
    wI = jnp.asarray(IMPLICIT_WEIGHTS, dtype)
    Un = tuple(U)
    t = jnp.asarray(t, jnp.result_type(t, float))
    # Times of the explicit evaluation (Uⁿ, U₂) and of the implicit solve (U₂, U₃) of each stage.
    t_explicit = t + jnp.asarray([0.0, GAMMA], t.dtype) * dt
    t_implicit = t + jnp.asarray([GAMMA, 1.0], t.dtype) * dt

    acoustic = num.acoustics == "implicit"
    h0 = None
    if acoustic:  # the enthalpy of the linear/non-linear split, frozen at Uⁿ for the step (:mod:`.acoustics`)
        h0 = enthalpy(Un, r0 if r0 is not None else cell_coefficients(primitive_fields(Un), grid, phys, t), phys)

    def stage(k: Any, carry: tuple) -> tuple:
        Uk, rk, KE1, KI2, worst = carry
        KE = explicit_rhs(Uk, grid, phys, num, viscous=False, r=explicit_coefficients(rk, num), t=t_explicit[k], h0=h0)
        KE1 = tuple(jnp.where(k == 0, a, b) for a, b in zip(KE, KE1))
        Uhat = tuple(u + dt * (wE[k, 0] * e1 + wE[k, 1] * e + wI[k] * i2)
                     for u, e1, e, i2 in zip(Un, KE1, KE, KI2))
        # Plain float32: the stage solves run in float64 (float32 Krylov iterations stall above
        # the tolerance: residual 67x the limit after a few steps).  Mixed: float32 vectors,
        # float64 inner products (docs/solver.md, Speed).
        Uhat64 = Uhat if num.mixed else tuple(u.astype(jnp.float64) for u in Uhat)
        r = cell_coefficients(primitive_fields(Uhat64), grid, phys, t_implicit[k])
        stage_acoustics = AcousticStage(h0.astype(Uhat64[0].dtype), lambda W: cell_coefficients(
            W, grid, phys, t_implicit[k])) if acoustic else None
        Ui, fI, res = implicit_stage(Uhat64, GAMMA * jnp.asarray(dt, jnp.float64).astype(Uhat64[0].dtype), grid, phys,
                                     r, jnp.asarray(num.implicit_tol, jnp.float64), num.implicit_maxiter, num.sweeps,
                                     t_implicit[k], mixed=num.mixed, acoustic=stage_acoustics,
                                     sink=num.sink == "implicit")
        r = jax.tree_util.tree_map(lambda x: jnp.asarray(x).astype(dtype), r)
        return tuple(u.astype(dtype) for u in Ui), r, KE1, \
            tuple(jnp.broadcast_to(f, Un[0].shape).astype(dtype) for f in fI), jnp.maximum(worst, res.astype(dtype))

    zeros = tuple(jnp.zeros_like(u) for u in Un)
    if r0 is None:
        r0 = cell_coefficients(primitive_fields(Un), grid, phys, t)
    r0 = jax.tree_util.tree_map(lambda x: jnp.asarray(x).astype(dtype), r0)
    init = (Un, r0, zeros, zeros, jnp.zeros((), dtype))
    Ui, _, _, _, worst = jax.lax.fori_loop(0, 2, stage, init)
    return Ui, worst


def scheme_step(U: Any, dt: Any, grid: Grid, phys: Physics, num: Numerics, t: Any = 0.0,
                r0: Any = None) -> tuple[Any, Any]:
    """One step of the configured scheme from time t: (state, implicit residual / tolerance — 0 for SSP-RK3).

    ``r0``: the cell coefficients of U, if already evaluated."""
    if num.scheme == "imex":
        return imex_step(U, dt, grid, phys, num, t, r0)
    return ssprk3_step(U, dt, grid, phys, num, t, r0), jnp.zeros((), U[0].dtype)


#: CPU time of one IMEX step over one SSP-RK3 step, measured (RET at φ = 0.5 with Δx = ℓ, 32³: 108 against 36 ms).
IMEX_COST = 3.0
#: The same where SSP-RK3's stages run on cell programs (:func:`cell_programs_apply`), measured likewise in
#: float64 at the steady state, CPU time: 9.4, 11.6× at 32³, 64³ (528.3 against 45.7 ms at 64³).
IMEX_COST_CELLS = 10.0


def auto_ratio(grid: Grid, phys: Physics, num: Numerics, dtype: Any) -> float:
    """The step ratio (IMEX over SSP-RK3) above which ``auto`` picks IMEX: twice the break-even, whose cost
    ratio is :data:`IMEX_COST_CELLS` where SSP-RK3's stages would run on cell programs, else :data:`IMEX_COST`.
    The factor two is a margin for IMEX's compilation (≈ 4× that of SSP-RK3, measured; 10× against SSP-RK3 on
    cell programs: 6.8 s against 0.6–0.7 s at 32³)."""
    explicit = replace(num, scheme="ssprk3", sink="explicit", acoustics="explicit")
    cells = cell_programs_apply(grid) and checks_program(grid, phys, explicit, dtype) is not None
    return 2.0 * (IMEX_COST_CELLS if cells else IMEX_COST)


def choose_scheme(U: Any, grid: Grid, phys: Physics, num: Numerics) -> str:
    """``imex`` or ``ssprk3``: IMEX where its step exceeds the explicit one by :func:`auto_ratio`."""
    lim = [float(v) for v in limits(U, grid, phys, num)]
    explicit = min(lim)
    ratio = auto_ratio(grid, phys, num, U[0].dtype)
    return "imex" if min(lim[0], lim[3]) > ratio * explicit else "ssprk3"


def binding_limit(lim: Any, scheme: str) -> str:
    """Name of the smallest of the step limits the scheme obeys."""
    active = (0, 3) if scheme == "imex" else (0, 1, 2, 3)
    return LIMIT_NAMES[min(active, key=lambda i: float(lim[i]))]


#: An implicit solve whose final relative residual exceeds this multiple of its tolerance fails.
RESIDUAL_FAIL = 10.0


def status_of_maxima(maxima: Any, phys: Physics) -> Any:
    """Status code (0 fine, 1 non-finite, 2 θ ≤ 0, 3 φ ≥ phi_stop, 4 ρ ≤ 0; the first that applies) from the
    maxima over the cells of :data:`STATUS_TERMS` (a NaN wins a maximum, as in ``jnp.max``)."""
    nonfinite, neg_theta, rho, neg_rho = maxima
    return jnp.where(
        ~jnp.isfinite(nonfinite), 1,
        jnp.where(neg_theta >= 0.0, 2,
                  jnp.where(rho >= phys.phi_stop * phys.material_density, 3,
                            jnp.where(neg_rho >= 0.0, 4, 0))),
    ).astype(jnp.int32)


def state_status(U: Any, phys: Physics) -> Any:
    """Status code (:func:`status_of_maxima`) of a state."""
    return status_of_maxima([jnp.max(f) for f in status_terms(U, primitive_fields(U))], phys)


@jax.jit
def advance(U: Any, t: Any, t_end: Any, max_steps: Any, grid: Grid, phys: Physics, num: Numerics) -> tuple:
    """Step from time t towards t_end (the last step is shortened to land on it exactly).

    Returns ``(U, t, steps, status, dt)``: the last good state and its time, the number of
    accepted steps, the status code of the first rejected step (0 if none) and the Δt of the
    last attempted step (to reproduce a failure for its diagnosis).

    With a step-start cell program (:func:`checks_program`) the kernel reduces the :data:`START_TERMS` of each
    new state once (:func:`.flux_kernel.cell_limits`): its status, and the next step's limits.
    """
    checks = checks_program(grid, phys, num, U[0].dtype)
    if checks is not None:
        from .cell_program import leaf_values
        from .flux_kernel import cell_limits

        def start_maxima(U: Any) -> Any:  # the step limits' and the status' terms of U, reduced by the kernel
            return cell_limits(U, checks, leaf_values(phys, grid), grid, num.limiter, num.riemann)

    def cond_before(limit: Any) -> Any:
        return lambda carry: (carry[1] < t_end) & (carry[2] < limit) & (carry[3] == 0)

    def step_size(lim: Any, t: Any) -> tuple:
        # Time is kept in float64 whatever the state precision, so a float32 run still lands
        # exactly on t_end.
        dt_stable = dt_of_limits(lim, num).astype(t.dtype)
        last = dt_stable >= t_end - t
        return dt_stable, jnp.where(last, t_end - t, dt_stable), last

    def size_status(dt_stable: Any, dt: Any) -> Any:
        return jnp.where(jnp.isfinite(dt_stable) & (dt > 0), 0, 5)

    def body(carry: tuple) -> tuple:
        U, t, n, _, _, maxima = carry  # maxima: U's of the checks program (empty without it)
        # The closures of the step start, evaluated by XLA, serve both the step limits and the step's first stage
        # (none with cell programs: the kernel evaluates them).
        cells = checks is not None and cell_programs_apply(grid)
        r0 = None if cells else cell_coefficients(primitive_fields(U), grid, phys, t)
        if checks is None:
            lim = step_limits(U, grid, phys, num, r0)
        else:
            lim = kernel_step_limits(maxima, primitive_fields(U)[1:4], grid, num)
        dt_stable, dt, last = step_size(lim, t)
        U_new, residual = scheme_step(U, dt.astype(U[0].dtype), grid, phys, num, t, r0)
        if checks is None:
            new_maxima, bad_state = maxima, state_status(U_new, phys)
        else:  # the new state's check, and the next step's limits
            new_maxima = start_maxima(U_new)
            bad_state = status_of_maxima(new_maxima[len(LIMIT_TERMS):], phys)
        status = jnp.where(bad_state != 0, bad_state, size_status(dt_stable, dt))
        status = jnp.where((status == 0) & ~(residual <= RESIDUAL_FAIL), 6, status)
        good = status == 0
        t = jnp.where(good, jnp.where(last, t_end, t + dt), t)
        return (tuple(jnp.where(good, a, b) for a, b in zip(U_new, U)), t, n + good.astype(n.dtype), status, dt,
                jnp.where(good, new_maxima, maxima))

    U = tuple(U)
    t = jnp.asarray(t, jnp.float64)
    t_end = jnp.asarray(t_end, jnp.float64)
    zero = jnp.zeros((), jnp.int32)
    init = (U, t, zero, zero, jnp.zeros((), jnp.float64))
    maxima = jnp.zeros((0,), U[0].dtype) if checks is None else start_maxima(U)
    U, t, n, status, dt, _ = jax.lax.while_loop(cond_before(max_steps), body, (*init, maxima))
    return jnp.stack(U), t, n, status, dt


@jax.jit
def step(U: Any, dt: Any, grid: Grid, phys: Physics, num: Numerics, t: Any = 0.0) -> tuple[Any, Any]:
    """One step (compiled) and its implicit residual / tolerance, to reproduce a failed step for its diagnosis."""
    U_new, residual = scheme_step(tuple(U), dt, grid, phys, num, t)
    return jnp.stack(U_new), residual


@jax.jit
def limits(U: Any, grid: Grid, phys: Physics, num: Numerics) -> Any:
    """:func:`step_limits` compiled (per-output record of the binding limit)."""
    return step_limits(tuple(U), grid, phys, num)
