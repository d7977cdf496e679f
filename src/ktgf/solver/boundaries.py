"""Boundary conditions of the finite-volume solver as data: one kind per grid axis (the conditions, with their
equations: docs/solver.md, "Cases and boundaries").

Every stencil of :mod:`.fluxes` and :mod:`.imex` reads fields padded with :data:`~.fluxes.GHOST`
ghost cells per side; the boundaries only decide what the ghost cells hold (:func:`pad`).

``periodic``
    The ghost cells are the cells at the other end of the axis (the cooling box; the code path
    is the one of :func:`~.fluxes.pad_periodic`, so periodic runs are unchanged bit for bit).
``lees-edwards``
    Shearing-periodic images (Lees & Edwards 1972, *J. Phys. C* 5, 1921): along the gradient axis a the image
    boxes move with ±γ̇L_a along the flow direction f and are displaced by ±Δ(t), Δ = γ̇L_a t mod L_f; a ghost
    cell holds the state of the cell it images plus the velocity jump ±γ̇L_a e_f (ρ, θ and the closures are
    unchanged).  Δ is not a whole number of cells: the image is interpolated linearly between the two cells it
    straddles (second order, like the reconstruction).  If f is not a grid axis (a 1D grid along the gradient,
    or a 2D grid x–y with flow along z) only the jump remains.  Uniform shear u_f = γ̇(x_a − L_a/2) is then an
    exact steady solution of the discrete momentum balance (a linear profile continues across the boundary).
``wall``
    Both ends of the axis are walls (:class:`WallSide`: a :class:`ktgf.couette.walls.Wall` and its velocity),
    the Johnson & Jackson (1987, *J. Fluid Mech.* 176, 67) conditions of the 1D Couette solver, evaluated by the
    same functions (:mod:`ktgf.couette.walls`): wall shear stress c u_sl (u_sl = u − U_w the slip), u_n = 0 and
    heat flux −q·n = D − G, G = c|u_sl|².  The convective flux through the wall face is
    :func:`~.fluxes.wall_flux` of the medium's face state (reconstructed with a one-sided slope in the wall
    cell).  The viscous and heat fluxes see ghost cells that make the central face fluxes equal to the
    conditions: the face velocity u_f solves η_f(u_c − u_f)/(Δ/2) = c(u_f − U_w) (u_c the wall cell),
    u_ghost = 2u_f − u_c, and θ_ghost = θ_c − Δ(D − G)/κ_f, so the discrete wall stress is exactly c(u_f − U_w)
    and the heat flux exactly D − G (η_f, κ_f: the face coefficients of the fluxes, the mean of the wall cell
    and a limited linear extrapolation).  φ and θ in c, D and G are the values at the wall extrapolated from
    the two nearest cells (second order), the slip the face u_f.  ``momentum = "prescribed"`` (no slip,
    c → ∞) and ``"free-slip"`` (c = 0), ``energy = "adiabatic"`` (q·n = 0) and ``"prescribed"``
    (θ_ghost = 2θ_w − θ_c) are the limits.

Affine parts.  The Lees–Edwards velocity jump, the wall velocity and the wall heat flux G are the
affine part of the boundary: an operator linear in the velocity or θ (the implicit operators of
the IMEX stage solves) is applied with ``affine=False`` and the rest goes into its right-hand
side (:func:`~.imex.implicit_stage`).  In those solves the coefficients c and D/θ of the walls
are frozen with the transport coefficients (at the sweep's θ), so D is linear in θ there.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import jax
import jax.numpy as jnp

from ..errors import InputError

PERIODIC = "periodic"
LEES_EDWARDS = "lees-edwards"
WALL = "wall"
KINDS = (PERIODIC, LEES_EDWARDS, WALL)
AXES = "xyz"
#: Wall conditions the 3D solver applies (of :mod:`ktgf.couette.walls`).
WALL_MOMENTUM = ("johnson-jackson", "prescribed", "free-slip")
WALL_ENERGY = ("johnson-jackson", "adiabatic", "prescribed")


@dataclass(frozen=True)
class WallSide:
    """One wall of the solver: its conditions (:class:`ktgf.couette.walls.Wall`) and velocity [m/s]."""

    wall: Any
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)


@jax.tree_util.register_pytree_node_class
@dataclass(frozen=True)
class Boundaries:
    """Boundary kind of every grid axis, and the Lees–Edwards shear if there is one.

    A JAX pytree: the kinds and the flow component are static, the shear rate a traced leaf.

    Parameters
    ----------
    kinds : tuple of str
        One of :data:`KINDS` per grid axis.
    shear_rate : float
        Lees–Edwards shear rate γ̇ [1/s] (du_f/dx_a of the images).
    flow : int
        Velocity component of the Lees–Edwards flow direction (0, 1, 2 = x, y, z; not the gradient axis).
    walls : tuple
        Per axis: None, or (lower, upper) :class:`WallSide` of a ``wall`` axis.
    """

    kinds: tuple[str, ...]
    shear_rate: float = 0.0
    flow: int = 0
    walls: tuple = ()

    def __post_init__(self) -> None:
        kinds = tuple(self.kinds)
        object.__setattr__(self, "kinds", kinds)
        for a, k in enumerate(kinds):
            if k not in KINDS:
                raise InputError(f"boundary kind {k!r} on axis {AXES[a]} is unknown; valid: {', '.join(KINDS)}")
        if kinds.count(LEES_EDWARDS) > 1:
            raise InputError("at most one axis can be Lees-Edwards (one shear-gradient direction)")
        if LEES_EDWARDS in kinds:
            a = kinds.index(LEES_EDWARDS)
            if self.flow == a or not 0 <= self.flow <= 2:
                raise InputError(f"Lees-Edwards flow direction {AXES[self.flow] if 0 <= self.flow <= 2 else self.flow} "
                                 f"must differ from the gradient axis {AXES[a]}")
            if self.flow < len(kinds) and kinds[self.flow] != PERIODIC:
                raise InputError(f"Lees-Edwards flow axis {AXES[self.flow]} must be periodic")
        walls = tuple(self.walls) or (None,) * len(kinds)
        object.__setattr__(self, "walls", walls)
        for a, k in enumerate(kinds):
            if (k == WALL) != (walls[a] is not None):
                raise InputError(f"axis {AXES[a]}: a wall axis needs its two walls (lower, upper), other axes none")
            for side in walls[a] or ():
                w = side.wall
                if w.momentum not in WALL_MOMENTUM or w.energy not in WALL_ENERGY:
                    raise InputError(f"wall conditions {w.momentum!r}/{w.energy!r} on axis {AXES[a]}: the 3D solver "
                                     f"applies momentum {', '.join(WALL_MOMENTUM)} and energy {', '.join(WALL_ENERGY)}")
                if w.momentum == "prescribed" and w.slip != 0.0:
                    raise InputError(f"wall slip = {w.slip:g} on axis {AXES[a]}: the 3D solver's prescribed wall is "
                                     "no-slip (slip = 0)")
                if w.heat_flux != "total":
                    raise InputError(f"wall heat_flux = {w.heat_flux!r} on axis {AXES[a]}: the 3D solver applies the "
                                     "JJ energy condition to the whole heat flux (heat_flux = 'total')")
                if side.velocity[a] != 0.0:
                    raise InputError(f"wall velocity {side.velocity} on axis {AXES[a]} has a normal component: "
                                     "walls move tangentially")

    def tree_flatten(self) -> tuple[tuple, tuple]:
        return (self.shear_rate,), (self.kinds, self.flow, self.walls)

    @classmethod
    def tree_unflatten(cls, aux: tuple, leaves: tuple) -> Boundaries:
        obj = object.__new__(cls)
        for name, v in zip(("kinds", "flow", "walls", "shear_rate"), (*aux, *leaves)):
            object.__setattr__(obj, name, v)
        return obj

    @property
    def all_periodic(self) -> bool:
        return all(k == PERIODIC for k in self.kinds)

    @property
    def shear_axis(self) -> int | None:
        """The Lees–Edwards gradient axis, or None."""
        return self.kinds.index(LEES_EDWARDS) if LEES_EDWARDS in self.kinds else None

    @property
    def wall_axes(self) -> tuple[int, ...]:
        return tuple(a for a, k in enumerate(self.kinds) if k == WALL)


def _shifted(f: Any, s: Any, axis: int) -> Any:
    """f(i − s) along ``axis`` (periodic), linear interpolation for a fractional s ≥ 0."""
    k = jnp.floor(s)
    w = (s - k).astype(f.dtype)
    k = k.astype(jnp.int32)
    return (1.0 - w) * jnp.roll(f, k, axis=axis) + w * jnp.roll(f, k + 1, axis=axis)


def _lees_edwards(f: Any, grid: Any, t: Any, jump: Any, G: int) -> Any:
    """f with G Lees–Edwards ghost layers on each side of the gradient axis (others not yet padded)."""
    bc = grid.boundaries
    a, fl = bc.shear_axis, bc.flow
    n = grid.cells[a]
    U = bc.shear_rate * grid.lengths[a]
    low = jax.lax.slice_in_dim(f, n - G, n, axis=a)  # images of the top cells below the box
    high = jax.lax.slice_in_dim(f, 0, G, axis=a)     # images of the bottom cells above the box
    if fl < grid.ndim:
        # Δ/Δx_f in cells, reduced modulo the period in float64 (t can be large).
        s = jnp.mod(jnp.asarray(U, jnp.float64) * jnp.asarray(t, jnp.float64) / grid.lengths[fl], 1.0) * grid.cells[fl]
        high = _shifted(high, s, fl)
        low = _shifted(low, -s + grid.cells[fl], fl)
    if jump is not None:
        high = high + jnp.asarray(jump * U, f.dtype)
        low = low - jnp.asarray(jump * U, f.dtype)
    return jnp.concatenate([low, f, high], axis=a)


def lees_edwards_faces(F: Sequence[Any], grid: Any, axis: int, t: Any, affine: bool = True) -> list[Any]:
    """Face fluxes along ``axis`` (5 components, faces −1/2 … N−1/2, a component may be the scalar 0)
    with the lower Lees–Edwards face flux replaced by the upper one, mapped back through the
    boundary: what leaves the box through the upper face enters it through the lower one.

    The upper face at x_f images the lower cells at x_f − Δ, interpolated with weights (1 − w, w)
    (:func:`_shifted`); its flux is handed to those two lower faces with the same weights (the
    transpose of the interpolation, which preserves sums), after the Galilean change to the frame of
    the lower image (velocity −γ̇L_a e_f): F_ρ' = F_ρ, F_f' = F_f − U F_ρ, F_E' = F_E − U F_f + U²F_ρ/2
    with U = γ̇L_a (``affine=False``: the linear part, without it).  So Σρ and the momentum
    components across and normal to the flow change only by round-off; Σρu_f and ΣE change by the
    work of the boundary, exactly as the Galilean rule says.  Other axes: F unchanged.
    """
    bc = grid.boundaries
    if bc is None or bc.shear_axis != axis:
        return list(F)
    n, fl = grid.cells[axis], bc.flow
    top = [f if jnp.ndim(f) == 0 else jax.lax.slice_in_dim(f, n, n + 1, axis=axis) for f in F]
    if affine:
        dtype = next(f.dtype for f in top if jnp.ndim(f))
        U = jnp.asarray(bc.shear_rate * grid.lengths[axis], dtype)
        top[4] = top[4] - U * top[1 + fl] + (0.5 * U * U) * top[0]
        top[1 + fl] = top[1 + fl] - U * top[0]
    if fl < grid.ndim:
        s = jnp.mod(jnp.asarray(bc.shear_rate * grid.lengths[axis], jnp.float64) * jnp.asarray(t, jnp.float64)
                    / grid.lengths[fl], 1.0) * grid.cells[fl]
        top = [f if jnp.ndim(f) == 0 else _shifted(f, -s + grid.cells[fl], fl) for f in top]
    return [f if jnp.ndim(f) == 0 else jnp.concatenate([b, jax.lax.slice_in_dim(f, 1, n + 1, axis=axis)], axis=axis)
            for f, b in zip(F, top)]


def _side(f: Any, axis: int, n: int, side: int, layer: int) -> Any:
    """The cell ``layer`` away from wall ``side`` (0 lower, 1 upper), kept as a slab of width 1."""
    i = layer if side == 0 else n - 1 - layer
    return jax.lax.slice_in_dim(f, i, i + 1, axis=axis)


def _extrapolated(layers: Sequence[Any], G: int, positive: bool) -> list[Any]:
    """Ghost layers continuing the two wall cells linearly; for a positive field (ρ, θ, closures)
    the first is kept within [f_0/2, 3f_0/2], so face means stay positive."""
    f0, f1 = layers[0], layers[1]
    g0 = 2.0 * f0 - f1
    if positive:
        g0 = jnp.clip(g0, 0.5 * f0, 1.5 * f0)
    return [f0 + (g + 1) * (g0 - f0) for g in range(G)]


def wall_face(f: Any, axis: int, n: int, side: int) -> Any:
    """The face value at wall ``side`` of a positive cell field as the fluxes see it: the mean of the
    wall cell and its :func:`_extrapolated` ghost (the coefficients η, κ at the wall)."""
    layers = [_side(f, axis, n, side, g) for g in range(2)]
    return 0.5 * (layers[0] + _extrapolated(layers, 1, positive=True)[0])


def frictional_wall_coefficient(wall: Any, ws: WallSide, pair: Any, phi_w: Any, phys: Any, uc: Sequence[Any],
                                beta: Any, c: Any, a: int) -> Any:
    """The frictional part c_f of a Johnson–Jackson wall's shear coefficient, wall stress = (c + c_f) u_sl.

    The frictional wall traction p_f tan δ_w u_sl/√(|u_sl|² + s²) (:func:`ktgf.couette.walls.jj_frictional_wall_stress`,
    s = ε_w |U_upper − U_lower|, p_f = w p_f at the wall's φ) makes the face condition η_f(u_c − u_f)/(Δ/2) =
    c u_sl + p_f tan δ_w u_sl/√(|u_sl|² + s²) nonlinear.  The slip u_sl is parallel to v = u_c − U_w (tangential),
    so its size σ is the root of f(σ) = (β + c)σ + Pσ/√(σ² + s²) − β|v| (β = 2η_f/Δ, P = p_f tan δ_w): f rises
    and is concave for σ ≥ 0, so Newton from σ = β|v|/(β + c) ≥ root moves below the root once and then rises to it
    monotonically.  Returns c_f = P/√(σ² + s²) at that root, so the ghost cell of :func:`_wall_ghosts` makes the
    discrete wall stress exactly the condition's.
    """
    model = phys.model
    P = model.friction.frictional_pressure(phi_w, model.phi_max) * math.tan(math.radians(wall.friction_angle))
    dU = [pair[1].velocity[j] - pair[0].velocity[j] for j in range(3)]
    s2 = (wall.slip_regularisation ** 2) * sum(d * d for d in dU)
    v = jnp.sqrt(sum((uc[j] - ws.velocity[j]) ** 2 for j in range(3) if j != a))
    target = beta * v

    def newton(_: int, sigma: Any) -> Any:
        root = jnp.sqrt(sigma * sigma + s2)
        f = (beta + c) * sigma + P * sigma / root - target
        return jnp.maximum(sigma - f / (beta + c + P * s2 / root**3), 0.0)

    sigma = jax.lax.fori_loop(0, 40, newton, target / (beta + c))
    return P / jnp.sqrt(sigma * sigma + s2)


def wall_terms(rho: Any, u: Sequence[Any], theta: Any, transport: Sequence[Any], grid: Any, phys: Any,
               frozen: dict | None = None) -> dict:
    """Ghost-cell coefficients of every wall, from the state (θ: the temperature of the coefficients).

    Per (axis, side): ``ratio``, ``offset`` (3 components) with u_ghost = ratio_j u_c + offset_j;
    ``heat`` = (a, g) with θ_ghost = θ_c − Δ(a θ_w − g)/κ_f, θ_w = (3θ_0 − θ_1)/2, a = D/θ_w and
    g = G (κ_f, and η_f in the velocity ghosts, are the wall-face coefficients the fluxes use);
    ``stress`` = η∂u/∂n = c(u_f − U_w) and ``slip`` = u_f − U_w per component (diagnostics);
    ``c_friction``: the frictional part of c (:func:`frictional_wall_coefficient`; walls with δ_w > 0).
    The coefficients depend on ``theta`` and on u; :func:`pad` applies them.  ``frozen``: earlier terms whose
    ``c_friction`` is kept (an implicit stage updates the heat terms after its momentum solve and keeps the
    momentum operator it solved with).
    """
    from ..couette.walls import jj_dissipation, jj_friction

    bc = grid.boundaries
    rho_s = phys.material_density
    eta, kappa = transport[0], transport[2]
    out = {}
    for a in bc.wall_axes:
        n, h = grid.cells[a], grid.spacing[a]
        for side, ws in enumerate(bc.walls[a]):
            wall = ws.wall
            (r0, t0), (r1, t1) = [[_side(x, a, n, side, g) for x in (rho, theta)] for g in (0, 1)]
            phi_w = jnp.clip((1.5 * r0 - 0.5 * r1) / rho_s, 0.5 * r0 / rho_s, 2.0 * r0 / rho_s)
            theta_w = jnp.clip(1.5 * t0 - 0.5 * t1, 0.5 * t0, 2.0 * t0)
            chi = phys.model.chi(phi_w)
            beta = 2.0 * wall_face(eta, a, n, side) / h  # the face η of the viscous flux
            uc = [_side(x, a, n, side, 0) for x in u]
            if wall.momentum == "johnson-jackson":
                c = c_collision = rho_s * jj_friction(wall, phi_w, chi, theta_w)
                if wall.friction_angle > 0.0:
                    c_friction = (frozen[a, side]["c_friction"] if frozen is not None else
                                  frictional_wall_coefficient(wall, ws, bc.walls[a], phi_w, phys, uc, beta, c, a))
                    c = c + c_friction
                ratio_t, weight = (beta - c) / (beta + c), 2.0 * c / (beta + c)
            elif wall.momentum == "prescribed":
                ratio_t, weight, c = -jnp.ones_like(beta), 2.0 * jnp.ones_like(beta), None
            else:
                ratio_t, weight, c = jnp.ones_like(beta), jnp.zeros_like(beta), jnp.zeros_like(beta)
                c_collision = c
            ratio = tuple(-jnp.ones_like(beta) if j == a else ratio_t for j in range(3))
            offset = tuple(jnp.zeros_like(beta) if j == a else weight * ws.velocity[j] for j in range(3))
            u_face = [0.5 * (uc[j] * (1.0 + ratio[j]) + offset[j]) for j in range(3)]
            slip = tuple(jnp.zeros_like(beta) if j == a else u_face[j] - ws.velocity[j] for j in range(3))
            # c None (no slip): the stress is the viscous one, η(u_c − u_f)/(Δ/2) toward the medium
            stress = tuple(c * s_ for s_ in slip) if c is not None else tuple(
                beta * (uc[j] - u_face[j]) if j != a else jnp.zeros_like(beta) for j in range(3))
            if wall.energy == "johnson-jackson":
                d_over_theta = rho_s * jj_dissipation(wall, phi_w, chi, theta_w) / theta_w
                # the slip work of the collisions only: the frictional traction's is dissipated at the wall contacts
                heat = (d_over_theta, jnp.zeros_like(beta) if c is None else sum(c_collision * sl * sl for sl in slip))
            elif wall.energy == "prescribed":
                heat = (jnp.full_like(beta, wall.temperature), jnp.zeros_like(beta))
            else:
                heat = (jnp.zeros_like(beta), jnp.zeros_like(beta))
            out[a, side] = {"ratio": ratio, "offset": offset, "heat": heat, "stress": stress, "slip": slip,
                            "kappa": wall_face(kappa, a, n, side)}
            if wall.friction_angle > 0.0:
                out[a, side]["c_friction"] = c_friction
    return out


def _wall_ghosts(f: Any, grid: Any, a: int, G: int, role: Any, terms: dict | None, affine: bool) -> Any:
    """f with G ghost layers on each side of wall axis a.

    ``role``: "even" (ρ, closures), ("u", j) a velocity component, "theta"; ``terms`` None: the
    ghosts of the convective fluxes (a linear extrapolation: the wall cell's slope is one-sided;
    the wall face flux itself is :func:`~.fluxes.wall_flux`), else the viscous ghosts.
    """
    n, h = grid.cells[a], grid.spacing[a]
    bc = grid.boundaries
    slabs = []
    for side in (0, 1):
        layers = [_side(f, a, n, side, g) for g in range(G)]
        if terms is None:  # convective and coefficients: extrapolation (one-sided slope in the wall cell)
            ghost = _extrapolated(layers, G, positive=not isinstance(role, tuple))
        elif role == "even":
            ghost = layers
        else:
            T, kind, f0 = terms[a, side], bc.walls[a][side].wall.energy, layers[0]
            if role != "theta":
                g0 = T["ratio"][role[1]] * f0 + (T["offset"][role[1]] if affine else 0.0)
            elif kind == "johnson-jackson":
                d_over_theta, work = T["heat"]
                theta_w = 1.5 * f0 - 0.5 * layers[1]
                g0 = f0 - h * (d_over_theta * theta_w - (work if affine else 0.0)) / T["kappa"]
            elif kind == "prescribed":
                g0 = -f0 + (2.0 * T["heat"][0] if affine else 0.0)
            else:
                g0 = f0
            ghost = [g0] + [f0 + g0 - layers[g] for g in range(1, G)]  # reflected through the face value (f0 + g0)/2
        slabs.append(ghost[::-1] if side == 0 else ghost)  # ghost[0] is next to the wall: outermost first below
    return jnp.concatenate([*slabs[0], f, *slabs[1]], axis=a)


def pad(fields: Sequence[Any], grid: Any, G: int, t: Any = 0.0, velocity: int | None = None,
        affine: bool = True, theta: int | None = None, walls: dict | None = None) -> tuple[Any, ...]:
    """Fields with G ghost cells per side of every grid axis, filled as the boundaries say.

    ``velocity``: index in ``fields`` of the x velocity component (the three components follow
    it), so that the Lees–Edwards jump and the wall conditions reach them; None if the fields
    hold no velocity.  ``theta``: index of θ (wall heat conditions).  ``walls``: the
    :func:`wall_terms` of the viscous and heat fluxes, or None for the extrapolated ghosts of the
    convective fluxes and of the cell coefficients.  ``affine=False`` leaves out the affine parts (the linear part of the operator).
    """
    bc = grid.boundaries
    ndim = grid.ndim
    if bc is None or bc.all_periodic:
        return tuple(jnp.pad(f, [(G, G)] * ndim, mode="wrap") for f in fields)
    wrapped = getattr(grid, "wrapped", False)  # the periodic axes' ghost cells already there (fluxes.grid_ends)
    out = []
    for i, f in enumerate(fields):
        is_velocity = velocity is not None and 0 <= i - velocity < 3
        role = ("u", i - velocity) if is_velocity else ("theta" if i == theta else "even")
        for a in bc.wall_axes:
            f = _wall_ghosts(f, grid, a, G, role, walls, affine)
        if bc.shear_axis is not None:
            f = _lees_edwards(f, grid, t, 1.0 if (is_velocity and affine and i == velocity + bc.flow) else None, G)
        widths = [(0, 0) if wrapped or b == bc.shear_axis or bc.kinds[b] == WALL else (G, G) for b in range(ndim)]
        out.append(jnp.pad(f, widths, mode="wrap"))
    return tuple(out)
