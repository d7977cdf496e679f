"""Discrete steady balances of the Couette cell (model.md §§7, 9): residual and diagnostics.

Discretisation: vertex-centred finite volumes on nodes x_0 … x_N (one node on each wall,
optionally clustered towards the walls).  Each node carries three unknowns

    u      tangential velocity (in units of the wall-speed scale V),
    s      ln(θ/V²)                    — θ stays positive,
    ψ      logit(φ/φ_max)              — 0 < φ < φ_max of the model's RDF,

and three equations:

* tangential momentum  F_{i+1/2} − F_{i−1/2} = 0 with F = A η dω/dx (shear stress or torque);
* energy  E_{i+1/2} − E_{i−1/2} + ½(P_{i−1/2} + P_{i+1/2}) − V_i Γ_i = 0 with the conductive
  flux E = B(κ dθ/dx + ω_φ dφ/dx) (both heat-flux terms of model.md §1), the shear work of
  each interval P = F Δω and the collisional dissipation Γ = (3/2)ρθζ0;
* normal momentum  ln p_{i+1} − ln p_i = Δx ⟨K⟩ (uniform p in the planar cell, radial balance
  dp/dr = ρu²/r in the annular one), the last row replaced by the inventory ⟨φ⟩ = φ̄.

At the walls the outer half-cell fluxes are the wall conditions of :mod:`ktgf.couette.walls`
(or the row is replaced by a Dirichlet condition); a bumpy wall's normal stress N is the model's
pressure at the wall node, so its shear stress and heat flux also depend on φ there.  The scheme
is conservative: at a solution the shear stress is the same in every interval and on both walls, and the shear work summed
over the intervals plus the slip work equals the wall power exactly, so the energy budget
closes to the solver tolerance.  The truncation error is O(Δx²) inside and O(Δx) in the wall
half-cells, which gives second-order global accuracy (tested by mesh refinement).

Units inside the solver: lengths in d, velocities in V, densities in ρ_s (so the model's
SI coefficient functions are called with d = ρ_s = 1 and θ in V²).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from .frictional_stress import frictional_terms
from .walls import Wall, bumpy_wall_fluxes, jj_friction, jj_frictional_wall_stress, jj_heat_loss

N_VARS = 3  # u, ln θ, ψ per node
#: Relative step of the Jacobian's central differences.
FD_STEP = 1e-5
#: The step where a coefficient varies on the scale of the shear rate itself, so that a step of 1e-5 U in u is
#: too coarse for Newton: a shear-dependent χ (rdf option ``shear_amplitude``, χ ∝ |γ̇|; a creeping core has
#: γ̇ ~ 1e-4 U/H: test_a_sheared_chi_converges_quadratically_in_a_creeping_core) and a frictional stress (its
#: viscosity ∝ 1/√(I2D + ε²(U/H)²) changes over ε U/H = 1e-3 U/H, while 1e-5 U over a face of a 10 d gap on
#: 800 cells is 8e-3 U/H: Newton lost descent there: test_a_frictional_stress_converges_on_a_fine_mesh).
RATE_SENSITIVE_FD_STEP = 1e-7


def phi_from_psi(psi: np.ndarray, phi_max: float) -> np.ndarray:
    """φ = φ_max / (1 + e^{−ψ}), computed without overflow."""
    return phi_max * 0.5 * (1.0 + np.tanh(0.5 * psi))


def psi_from_phi(phi: np.ndarray, phi_max: float) -> np.ndarray:
    x = np.asarray(phi, dtype=float) / phi_max
    return np.log(x) - np.log1p(-x)


@dataclass
class Problem:
    """The discrete Couette problem on a fixed grid, in solver units.

    Parameters
    ----------
    model : ktgf.closures.Model
    geometry : PlanarCell or AnnularCell
    bottom, top : Wall
        Walls at x_0 (n = +x) and x_N (n = −x).
    mean_phi : float
        Inventory: the area-weighted mean solid fraction.
    e : float
        Particle–particle restitution.
    x : ndarray
        Nodes in particle diameters.
    """

    model: Any
    geometry: Any
    bottom: Wall
    top: Wall
    mean_phi: float
    e: float
    x: np.ndarray
    v_scale: float = 1.0
    centrifugal: float = 1.0  # multiplier of the centripetal term (1 = physics; <1 only inside a homotopy)
    central_differences: bool = True  # O(h²) Jacobian: the near-jammed states have condition numbers ~1e13
    fd_step: float | None = None  # the Jacobian's relative step (None: FD_STEP, or RATE_SENSITIVE_FD_STEP)
    stress_scale: float = 0.0  # ρ_s V² [Pa]: converts a frictional stress (model option stress) to solver units

    def __post_init__(self) -> None:
        x = self.x
        g = self.geometry
        self.n = x.size
        self.phi_max = self.model.phi_max
        self.dx = np.diff(x)
        self.xf = 0.5 * (x[1:] + x[:-1])
        self.A = g.flux_metric(self.xf)
        self.B = g.volume_metric(self.xf)
        self.V = g.control_volumes(x)
        self.S_wall = g.stress_metric(x[[0, -1]])
        self.B_wall = g.volume_metric(x[[0, -1]])
        self.u_wall = g.wall_velocities()
        self.walls = (self.bottom, self.top)
        self.reference_shear_rate = abs(self.u_wall[1] - self.u_wall[0]) / (x[-1] - x[0])  # U/H in V/d
        # χ(φ, s) widens the Jacobian's stencil; it and a frictional stress need the finer difference step
        self.sheared_chi = bool(getattr(self.model.rdf, "shear_dependent", False))
        if self.fd_step is None:
            rate_sensitive = self.sheared_chi or self.model.friction.has_stress
            self.fd_step = RATE_SENSITIVE_FD_STEP if rate_sensitive else FD_STEP
        if not 0.0 < self.mean_phi < self.phi_max:
            from ..errors import InputError

            # the inventory cannot be packed below the RDF's divergence (φ_c(μ) for a frictional RDF): no steady state
            raise InputError(f"mean solid fraction mean_phi = {self.mean_phi:g} is out of range: valid 0 < mean_phi < "
                             f"{self.phi_max:g} (packing limit of {self.model.label or self.model.name}): no steady "
                             "state, the inventory does not fit below the jamming fraction")
        if self.model.friction.has_stress and not self.stress_scale > 0.0:
            from ..errors import InputError

            raise InputError("a model with a frictional stress needs the Couette stress scale rho_s V^2 > 0 (Pa)")
        for side, wall in zip(("bottom", "top"), self.walls):
            if wall.friction_angle > 0.0 and not (wall.momentum == "johnson-jackson" and self.model.friction.has_stress):
                from ..errors import InputError

                raise InputError(f"{side} wall friction_angle = {wall.friction_angle:g} acts on the frictional normal "
                                 "stress: valid only for a johnson-jackson momentum wall and a model with a frictional "
                                 "stress (friction option stress)")

    # --- fields --------------------------------------------------------------------------
    def unpack(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(u, θ, φ) at the nodes; a stack of states (leading axes) gives stacks of profiles."""
        X = X.reshape(*X.shape[:-1], self.n, N_VARS)
        return X[..., 0], np.exp(X[..., 1]), phi_from_psi(X[..., 2], self.phi_max)

    def pack(self, u: np.ndarray, theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
        return np.stack([u, np.log(theta), psi_from_phi(phi, self.phi_max)], axis=1).ravel()

    def prescribed_velocity(self, k: int) -> float:
        """Medium velocity at wall k (0 bottom, 1 top) for a prescribed lag behind the wall."""
        uw, uo = self.u_wall[k], self.u_wall[1 - k]
        return uw - self.walls[k].slip / self.v_scale * np.sign(uw - uo)

    def _wall_gradient(self, f: np.ndarray, k: int) -> float:
        """Second-order one-sided df/dx at wall k (0: x_0, 1: x_N) from the three nearest nodes."""
        x = self.x
        if k == 0:
            h1, h2 = x[1] - x[0], x[2] - x[1]
            f0, f1, f2, s = f[..., 0], f[..., 1], f[..., 2], 1.0
        else:
            h1, h2 = x[-1] - x[-2], x[-2] - x[-3]
            f0, f1, f2, s = f[..., -1], f[..., -2], f[..., -3], -1.0
        return s * (-(2 * h1 + h2) / (h1 * (h1 + h2)) * f0 + (h1 + h2) / (h1 * h2) * f1 - h1 / (h2 * (h1 + h2)) * f2)

    # --- residual --------------------------------------------------------------------------
    def terms(self, X: np.ndarray) -> dict[str, np.ndarray]:
        """Every flux and source of the discrete balances (used by the residual and the diagnostics).

        ``X`` may be a stack of states (leading axes, as :meth:`jacobian` passes its perturbed states): every term
        then has those axes in front, node or face last.
        """
        u, theta, phi = self.unpack(X)
        n = self.n
        batch = u.shape[:-1]
        phi_f = 0.5 * (phi[..., 1:] + phi[..., :-1])
        theta_f = 0.5 * (theta[..., 1:] + theta[..., :-1])
        w = self.geometry.angular(u, self.x)
        dw = np.diff(w)
        shear = None
        if self.model.shear_dependent:  # EKT, tangential stress: ζ0 at the nodes sees the local dγ̇/√θ;
            # a shear-dependent χ: p, ζ0 at the nodes and η, κ at the faces see it
            rate = np.abs(self.A / self.geometry.stress_metric(self.xf) * dw / self.dx)  # face shear rates
            node_rate = np.concatenate([rate[..., :1], 0.5 * (rate[..., 1:] + rate[..., :-1]), rate[..., -1:]], axis=-1)
            shear = np.concatenate([node_rate / np.sqrt(theta), rate / np.sqrt(theta_f)], axis=-1)
        c = self.model.coefficients(
            np.concatenate([phi, phi_f], axis=-1), self.e, np.concatenate([theta, theta_f], axis=-1), d=1.0,
            rho_s=1.0, check=False, shear=shear,
        )
        node, face = (..., slice(0, n)), (..., slice(n, None))
        rate_f = self.A / self.geometry.stress_metric(self.xf) * dw / self.dx
        p_fric, mu_fric = frictional_terms(self, phi, phi_f, theta_f, rate_f)  # zeros without a frictional stress
        F_kinetic = self.A * c.eta[face] * dw / self.dx
        F = F_kinetic + self.A * mu_fric * dw / self.dx
        E = self.B * (c.kappa[face] * np.diff(theta) + c.omega[face] * np.diff(phi)) / self.dx
        P = F_kinetic * dw  # frictional work is dissipated at the contacts (frictional_stress.py)
        gamma = 1.5 * phi * theta * c.zeta0[node]
        chi_w = self.model.chi(phi[..., [0, -1]])  # the wall's JJ conditions take χ(φ) (as the 3D wall ghosts do)
        p = c.p[node] + p_fric
        F_wall = np.zeros((*batch, 2))
        E_wall = np.zeros((*batch, 2))
        slip = np.zeros((*batch, 2))
        wall_dissipation = np.zeros((*batch, 2))
        for k, (i, sign) in enumerate(((0, 1.0), (-1, -1.0))):
            wall = self.walls[k]
            slip[..., k] = u[..., i] - self.u_wall[k]
            sl = slip[..., k]
            cf = jj_friction(wall, phi[..., i], chi_w[..., k], theta[..., i])
            bumpy = bumpy_wall_fluxes(wall, p[..., i], theta[..., i], sl) if wall.is_bumpy else None
            if bumpy is not None:  # N = the flow's normal stress at the wall node (p_yy = p in these models)
                wall_dissipation[..., k] = bumpy[2]
            if wall.momentum == "bumpy":
                F_wall[..., k] = sign * self.S_wall[k] * bumpy[0]
            if wall.momentum == "johnson-jackson":
                F_wall[..., k] = sign * self.S_wall[k] * cf * sl
                if wall.friction_angle > 0.0:  # its work is dissipated at the wall contacts, not fed to θ
                    scale = wall.slip_regularisation * abs(self.u_wall[1] - self.u_wall[0])
                    F_wall[..., k] += sign * self.S_wall[k] * jj_frictional_wall_stress(wall, p_fric[..., i], sl, scale)
            if wall.energy in ("johnson-jackson", "bumpy"):
                loss = (bumpy[1] if wall.energy == "bumpy"
                        else jj_heat_loss(wall, phi[..., i], chi_w[..., k], theta[..., i], sl))
                E_wall[..., k] = sign * self.B_wall[k] * loss
                if wall.heat_flux == "conductive":  # the condition sets κ∂θ/∂n only: add the ω∂φ/∂x part
                    E_wall[..., k] += self.B_wall[k] * c.omega[node][..., i] * self._wall_gradient(phi, k)
        return {
            "u": u, "theta": theta, "phi": phi, "p": p, "eta": c.eta[node],
            "F": F, "E": E, "P": P, "gamma": gamma, "F_wall": F_wall, "E_wall": E_wall, "slip": slip,
            "wall_dissipation": wall_dissipation,
            "K": self.centrifugal * self.geometry.centripetal(u, self.x, phi, p),
            "p_frictional": p_fric, "frictional_work": (F - F_kinetic) * dw,
        }

    def residual(self, X: np.ndarray, t: dict[str, np.ndarray] | None = None) -> np.ndarray:
        """The discrete balances (module docstring), flat; a stack of states gives a stack of residuals."""
        t = self.terms(X) if t is None else t
        n = self.n
        batch = t["u"].shape[:-1]
        R = np.empty((*batch, n, N_VARS))
        Fx = np.concatenate([t["F_wall"][..., :1], t["F"], t["F_wall"][..., 1:]], axis=-1)
        R[..., 0] = Fx[..., 1:] - Fx[..., :-1]
        Ex = np.concatenate([t["E_wall"][..., :1], t["E"], t["E_wall"][..., 1:]], axis=-1)
        zero = np.zeros((*batch, 1))
        Px = np.concatenate([zero, t["P"], zero], axis=-1)
        R[..., 1] = Ex[..., 1:] - Ex[..., :-1] + 0.5 * (Px[..., 1:] + Px[..., :-1]) - self.V * t["gamma"]
        lnp = np.log(t["p"])
        K = t["K"]
        R[..., :-1, 2] = np.diff(lnp) - self.dx * 0.5 * (K[..., 1:] + K[..., :-1])
        R[..., -1, 2] = t["phi"] @ self.V / self.V.sum() - self.mean_phi
        for k, i in ((0, 0), (1, n - 1)):
            wall = self.walls[k]
            if wall.momentum == "prescribed":
                R[..., i, 0] = t["u"][..., i] - self.prescribed_velocity(k)
            if wall.energy == "prescribed":
                R[..., i, 1] = np.log(t["theta"][..., i]) - np.log(wall.temperature / self.v_scale**2)
        return R.reshape(*batch, n * N_VARS)

    def residual_scales(self, t: dict[str, np.ndarray]) -> np.ndarray:
        """Magnitude of the terms of each equation, to report a relative residual."""
        n = self.n
        S = np.ones((n, N_VARS))
        Fx = np.abs(np.concatenate([t["F_wall"][:1], t["F"], t["F_wall"][1:]]))
        S[:, 0] = Fx.max() + 1e-300
        Ex = np.abs(np.concatenate([t["E_wall"][:1], t["E"], t["E_wall"][1:]]))
        Px = np.abs(np.concatenate([[0.0], t["P"], [0.0]]))
        S[:, 1] = Ex[1:] + Ex[:-1] + 0.5 * (Px[1:] + Px[:-1]) + self.V * t["gamma"] + 1e-300
        return S.ravel()

    # --- Jacobian ----------------------------------------------------------------------------
    @cached_property
    def _difference_pattern(self) -> tuple[list[tuple[int, np.ndarray]], tuple[np.ndarray, ...]]:
        """The colour groups (unknown k, nodes j perturbed together) and, for every Jacobian entry they give, its
        (group, row node i, equation q, column node j, unknown k); the inventory row is left out (exact)."""
        n = self.n
        # a residual row sees the nodes within `reach` of its own: 1, but 2 with a shear-dependent χ (p at a node
        # then depends on the velocities of its neighbours, and the rows next to it see that p)
        reach = 2 if self.sheared_chi else 1
        offsets = (*range(-reach, reach + 1), "walls") if reach == 1 else tuple(range(-reach, reach + 1))
        groups = [(k, np.arange(colour, n, 2 * reach + 1)) for k in range(N_VARS) for colour in range(2 * reach + 1)]
        entries = []
        for g, (k, j) in enumerate(groups):
            for off in offsets:
                if off == "walls":  # wall rows also see the third node (one-sided wall gradients)
                    i = np.where(j == 2, 0, np.where(j == n - 3, n - 1, -1))
                else:
                    i = j + off
                ok = (i >= 0) & (i < n)
                for q in range(N_VARS):
                    keep = ok & ~((i == n - 1) & (q == 2))
                    entries.append(np.stack(np.broadcast_arrays(g, i[keep], q, j[keep], k)))
        return groups, tuple(np.concatenate(entries, axis=1))

    def jacobian(self, X: np.ndarray, R0: np.ndarray):
        """Sparse Jacobian: coloured differences for the banded part, exact inventory row.

        Every perturbed state of every colour goes through one call of :meth:`residual` (a stack of states), so
        the closures run once per Jacobian on (colours × unknowns × 2) profiles instead of once per profile.
        """
        import scipy.sparse as sp

        n = self.n
        Xm = X.reshape(n, N_VARS)
        groups, (g, i, q, j, k) = self._difference_pattern
        h = self.fd_step * (1.0 + np.abs(Xm))  # the step of each unknown
        signs = (1.0, -1.0) if self.central_differences else (1.0,)
        stack = np.repeat(Xm[None], len(groups) * len(signs), axis=0)
        for c, (kc, jc) in enumerate(groups):
            for s, sign in enumerate(signs):
                stack[c * len(signs) + s, jc, kc] += sign * h[jc, kc]
        Rs = self.residual(stack.reshape(len(stack), n * N_VARS)).reshape(len(groups), len(signs), n, N_VARS)
        dR = 0.5 * (Rs[:, 0] - Rs[:, 1]) if self.central_differences else Rs[:, 0] - R0.reshape(n, N_VARS)
        inv_row = (n - 1) * N_VARS + 2
        phi = phi_from_psi(Xm[:, 2], self.phi_max)
        rows = np.concatenate([i * N_VARS + q, np.full(n, inv_row)])
        cols = np.concatenate([j * N_VARS + k, np.arange(n) * N_VARS + 2])
        vals = np.concatenate([dR[g, i, q] / h[j, k], self.V * phi * (1.0 - phi / self.phi_max) / self.V.sum()])
        m = n * N_VARS
        return sp.csc_matrix((vals, (rows, cols)), shape=(m, m))
