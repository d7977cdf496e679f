"""Linear stability of steady uniform shear flow at Navier–Stokes order, for every registered model.

Base state (model.md §9): u = γ̇ y e_x, uniform φ and θ with the steady energy balance
η γ̇² = (3/2) ρ θ ζ0, i.e. θ = T(φ, e) (γ̇ d)² with T of :func:`ktgf.shear.steady.steady_shear`.

Perturbations ∝ exp(i k·r) in the frame moving with the base flow.  With k_x = 0 the base
advection γ̇ y ∂_x does not act on them and the problem has constant coefficients: normal modes
exp(σt).  With k_x ≠ 0 the wavevector is sheared, k_y(t) = k_y(0) − γ̇ k_x t (Kelvin modes, the
method of Savage 1992, JFM 241, 109, and Alam & Nott 1997, JFM 343, 267), and the amplitudes obey
dy/dt = A(k(t)) y.

State y = (δφ, δu_x, δu_y, δu_z, δθ) (SI: 1, m/s, m/s, m/s, m²/s²).  Linearising the balances of
model.md §1 (P = pI − η(∇u + ∇uᵀ − (2/3)∇·u I) − λ_b ∇·u I, q = −κ∇θ − ω∇φ,
ζ = ζ0 + ζ_U ∇·u) about the base state, with D = k·δu, k² = |k|², ρ = ρ_s φ:

    dδφ/dt   = −i φ D
    ρ dδu_x/dt = −ρ γ̇ δu_y + i γ̇ k_y δη − i k_x δp − η k² δu_x − (η/3 + λ_b) k_x D
    ρ dδu_y/dt =            + i γ̇ k_x δη − i k_y δp − η k² δu_y − (η/3 + λ_b) k_y D
    ρ dδu_z/dt =                         − i k_z δp − η k² δu_z − (η/3 + λ_b) k_z D
    (3/2) ρ dδθ/dt = −κ k² δθ − ω k² δφ − i (p + (3/2) ρ θ ζ_U) D
                     + 2 i η γ̇ (k_y δu_x + k_x δu_y) + γ̇² δη − δΓ

with δp = p_φ δφ + (p/θ) δθ, δη = η_φ δφ + (η/(2θ)) δθ, δΓ = Γ_φ δφ + (3Γ/(2θ)) δθ for the
collisional dissipation Γ = (3/2) ρ_s φ θ ζ0.  The θ-derivatives are exact because every
coefficient is ∝ √θ (model.md §1); p_φ = ρ_s θ C and Γ_φ = Γ (1 + g)/φ use the models' own
C = ∂(φp*)/∂φ and g = ∂ln ζ0/∂ln n (the HCS pieces, :class:`ktgf.closures.Reduced`); η_φ is a
central difference of the model's η*.  The terms with γ̇ are what the shear adds to the HCS
analysis (:mod:`ktgf.hcs.stability`): the lift-up −γ̇ δu_y, the perturbation of the viscous
stress of the base shear (γ̇ δη) and the perturbed shear work (2iηγ̇(…) + γ̇² δη).

Limits (the oracles of the tests):

* k → 0: four zero rates and the homogeneous temperature mode σ = ∂/∂θ [(2/(3ρ))(ηγ̇² − Γ)]
  = −ζ0 (the linearised 0D energy balance at fixed γ̇ and φ; the base balance ηγ̇² = Γ makes it
  exactly −ζ0 = −2ηγ̇²/(3ρθ));
* k = (0, 0, k_z) (vorticity direction): δu_x decouples exactly, σ = −η k²/ρ (a shear wave),
  and forms a Jordan block with δu_y (same rate; δu_y feeds δu_x by lift-up, algebraic growth);
  (δφ, δu_z, δθ) is a sound/heat system like the HCS longitudinal one;
* k = (0, k_y, 0): δu_z decouples, σ = −η k²/ρ; (δφ, δu_x, δu_y, δθ) carry the layering
  (shear-banding) mode.  At small k it is slow (σ = O(k²)) while pressure, shear stress and the
  local energy balance relax fast, so the layers are a sequence of uniform-shear states at one
  pressure; eliminating the fast variables gives (docs/uniform_shear_stability.md)

      σ/γ̇ = (kd)² f_p μ'(φ) / (1 + (φ/2) (ln f_p)'),   μ = |P_xy|/p,   f_p = p/(ρ_s γ̇² d²) = φ p* T,

  both from the closed form (model.md §9): unstable exactly where the stress ratio rises with φ
  (the flow "cannot sustain increasing dynamic friction with increasing density", Alam, Shukla &
  Luding 2008, arXiv:0811.2459, abstract);
* k = (0, 0, k_z), the (δφ, δu_z, δθ) block: its k-dependent part is, in the HCS variables,
  exactly the HCS longitudinal matrix of model.md §8 (tested); the two analyses differ only in
  the homogeneous terms of their base states.  Dilute flows (φ = 0.05 and 0.1 at e = 0.9; not
  0.2–0.5) are unstable to this vorticity-direction clustering, as the HCS is (docs table).

There is no elastic limit at fixed γ̇ (uniform shear needs e < 1: θ/(γ̇d)² → ∞ as e → 1).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..closures import get_model
from ..closures.coefficients import Dimensional
from .steady import steady_temperature
from ..errors import InputError
from ..validation import check_positive, check_range

#: Names of the five perturbation amplitudes, in the order of the matrix.
FIELDS: tuple[str, ...] = ("phi", "u_x", "u_y", "u_z", "theta")
#: Relative step of the central difference for ∂η*/∂φ.
_PHI_STEP = 1e-6


class ShearBase(NamedTuple):
    """Steady uniform shear in SI units and the derivatives the linearisation needs.

    Attributes: solid fraction ``phi``, ``shear_rate`` γ̇ [1/s], ``theta`` [m²/s²], bulk density
    ``rho`` [kg/m³], the model's SI coefficients ``c`` (:class:`~ktgf.closures.coefficients.Dimensional`:
    p, η, λ_b, κ, ω, ζ0, ζ_U), ``p_phi`` = ∂p/∂φ [Pa], ``eta_phi`` = ∂η/∂φ [Pa s],
    ``gamma`` = Γ = (3/2)ρθζ0 [W/m³] and ``gamma_phi`` = ∂Γ/∂φ [W/m³], all at fixed θ.
    """

    phi: float
    shear_rate: float
    theta: float
    rho: float
    c: Dimensional
    p_phi: Any
    eta_phi: Any
    gamma: Any
    gamma_phi: Any


def shear_base_state(model: Any, phi: float, e: float, shear_rate: float, *, d: float, rho_s: float) -> ShearBase:
    """The steady uniform shear of ``model`` at (φ, e, γ̇) for particles of diameter d and density ρ_s.

    Raises :class:`~ktgf.errors.InputError` for e = 1 (no steady uniform shear), a non-positive
    shear rate, or a model whose cooling rate depends on the local shear (extended kinetic
    theory: its perturbation is not part of this linearisation).
    """
    model = get_model(model)
    model.check(phi, e)
    check_range("restitution coefficient e", e, low=0.0, high=1.0, low_open=True, high_open=True,
                why="uniform shear needs dissipation")
    check_positive("shear rate", shear_rate, "1/s")
    check_positive("particle diameter d", d, "m")
    check_positive("material density rho_s", rho_s, "kg/m^3")
    if model.shear_dependent:
        what = (f"dissipation {model.dissipation.key!r}" if model.dissipation.key != "none"
                else "radial distribution (shear_amplitude > 0)" if getattr(model.rdf, "shear_dependent", False)
                else "sink of the tangential stress (friction option tangential_stress)")
        raise InputError(f"model {model.name!r} has the shear-dependent {what}; the uniform-shear stability analysis "
                         "supports models whose coefficients do not depend on the shear (dissipation 'none', "
                         "tangential_stress 'none', shear_amplitude 0)")
    theta = float(steady_temperature(model, phi, e)) * (shear_rate * d) ** 2
    c = model.coefficients(phi, e, theta, d=d, rho_s=rho_s)
    r = model.reduced(phi, e)
    h = _PHI_STEP * max(phi, 1e-3)
    deta = (model.coefficients(phi + h, e, theta, d=d, rho_s=rho_s, check=False).eta
            - model.coefficients(phi - h, e, theta, d=d, rho_s=rho_s, check=False).eta) / (2.0 * h)
    rho = rho_s * phi
    gamma = 1.5 * rho * theta * float(c.zeta0)
    return ShearBase(
        phi=float(phi), shear_rate=float(shear_rate), theta=theta, rho=rho, c=Dimensional(*(float(v) for v in c)),
        p_phi=rho_s * theta * float(r.C), eta_phi=float(deta), gamma=gamma, gamma_phi=gamma * (1.0 + float(r.g)) / phi,
    )


def shear_matrix(base: ShearBase, kx: Any, ky: Any, kz: Any) -> np.ndarray:
    """The matrix A(k) of dy/dt = A y (module docstring), shape ``broadcast(kx, ky, kz) + (5, 5)``, complex, [1/s].

    ``kx, ky, kz`` are wavenumbers [1/m] in the frame of the base flow.  For k_x = 0 the
    eigenvalues of A are the growth rates; for k_x ≠ 0 A holds only at one instant (Kelvin mode).
    """
    b, c = base, base.c
    kx, ky, kz = np.broadcast_arrays(*(np.asarray(k, dtype=float) for k in (kx, ky, kz)))
    k2 = kx**2 + ky**2 + kz**2
    g, rho, th = b.shear_rate, b.rho, b.theta
    eta_t, p_t, gam_t = c.eta / (2.0 * th), c.p / th, 1.5 * b.gamma / th  # θ-derivatives (∝ √θ scalings)
    bulk = c.eta / 3.0 + c.lambda_b
    A = np.zeros(kx.shape + (5, 5), dtype=complex)
    kv = (kx, ky, kz)
    # mass: dδφ/dt = −iφ k·δu
    for j in range(3):
        A[..., 0, 1 + j] = -1j * b.phi * kv[j]
    # momentum: pressure, perturbed base stress γ̇δη (x row from k_y, y row from k_x), viscous terms
    shear_eta = (1j * g * ky, 1j * g * kx, 0.0 * kx)
    for i in range(3):
        A[..., 1 + i, 0] = (-1j * kv[i] * b.p_phi + shear_eta[i] * b.eta_phi) / rho
        A[..., 1 + i, 4] = (-1j * kv[i] * p_t + shear_eta[i] * eta_t) / rho
        for j in range(3):
            A[..., 1 + i, 1 + j] = -bulk * kv[i] * kv[j] / rho
        A[..., 1 + i, 1 + i] += -c.eta * k2 / rho
    A[..., 1, 2] += -g  # lift-up: the base velocity gradient advected by δu_y
    # energy: conduction, compression work and ζ_U, perturbed shear work, perturbed dissipation
    cv = 1.5 * rho
    A[..., 4, 0] = (-c.omega * k2 + g**2 * b.eta_phi - b.gamma_phi) / cv
    A[..., 4, 4] = (-c.kappa * k2 + g**2 * eta_t - gam_t) / cv
    comp = c.p + 1.5 * rho * th * c.zeta_u
    for j in range(3):
        A[..., 4, 1 + j] = -1j * comp * kv[j] / cv
    A[..., 4, 1] += 2j * c.eta * g * ky / cv
    A[..., 4, 2] += 2j * c.eta * g * kx / cv
    return A


def _scales(base: ShearBase) -> np.ndarray:
    """Amplitude scales (φ, √θ, √θ, √θ, θ): the eigenproblem is solved in these units."""
    s = math.sqrt(base.theta)
    return np.array([base.phi, s, s, s, base.theta])


class ShearModes(NamedTuple):
    """Normal modes of uniform shear at wavevectors (0, k_y, k_z).

    Attributes
    ----------
    growth_rates : (..., 5) complex σ [1/s], sorted by decreasing real part; a mode grows as exp(σt).
    vectors : (..., 5, 5) complex; ``vectors[..., :, m]`` is mode m in SI amplitudes
        (δφ, δu_x, δu_y, δu_z, δθ), normalised so that (δφ/φ, δu/√θ, δθ/θ) has unit norm and its
        largest component is real and positive.
    base : the :class:`ShearBase`.
    """

    growth_rates: Any
    vectors: Any
    base: ShearBase


def shear_modes(model: Any, phi: float, e: float, shear_rate: float, ky: Any, kz: Any = 0.0, *, d: float,
                rho_s: float) -> ShearModes:
    """Growth rates and eigenvectors of uniform shear for perturbations exp(i(k_y y + k_z z) + σt).

    Parameters
    ----------
    model, phi, e, shear_rate : the base state (:func:`shear_base_state`); γ̇ in 1/s.
    ky, kz : wavenumbers [1/m] in the gradient (y) and vorticity (z) directions (broadcast).
    d, rho_s : particle diameter [m] and material density [kg/m³].

    Examples
    --------
    >>> m = shear_modes("ret", 0.3, 0.9, 100.0, ky=2 * 3.14159 / 0.02, d=1e-3, rho_s=2500.0)
    >>> m.growth_rates.shape, m.vectors.shape
    ((5,), (5, 5))
    """
    base = shear_base_state(model, phi, e, shear_rate, d=d, rho_s=rho_s)
    S = _scales(base)
    A = shear_matrix(base, 0.0, ky, kz)
    As = A * S[None, :] / S[:, None]  # D⁻¹ A D with D = diag(S)
    s, v = np.linalg.eig(As)
    order = np.argsort(-s.real, axis=-1)
    s = np.take_along_axis(s, order, axis=-1)
    v = np.take_along_axis(v, order[..., None, :], axis=-1)
    v = v / np.linalg.norm(v, axis=-2, keepdims=True)
    big = np.take_along_axis(v, np.abs(v).argmax(axis=-2)[..., None, :], axis=-2)
    v = v * (np.abs(big) / big)
    return ShearModes(growth_rates=s, vectors=v * S[:, None], base=base)


def kelvin_evolution(base: ShearBase, k0: tuple[float, float, float], y0: Any, times: Any, *, rtol: float = 1e-10,
                     atol: float = 1e-14) -> np.ndarray:
    """Amplitudes y(t) of a Kelvin mode: wavevector k(t) = (k_x, k_y0 − γ̇ k_x t, k_z), dy/dt = A(k(t)) y.

    ``k0`` is the wavevector at t = 0 [1/m], ``y0`` the SI amplitudes (δφ, δu_x, δu_y, δu_z, δθ) at
    t = 0 and ``times`` the output times [s] (increasing, from 0).  Integrated in the scaled
    amplitudes of :class:`ShearModes` with an explicit Runge–Kutta method (DOP853).  Returns
    shape ``(len(times), 5)``.  For k_x = 0 this is exp(At) y0.
    """
    from scipy.integrate import solve_ivp

    kx, ky0, kz = (float(k) for k in k0)
    S = _scales(base)
    g = base.shear_rate

    def rhs(t: float, z: np.ndarray) -> np.ndarray:
        A = shear_matrix(base, kx, ky0 - g * kx * t, kz)
        return (A * S[None, :] / S[:, None]) @ z

    times = np.asarray(times, dtype=float)
    sol = solve_ivp(rhs, (0.0, float(times[-1])), np.asarray(y0, dtype=complex) / S, method="DOP853",
                    t_eval=times, rtol=rtol, atol=atol)
    if not sol.success:  # pragma: no cover - DOP853 on a linear system
        raise RuntimeError(f"Kelvin-mode integration failed: {sol.message}")
    return sol.y.T * S
