"""IMEX Runge–Kutta time stepping: convection and the collisional sink explicit, viscous stress
and heat conduction implicit, so Δt is set by the acoustic CFL and the cooling rate alone.

Scheme: the ARS(2,2,2) pair of Ascher, Ruuth & Spiteri (1997), *Implicit-explicit Runge–Kutta
methods for time-dependent partial differential equations*, Appl. Numer. Math. 25, 151–167,
§2.6 — second order, the implicit part L-stable and stiffly accurate (the step result is the
last stage, so no explicit evaluation of the stiff operator is needed), γ = 1 − 1/√2,
δ = 1 − 1/(2γ):

    explicit (Ã, b̃)                  implicit (A, b)
    0 | 0     0    0                 0 | 0    0    0
    γ | γ     0    0                 γ | 0    γ    0
    1 | δ   1−δ    0                 1 | 0  1−γ    γ
      | δ   1−δ    0                   | 0  1−γ    γ

For dU/dt = f_E(U) + f_I(U) one step is (f_E: convection + sink, f_I: −∇·(viscous + heat flux))

    Û₂ = Uⁿ + Δt γ f_E(Uⁿ),                       U₂ = Û₂ + Δt γ f_I(U₂)
    Û₃ = Uⁿ + Δt(δ f_E(Uⁿ) + (1−δ) f_E(U₂)) + Δt(1−γ) f_I(U₂),   Uⁿ⁺¹ = U₃ = Û₃ + Δt γ f_I(U₃)

— two convective evaluations and two implicit stage solves per step.

Implicit stage solve.  f_I has no mass component, so ρ of a stage is the known ρ̂ and the
closures (functions of φ) are evaluated once per stage at ρ̂.  With the coefficients frozen at a
temperature θ_k (η, λ_b, κ ∝ √θ, ω ∝ θ^{3/2}) the stage equation splits into two linear problems:

    ρ̂u − aΔt ∇·τ[η, λ_b](u) = m̂                                     (3 velocity components)
    (3/2)ρ̂θ − aΔt ∇·(κ∇θ) = Ê − ρ̂|u|²/2 + aΔt ∇·(τ·u + ω∇φ)           (then θ, given u)

solved by BiCGSTAB (the discrete operator is not symmetric for variable η) and CG (symmetric positive
definite), matrix-free, each preconditioned by the FFT inverse of the constant-coefficient operator (mean ρ̂,
η, λ_b, κ; the symbols of the same discrete stencils).  θ_k is θ of Û plus the explicit increment of f_I, an
O(Δt²) estimate of the stage θ that keeps the scheme second order (tests/solver/test_solver_imex.py); each
further sweep (``sweeps``) takes θ of the previous solution.  The stage state is then U = Û + aΔt f_I(ρ̂, u, θ)
with the flux divergence of the explicit scheme, so mass, momentum and energy are conserved exactly whatever
the solver residual; a solve whose relative residual exceeds 10× the tolerance rejects the step (status 6).

With ``numerics.acoustics = "implicit"`` f_I also holds the pressure waves (the mass, pressure and
enthalpy fluxes of :mod:`.acoustics`), solved in the same momentum problem as a bulk viscosity.

With ``numerics.sink = "implicit"`` f_I also holds the collisional sink S(θ) = (3/2)ρθζ0(φ, θ) (ζ0 of
:meth:`~.physics.Physics.cooling_rate`, ∝ √θ), linearised about the coefficient temperature θ_k of the
sweep: S ≈ S_k + S'_k(θ − θ_k) with S'_k = ∂S/∂θ by ``jax.jvp`` (no exponent is assumed here).  The heat
problem becomes ((3/2)ρ + aΔt S'_k)θ − aΔt∇·(κ∇θ) = … − aΔt(S_k − S'_k θ_k): S'_k > 0 keeps it
symmetric positive definite, and the constant part adds energy, so θ > 0 for any Δt (the step is no
longer limited by cfl_source/ζ0).  The energy of the stage takes the linearised sink at the solved θ,
consistent with the solve; a second sweep (``sweeps = 2``) relinearises about the first solution.
"""

from __future__ import annotations

import math
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
from jax.scipy.sparse.linalg import bicgstab, cg

from ..closures.coefficients import Reduced
from .acoustics import MIN_SWEEPS, AcousticStage, implicit_fluxes, pressure, pressure_divergence
from .fluxes import (face_coefficients, face_divergence, face_jump, face_mean, has_walls, pad_fields, pad_viscous,
                     stress, viscous_flux)
from .boundaries import lees_edwards_faces, wall_terms
from .grid import Grid
from .physics import Physics, is_frictional
from .state import primitive_fields

GAMMA = 1.0 - 1.0 / math.sqrt(2.0)
DELTA = 1.0 - 1.0 / (2.0 * GAMMA)
#: Explicit weights of (f_E(Uⁿ), f_E(U₂)) and implicit weight of f_I(U₂) in Û of stages 2 and 3.
EXPLICIT_WEIGHTS = ((GAMMA, 0.0), (DELTA, 1.0 - DELTA))
IMPLICIT_WEIGHTS = (0.0, 1.0 - GAMMA)
#: Krylov iterations per unit of ``implicit_maxiter``.
RESTART = 10


def _symbols(grid: Grid, dtype: Any) -> tuple[list[Any], list[Any]]:
    """Fourier symbols (rfftn layout) of the discrete stencils, per grid axis.

    s²_a = (2 sin(πm/n)/Δx)² (two-point second difference, −∂²), t_a = sin(2πm/n)/Δx
    (central difference, i∂); arrays broadcastable to the rfftn shape of a field.
    """
    s2, t = [], []
    for a, n in enumerate(grid.cells):
        m = np.fft.rfftfreq(n) * n if a == grid.ndim - 1 else np.fft.fftfreq(n) * n
        shape = [m.size if b == a else 1 for b in range(grid.ndim)]
        h = grid.spacing[a]
        s2.append(jnp.asarray((2.0 * np.sin(np.pi * m / n)) ** 2, dtype).reshape(shape) / (h * h))
        t.append(jnp.asarray(np.sin(2.0 * np.pi * m / n), dtype).reshape(shape) / h)
    return s2, t


def _fft(f: Any, grid: Grid) -> Any:
    return jnp.fft.rfftn(f, axes=tuple(range(grid.ndim)))


def _ifft(f: Any, grid: Grid, dtype: Any) -> Any:
    return jnp.fft.irfftn(f, s=grid.cells, axes=tuple(range(grid.ndim))).astype(dtype)


def momentum_preconditioner(grid: Grid, rho: Any, eta: Any, lam: Any, adt: Any, dtype: Any):
    """Exact inverse of ρ − aΔt∇·τ[η, λ_b] for constant ρ, η, λ_b (per wavevector a 3×3 system).

    Symbol of −∇·τ: η|s|² I + c(diag(s²) − diag(t²)) + c t tᵀ, c = η/3 + λ_b; the matrix
    D + c' t tᵀ is inverted by the Sherman–Morrison formula (D > 0 since t² ≤ s²).
    """
    s2, t = (x + [0.0] * (3 - grid.ndim) for x in _symbols(grid, dtype))
    s2sum = sum(s2)
    c = adt * (eta / 3.0 + lam)
    D = [rho + adt * eta * s2sum + c * (s2[j] - t[j] * t[j]) for j in range(3)]

    def apply(r: tuple) -> tuple:
        y = [_fft(x, grid) / d for x, d in zip(r, D)]
        num = sum(t[j] * y[j] for j in range(3))
        den = 1.0 + c * sum(t[j] * t[j] / D[j] for j in range(3))
        coef = c * num / den
        return tuple(_ifft(y[j] - coef * t[j] / D[j], grid, dtype) for j in range(3))

    return apply


def heat_preconditioner(grid: Grid, mass: Any, kappa: Any, adt: Any, dtype: Any):
    """Exact inverse of m − aΔt∇·(κ∇) for constant m (= (3/2)ρ, plus aΔt S' with an implicit sink) and κ."""
    D = mass + adt * kappa * sum(_symbols(grid, dtype)[0])
    return lambda r: _ifft(_fft(r, grid) / D, grid, dtype)


def viscous_divergence(W: tuple, transport: tuple, grid: Grid, phys: Physics, t: Any = 0.0,
                       walls: Any = None) -> list[Any]:
    """f_I = −∇·(viscous + heat flux) at the cells: (0, ∇·τ, ∇·(τ·u) − ∇·q) (``t``: time of the boundaries;
    ``walls``: frozen wall coefficients, else from W)."""
    P = pad_viscous(W, transport, grid, phys, t, walls)
    Pk = pad_fields(transport, grid, t)
    out: list[Any] = [0.0] * 4
    for a in range(grid.ndim):
        F = lees_edwards_faces(viscous_flux(P, Pk, a, grid, phys.material_density), grid, a, t)
        dF = face_divergence(jnp.stack([jnp.broadcast_to(f, F[1].shape) for f in F[1:]]), grid, a)
        out = [o + dF[i] for i, o in enumerate(out)]
    return [jnp.zeros_like(W[0]), *out]


def _face_sum(faces: list[Any], grid: Grid, axis: int) -> Any:
    """Sum of a face coefficient over the two faces of every cell along ``axis``."""
    n = grid.cells[axis]
    f = faces[axis]
    return jax.lax.slice_in_dim(f, 0, n, axis=axis) + jax.lax.slice_in_dim(f, 1, n + 1, axis=axis)


def _scaled(apply: Any, scale: Any) -> Any:
    """S⁻¹ M⁻¹ S⁻¹: the constant-coefficient inverse with the diagonal variation of the operator."""
    if isinstance(scale, tuple):
        return lambda r: tuple(y / s for y, s in zip(apply(tuple(x / s for x, s in zip(r, scale))), scale))
    return lambda r: apply(r / scale) / scale


def _leaves(x: Any) -> tuple:
    return x if isinstance(x, tuple) else (x,)


def _dot(x: Any, y: Any, acc: Any = None) -> Any:
    """Σ x·y over all cells and components, accumulated in ``acc`` (default: the dtype of x)."""
    acc = acc or _leaves(x)[0].dtype
    return sum(jnp.sum(a.astype(acc) * b.astype(acc)) for a, b in zip(_leaves(x), _leaves(y)))


def _norm(x: Any, acc: Any = None) -> Any:
    return jnp.sqrt(_dot(x, x, acc))


def _axpy(x: Any, a: Any, y: Any) -> Any:
    """x + a·y with a (a float64 scalar of the mixed solvers) cast to the dtype of the vectors."""
    return jax.tree_util.tree_map(lambda u, v: u + a.astype(u.dtype) * v, x, y)


def _until(b: Any, tol: Any, atol: Any, maxiter: int) -> tuple[Any, Any]:
    """The loop condition of a solve of ``b`` with float64 norms (iterate while ‖r‖ > max(tol‖b‖, atol) and
    fewer than ``maxiter`` iterations; the carry holds r second and the count last), and that bound squared."""
    stop2 = jnp.maximum(tol * _norm(b, jnp.float64), atol) ** 2
    return lambda c: (_dot(c[1], c[1], jnp.float64) > stop2) & (c[-1] < maxiter), stop2


def _bicgstab64(A: Any, b: Any, tol: Any, atol: Any, maxiter: int, M: Any) -> Any:
    """Right-preconditioned BiCGSTAB (van der Vorst 1992) with float32 vectors and float64 inner products.

    The same iteration as ``jax.scipy.sparse.linalg.bicgstab`` (x0 = 0, stop at
    ‖r‖ ≤ max(tol‖b‖, atol)); only the scalars (inner products, norms, α, ω) are float64.
    """
    f8 = jnp.float64
    cond, stop2 = _until(b, tol, atol, maxiter)
    zero = jax.tree_util.tree_map(jnp.zeros_like, b)
    one = jnp.ones((), f8)

    def body(c: tuple) -> tuple:
        x, r, rhat, p, v, rho_old, alpha, omega, k = c
        rho = _dot(rhat, r, f8)
        beta = (rho / rho_old) * (alpha / omega)
        p = _axpy(r, beta, _axpy(p, -omega, v))
        ph = M(p)
        v = A(ph)
        alpha = rho / _dot(rhat, v, f8)
        s = _axpy(r, -alpha, v)
        sh = M(s)
        tv = A(sh)
        done = _dot(s, s, f8) <= stop2  # converged at the half step: no ω update (ω = 0 would break it)
        omega = jnp.where(done, one, _dot(tv, s, f8) / _dot(tv, tv, f8))
        x = _axpy(_axpy(x, alpha, ph), jnp.where(done, 0.0, omega), sh)
        r = jax.tree_util.tree_map(lambda a, b_: jnp.where(done, a, b_), s, _axpy(s, -omega, tv))
        return x, r, rhat, p, v, rho, alpha, omega, k + 1

    return jax.lax.while_loop(cond, body, (zero, b, b, zero, zero, one, one, one, 0))[0]


def _cg64(A: Any, b: Any, tol: Any, atol: Any, maxiter: int, M: Any) -> Any:
    """Preconditioned CG with float32 vectors and float64 inner products (else as ``jax.scipy``'s ``cg``)."""
    f8 = jnp.float64
    cond, _ = _until(b, tol, atol, maxiter)
    z = M(b)

    def body(c: tuple) -> tuple:
        x, r, p, gamma, k = c
        Ap = A(p)
        alpha = gamma / _dot(p, Ap, f8)
        x = _axpy(x, alpha, p)
        r = _axpy(r, -alpha, Ap)
        z = M(r)
        gamma_new = _dot(r, z, f8)
        p = _axpy(z, gamma_new / gamma, p)
        return x, r, p, gamma_new, k + 1

    return jax.lax.while_loop(cond, body, (jnp.zeros_like(b), b, z, _dot(b, z, f8), 0))[0]


def _unit(x: Any, acc: Any = None) -> Any:
    """The norm of x, or 1 where it is 0 (to solve on a unit right-hand side)."""
    n = _norm(x, acc)
    return jnp.where(n > 0, n, 1.0).astype(_leaves(x)[0].dtype)


def collisional_sink(rho: Any, theta: Any, r: Reduced, phys: Physics) -> tuple[Any, Any]:
    """S = (3/2)ρθζ0 [W/m³] of the cells at θ and ∂S/∂θ (ζ0 alone: no ζ_U∇·u, no frictional work)."""
    r0 = r._replace(zeta_f=jnp.zeros_like(r.zeta_f)) if is_frictional(r) else r
    return jax.jvp(lambda th: 1.5 * rho * th * phys.cooling_rate(rho, th, 0.0, r0), (theta,), (jnp.ones_like(theta),))


def implicit_stage(Uhat: tuple, adt: Any, grid: Grid, phys: Physics, r: Reduced, tol: Any, maxiter: int,
                   sweeps: int, t: Any = 0.0, mixed: bool = False,
                   acoustic: AcousticStage | None = None, sink: bool = False) -> tuple[tuple, list[Any], Any]:
    """Solve U = Û + aΔt f_I(U) (see the module docstring) at the stage time ``t``.

    ``sink``: f_I also holds the collisional sink (3/2)ρθζ0, linearised in θ about each sweep's θ_k.

    ``acoustic``: f_I also holds the acoustic part of the convective flux (:mod:`.acoustics`): the
    momentum problem gains the bulk viscosity aΔtρc² and the pressure of the latest iterate, and
    mass and energy take their implicit fluxes; at least :data:`~.acoustics.MIN_SWEEPS` sweeps.

    ``mixed``: a float32 stage solved with float32 vectors and float64 inner products, norms and
    Krylov scalars (:func:`_bicgstab64`, :func:`_cg64`); else everything in the dtype of Û.

    Returns the stage state, f_I at it, and the largest relative residual divided by ``tol``.
    Boundaries: the Krylov operators leave out the affine parts, which enter the right-hand side (:mod:`.boundaries`,
    "Affine parts"); the FFT preconditioner stays the periodic one (only the iteration count depends on it).
    """
    dtype = Uhat[0].dtype
    Wh = primitive_fields(Uhat)
    rho = rho_hat = Wh[0]
    m_hat, E_hat = Uhat[1:4], Uhat[4]
    rho_mean = jnp.mean(rho)
    u, theta = tuple(Wh[1:4]), Wh[4]
    floor = 100.0 * float(jnp.finfo(dtype).eps)
    inv_dx2 = [1.0 / (h * h) for h in grid.spacing]
    # Coefficient temperature: θ of Û plus the explicit implicit-part increment, an O(Δt²)
    # estimate of the stage θ (kept within a factor 2 of θ̂, which only matters far outside the
    # asymptotic range).
    # A frictional stress's work 2μ_f S:S (docs/friction.md §7) is removed here, in the implicit part with
    # the frictional heating it cancels, frozen with μ_f at the stage start (as a rate ∝ θ, or explicitly,
    # the stage-start θ biased the steady θ by O(ζΔt), 4-7 % measured; explicitly a stiff one overshot).
    friction_sink = 1.5 * rho * theta * r.zeta_f if is_frictional(r) else 0.0
    galilean = acoustic is not None and grid.boundaries is not None and grid.boundaries.shear_axis is not None
    if acoustic is not None:
        sweeps = max(sweeps, MIN_SWEEPS)
        p_ref, d_ref = pressure(rho, theta, r, phys), [0.0] * grid.ndim  # Û holds no compression
    fI = viscous_divergence(Wh, phys.transport(rho, theta, r), grid, phys, t)
    fI[4] = fI[4] - friction_sink - (collisional_sink(rho, theta, r, phys)[0] if sink else 0.0)
    heat = fI[4] - sum(x * f for x, f in zip(u, fI[1:4]))
    theta = jnp.clip(theta + adt * heat / (1.5 * rho), 0.5 * theta, 2.0 * theta)

    worst = jnp.zeros((), dtype)
    acc = jnp.float64 if mixed else None
    solve_m = (lambda *a, **k: (_bicgstab64(*a[:2], **k), None)) if mixed else bicgstab
    solve_E = (lambda *a, **k: (_cg64(*a[:2], **k), None)) if mixed else cg
    for sweep in range(sweeps):
        if acoustic is not None and sweep > 0:  # linearise about the previous sweep's state
            r = acoustic.coefficients((rho, *u, theta))
            p_ref = pressure(rho, theta, r, phys)
        transport = phys.transport(rho, theta, r)
        Pk = pad_fields(transport, grid, t)
        faces = [face_coefficients(Pk, grid.cells, a) for a in range(grid.ndim)]
        eta_f, lam_f, kap_f = ([f[i] for f in faces] for i in range(3))
        lam_ac_m = 0.0
        if acoustic is not None:
            lam_ac = adt * rho * phys.sound_speed(theta, r) ** 2
            lam_ac_m = jnp.mean(lam_ac)
            Pac = pad_fields((lam_ac, p_ref), grid, t)
            lam_ac_f = [face_mean(Pac[0], grid.cells, a) for a in range(grid.ndim)]
            p_ref_f = [face_mean(Pac[1], grid.cells, a) for a in range(grid.ndim)]
            lam_f = [lb + la for lb, la in zip(lam_f, lam_ac_f)]
        c_f = [e / 3.0 + lb for e, lb in zip(eta_f, lam_f)]

        # Wall coefficients frozen with the transport ones (a frictional wall's momentum part at the sweep's u).
        walls = wall_terms(rho, u, theta, transport, grid, phys) if has_walls(grid) else None

        def div_tau(v: tuple, affine: bool = False) -> list[Any]:
            Pu = pad_fields(v, grid, t, velocity=0, affine=affine, walls=walls)
            out: list[Any] = [0.0, 0.0, 0.0]
            for a in range(grid.ndim):
                tau = lees_edwards_faces([0.0, *stress(Pu, faces[a][0], lam_f[a], a, grid), 0.0], grid, a, t,
                                         affine=False)[1:4]
                dF = face_divergence(jnp.stack(tau), grid, a)
                out = [o - dF[j] for j, o in enumerate(out)]
            return out

        def A(v: tuple, affine: bool = False) -> tuple:
            d = div_tau(v, affine)
            if galilean:  # the flow momentum of the implicit mass flux across a Lees-Edwards boundary
                d = [x + g for x, g in zip(d, implicit_fluxes(rho, v, None, grid, t, affine=False)[1])]
            return tuple(rho * v[j] - adt * d[j] for j in range(3))

        eta_m, lam_m = jnp.mean(transport[0]), jnp.mean(transport[1]) + lam_ac_m
        c_m = eta_m / 3.0 + lam_m
        iso = sum(_face_sum(eta_f, grid, a) * inv_dx2[a] for a in range(grid.ndim))
        iso_m = 2.0 * eta_m * sum(inv_dx2)
        scale = tuple(
            jnp.sqrt((rho + adt * (iso + (_face_sum(c_f, grid, j) * inv_dx2[j] if j < grid.ndim else 0.0)))
                     / (rho_mean + adt * (iso_m + (2.0 * c_m * inv_dx2[j] if j < grid.ndim else 0.0))))
            for j in range(3))
        M = _scaled(momentum_preconditioner(grid, rho_mean, eta_m, lam_m, adt, dtype), scale)
        m_base = m_hat
        if acoustic is not None:  # the pressure of the iterate: m̂ − aΔt∇(p_k + λ_ac∇·u_k)
            m_base = tuple(m + adt * d for m, d in zip(m_hat, pressure_divergence(
                [p + la * d for p, la, d in zip(p_ref_f, lam_ac_f, d_ref)], grid, t) + [0.0] * (3 - grid.ndim)))
        b = tuple(m - a for m, a in zip(m_base, A(u, True)))  # solve for the correction to the current u
        # Absolute floors from the scale of the state (thermal momentum ρ√θ, energy Ê), not of
        # the correction: in a nearly uniform gas the correction itself is round-off.
        atol_m = floor * _norm(rho, acc) * jnp.sqrt(jnp.mean(theta))
        # BiCGSTAB, not GMRES: jax.scipy's GMRES returned a zero correction late in the decay of the 0.7 L⊥
        # paper box (θ ~ 5e-13 m²/s²), where BiCGSTAB converged.  Solved on a unit right-hand side.
        sb = _unit(b, acc)
        du, _ = solve_m(A, tuple(x / sb for x in b), tol=tol, atol=atol_m / sb, maxiter=RESTART * maxiter, M=M)
        u = tuple(x + sb * dx for x, dx in zip(u, du))
        rho_op, E_base = rho, E_hat
        if acoustic is not None:  # the face pressure of the solution, and mass and energy from its fluxes
            Pu = pad_fields(u, grid, t, velocity=0, walls=walls)
            div_f = [stress(Pu, 0.0, 1.0, a, grid)[a] for a in range(grid.ndim)]
            d_rho, d_m, d_E = implicit_fluxes(rho, u, acoustic.enthalpy, grid, t, walls)
            m_base = tuple(m + adt * (d + g) for m, d, g in zip(m_hat, pressure_divergence(
                [p + la * (d0 - d) for p, la, d0, d in zip(p_ref_f, lam_ac_f, d_ref, div_f)], grid, t)
                + [0.0] * (3 - grid.ndim), d_m))
            rho, E_base, d_ref = rho_hat + adt * d_rho, E_hat + adt * d_E, div_f
        if walls is not None:  # the wall heat terms need the slip of the new u (at the operator's ρ)
            walls = wall_terms(rho_op, u, theta, transport, grid, phys, frozen=walls)

        def B(th: Any) -> Any:
            Pt = pad_fields((th,), grid, t, affine=False, theta=0, walls=walls)[0]
            div = sum(face_divergence(lees_edwards_faces(
                [0.0, 0.0, 0.0, 0.0, -kap_f[a] * face_jump(Pt, grid.cells, a) / grid.spacing[a]], grid, a, t,
                affine=False)[4], grid, a) for a in range(grid.ndim))
            return 1.5 * rho * th - adt * div

        # The collisional sink linearised about θ_k: S_k + S'_k (θ − θ_k) (module docstring).
        s_k, ds_k = collisional_sink(rho, theta, r, phys) if sink else (0.0, 0.0)
        s_const = s_k - ds_k * theta
        mass = 1.5 * rho + adt * ds_k

        B_sink = (lambda th: B(th) + adt * ds_k * th) if sink else B
        # Right-hand side: Ê − ρ̂|u|²/2 + aΔt∇·(τ·u + ω∇φ), i.e. the stage equation with κ = 0.
        fI0 = viscous_divergence((rho, *u, jnp.zeros_like(theta)), transport, grid, phys, t, walls)
        rhs_E = E_base - 0.5 * rho * sum(x * x for x in u) + adt * (fI0[4] - friction_sink - s_const)
        kap_m = jnp.mean(transport[2])
        hscale = jnp.sqrt((mass + adt * sum(_face_sum(kap_f, grid, a) * inv_dx2[a] for a in range(grid.ndim)))
                          / (jnp.mean(mass) + 2.0 * adt * kap_m * sum(inv_dx2)))
        Mh = _scaled(heat_preconditioner(grid, jnp.mean(mass), kap_m, adt, dtype), hscale)
        th0 = primitive_fields((rho, *(rho * x for x in u), E_base))[4]  # θ of Û with the new u
        bE = rhs_E - B_sink(th0)
        atol_E = floor * _norm(E_hat, acc)
        sE = _unit(bE, acc)
        dth, _ = solve_E(B_sink, bE / sE, tol=tol, atol=atol_E / sE, maxiter=RESTART * maxiter, M=Mh)
        theta = th0 + sE * dth

        # The conservative stage state and the residual of its two linear problems.
        fI = viscous_divergence((rho, *u, theta), transport, grid, phys, t, walls)
        fI[4] = fI[4] - friction_sink - (s_const + ds_k * theta if sink else 0.0)
        U = (rho, *(m + adt * f for m, f in zip(m_base, fI[1:4])), E_base + adt * fI[4])
        res_m = _norm(tuple(rho_op * x - m for x, m in zip(u, U[1:4])), acc)
        res_E = _norm(U[4] - rho * (0.5 * sum(x * x for x in u) + 1.5 * theta), acc)
        tiny = float(jnp.finfo(dtype).tiny)  # a zero right-hand side (uniform gas) is solved exactly
        worst = jnp.maximum(worst, jnp.maximum(res_m / jnp.maximum(jnp.maximum(tol * _norm(b, acc), atol_m), tiny),
                                               res_E / jnp.maximum(jnp.maximum(tol * _norm(bE, acc), atol_E), tiny)
                                               ).astype(dtype))
        theta = primitive_fields(U)[4]
    if acoustic is not None:  # f_I as applied: the increment of every conserved field
        fI = [(x - y) / adt for x, y in zip(U, Uhat)]
    return U, fI, worst
