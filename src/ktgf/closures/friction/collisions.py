"""Frictional collisions in kinetic theory: effective restitution and the modified dissipation.

A frictional (or rough) collision removes more energy than a smooth one: part of the relative
tangential motion is destroyed, and energy fed into rotation is later dissipated too.  In a
kinetic theory of *frictionless* spheres this is represented by an effective restitution
coefficient e_eff < e that enters the collisional dissipation (the cooling rate ζ0) only:

    ζ0*_frictional = ζ0*(φ, e) · (1 − e_eff²)/(1 − e²)                                   (1)

(the form of Chialvo & Sundaresan 2013, their modified dissipation K' = K (1 − e_eff²)/(1 − e²)),
so pressure and viscosity keep the normal restitution e.  Two laws for e_eff are given here:

* :class:`ChialvoSundaresanRestitution` — e_eff = e − (3/2) μ exp(−3μ), the fit of Chialvo &
  Sundaresan (2013) to their DEM of sheared frictional spheres (Coulomb friction μ);
* :class:`RoughSphereRestitution` — spheres with a constant tangential restitution β, with the
  rotational temperature from the Maxwellian collision integrals of Huthmann & Zippelius (1997);
  it also predicts T_rot/T, which the frictional DEM file reports;
* :class:`WaltonRestitution` — Coulomb friction μ with a sticking tangential restitution β0
  (Walton's rule), averaged numerically over the same Maxwellian: no fitted roughness.

All reduce exactly to e at μ = 0.  Jenkins & Zhang (2002) give closed forms for Walton's rule in the
nearly elastic limit; those are *not* transcribed: we could not read the paper's equations to check
them (see ``docs/friction.md``).

Glossary: ``e`` normal restitution, ``mu`` particle (Coulomb) friction coefficient, ``beta``
tangential restitution (−1 smooth … +1 perfectly rough), ``q`` = 4I/(m d²) (2/5 for a solid sphere).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache, wraps
from typing import Any, ClassVar

from ..._array import namespace
from ._part import FrictionPart, check_friction_coefficient, check_range


def modified_cooling_rate(zeta0: Any, e: Any, inelasticity: Any) -> Any:
    """ζ0* with the collisional dissipation of an effective restitution, Eq. (1) above.

    ``inelasticity`` is 1 − e_eff² (from a law's :meth:`inelasticity`).  Chialvo & Sundaresan,
    Phys. Fluids 25, 070603 (2013): K' = K (1 − e_eff²)/(1 − e²) (their Eq. 26 as cited by the
    CFDEM-PRINCETON implementation; not checked against the printed paper).  Needs e < 1.
    """
    return zeta0 * inelasticity / (1.0 - e**2)


def _memoised(method: Any) -> Any:
    """Cache a scalar method of a frozen law on (law, e, μ): a root find over quadratures whose value the solvers
    ask for at every residual evaluation with the same material constants (the same float, so bit for bit)."""
    cached = lru_cache(maxsize=1024)(method)

    @wraps(method)
    def call(self: Any, e: Any, mu: Any, *rest: Any) -> Any:
        return cached(self, float(e), float(mu), *rest)

    return call


@dataclass(frozen=True)
class ChialvoSundaresanRestitution(FrictionPart):
    """Chialvo & Sundaresan (2013): e_eff = e − a μ exp(−b μ), a = 3/2, b = 3.

    Chialvo & Sundaresan, "A modified kinetic theory for frictional granular flows in dense and
    dilute regimes", Phys. Fluids 25, 070603 (2013): a fit to DEM of simple shear of frictional
    spheres.  The form and constants (3/2, 3) are those of the public implementation of this
    model in CFDEM-PRINCETON (``twoPhaseEulerFoamPU/kineticTheoryModel.C``: ``eEff_ = e_ - 3.0/2.0*
    muFric_*exp(-3.0*muFric_)``); the paper's own equation number could not be checked.
    Limits: e_eff = e at μ = 0 and as μ → ∞; the largest reduction, a/(b·exp 1) = 0.184, is at μ = 1/b.
    """

    amplitude: float = 1.5
    decay: float = 3.0
    key: ClassVar[str] = "chialvo-sundaresan-2013"
    label: ClassVar[str] = "Chialvo–Sundaresan e_eff"
    reference: ClassVar[str] = "Chialvo & Sundaresan, Phys. Fluids 25, 070603 (2013)"

    def __post_init__(self) -> None:
        check_range("e_eff amplitude a", self.amplitude, low=0.0)
        check_range("e_eff decay rate b", self.decay, low=0.0)

    def effective_restitution(self, e: Any, mu: Any) -> Any:
        """e_eff(e, μ) = e − a μ exp(−b μ)."""
        xp = namespace(e, mu)
        return e - self.amplitude * mu * xp.exp(-self.decay * mu)

    def d_effective_restitution_dmu(self, e: Any, mu: Any) -> Any:
        """∂e_eff/∂μ = −a exp(−b μ)(1 − b μ)."""
        xp = namespace(e, mu)
        return -self.amplitude * xp.exp(-self.decay * mu) * (1.0 - self.decay * mu)

    def inelasticity(self, e: Any, mu: Any) -> Any:
        """1 − e_eff², the factor of the collisional dissipation."""
        return 1.0 - self.effective_restitution(e, mu) ** 2

    def rotational_ratio(self, e: Any, mu: Any) -> Any:
        """T_rot/T is not modelled by this law (returns ``None``)."""
        return None

    def check(self, e: Any, mu: Any) -> None:
        """Raise :class:`~ktgf.errors.InputError` for μ < 0 or an e_eff outside (−1, 1]."""
        check_friction_coefficient(mu)
        check_range("effective restitution e_eff", self.effective_restitution(e, mu), low=-1.0, high=1.0,
                    low_open=True, why="from e and mu")


@dataclass(frozen=True)
class RoughSphereRestitution(FrictionPart):
    """Rough spheres of constant tangential restitution β: T_rot/T and e_eff in a steady homogeneous state.

    Collision rule: normal relative contact velocity × (−e), tangential × (−β).  With Maxwellian
    translational (T) and rotational (T_rot) velocities, the collisional rates of change are
    (Huthmann & Zippelius, Phys. Rev. E 56, R6275 (1997); written this way by Luding, Huthmann,
    McNamara & Zippelius, Phys. Rev. E 58, 3416 (1998), whose 3D form has equal prefactors)

        dT/dt ∝ −A T + B T_rot,     dT_rot/dt ∝ B T − C T_rot,
        A = (1 − e²)/4 + η(1 − η),  B = η²/q,  C = (η/q)(1 − η/q),   η = q(1 + β)/(2(1 + q)).

    The three coefficients are checked in the tests against a direct Monte Carlo average of the
    collision rule (independent of these formulas).  In a steady homogeneous state (uniform shear
    heats translation only) the rotational balance gives T_rot/T = B/C = η/(1 − η/q), and the
    net translational dissipation A − B²/C defines e_eff through (1 − e_eff²)/4 = A − B²/C:

        1 − e_eff² = (1 − e²) + 4[η(1 − η) − η³/(q − η)].

    Limits: β = −1 (smooth) gives η = 0, e_eff = e, T_rot = 0; β = 1 and e = 1 give equipartition
    (T_rot = T) and no dissipation.  Frictionless particles have no tangential impulse, so at μ = 0
    the law uses β = −1 whatever the ``beta`` option; ``beta`` is the effective tangential restitution of
    the frictional contacts (a calibration parameter: constant β is a simplification of Coulomb friction).
    Defaults β = −1 (smooth), q = 2/5 (solid sphere, I = m d²/10 as in the shared DEM data).
    """

    beta: float = -1.0
    q: float = 0.4
    key: ClassVar[str] = "rough-sphere"
    label: ClassVar[str] = "Rough spheres (constant β)"
    reference: ClassVar[str] = "Huthmann & Zippelius, Phys. Rev. E 56, R6275 (1997); Luding et al., Phys. Rev. E 58, 3416 (1998)"

    def __post_init__(self) -> None:
        check_range("tangential restitution beta", self.beta, low=-1.0, high=1.0)
        check_range("reduced moment of inertia q", self.q, low=0.0, high=2.0 / 3.0, low_open=True,
                    why="q = 4I/(m d^2); 2/3 is a hollow shell")

    def _beta(self, mu: Any) -> Any:
        xp = namespace(mu)
        return xp.where(mu > 0.0, self.beta, -1.0)

    def tangential_factor(self, mu: Any) -> Any:
        """η = q(1 + β)/(2(1 + q)) (0 for smooth spheres)."""
        return self.q * (1.0 + self._beta(mu)) / (2.0 * (1.0 + self.q))

    def collision_coefficients(self, e: Any, mu: Any) -> tuple[Any, Any, Any]:
        """(A, B, C) of the translational/rotational collisional energy exchange."""
        eta = self.tangential_factor(mu)
        q = self.q
        return (1.0 - e**2) / 4.0 + eta * (1.0 - eta), eta**2 / q, (eta / q) * (1.0 - eta / q)

    def rotational_ratio(self, e: Any, mu: Any) -> Any:
        """T_rot/T = η/(1 − η/q) in a steady homogeneous state (independent of e and φ)."""
        eta = self.tangential_factor(mu)
        return eta / (1.0 - eta / self.q) + 0.0 * e

    def inelasticity(self, e: Any, mu: Any) -> Any:
        """1 − e_eff² = (1 − e²) + 4[η(1 − η) − η³/(q − η)] (it may exceed 1 for small e and β ≈ 0)."""
        eta = self.tangential_factor(mu)
        return (1.0 - e**2) + 4.0 * (eta * (1.0 - eta) - eta**3 / (self.q - eta))

    def effective_restitution(self, e: Any, mu: Any) -> Any:
        """e_eff = √(1 − inelasticity); NaN where the inelasticity exceeds 1 (no real e_eff)."""
        xp = namespace(e, mu)
        return xp.sqrt(1.0 - self.inelasticity(e, mu))

    def hcs_rotational_ratio(self, e: Any, mu: Any) -> Any:
        """T_rot/T in the homogeneous cooling state, where both temperatures decay together.

        d(T_rot/T)/dτ = B + (A − C) r − B r² = 0 gives r = [A − C + √((A − C)² + 4B²)]/(2B)
        (Huthmann & Zippelius 1997; Luding et al. 1998).  Smooth spheres (B = 0) exchange no energy
        with rotation: r = 0 is returned (the state that starts without rotation keeps none).
        """
        xp = namespace(e, mu)
        A, B, C = self.collision_coefficients(e, mu)
        coupled = B > 0.0
        safe = xp.where(coupled, B, 1.0)
        return xp.where(coupled, (A - C + xp.sqrt((A - C) ** 2 + 4.0 * B**2)) / (2.0 * safe), 0.0)

    def hcs_inelasticity(self, e: Any, mu: Any) -> Any:
        """4(A − B r_HCS): the translational cooling of the HCS in units of the smooth (1 − e²).

        At T_rot = r T the translational balance dT/dτ ∝ −4(A T − B T_rot) (the smooth gas: −(1 − e²) T)
        makes Haff's law of rough spheres dT/dt = −[4(A − B r)/(1 − e²)] × (smooth cooling rate)
        (Luding, Huthmann, McNamara & Zippelius 1998; both temperatures decay at this rate).  It equals
        1 − e² for smooth spheres (B = 0, r = 0).
        """
        A, B, _ = self.collision_coefficients(e, mu)
        return 4.0 * (A - B * self.hcs_rotational_ratio(e, mu))

    def check(self, e: Any, mu: Any) -> None:
        """Raise :class:`~ktgf.errors.InputError` for μ < 0."""
        check_friction_coefficient(mu)


@lru_cache(maxsize=256)
def _walton_moments(e: float, mu: float, beta0: float, q: float, r: float) -> tuple[float, float]:
    """⟨η ρ²⟩ and ⟨η² ρ²⟩ per collision (T = m = 1) for Walton's rule at T_rot/T = r.

    ρ = |g_ct| (relative tangential contact velocity: 2D Gaussian, variance σ² = 2(1 + r/q) per
    component), g_n rate-weighted (density (g/2) exp(−g²/4)); u = g_n²/4, v = ρ²/(2σ²).  Sticking
    (ρ ≤ c g_n/(1 + β0), c = μ(1 + e)(1 + 1/q)) has η = η0; sliding has η = μ(1 + e) g_n/(2ρ).  The v
    integral is analytic (incomplete gamma functions), the u integral is done numerically.
    """
    from scipy.integrate import quad
    from scipy.special import gamma, gammaincc

    sigma2 = 2.0 * (1.0 + r / q)
    eta0 = q * (1.0 + beta0) / (2.0 * (1.0 + q))
    slide = mu * (1.0 + e)

    def integrands(u: float) -> tuple[float, float]:
        gn = 2.0 * math.sqrt(u)
        vstar = (slide * (1.0 + 1.0 / q) * gn / (1.0 + beta0)) ** 2 / (2.0 * sigma2)
        stick = 2.0 * sigma2 * (1.0 - (1.0 + vstar) * math.exp(-vstar))  # ∫_0^v* ρ² e^(−v) dv
        tail_rho = math.sqrt(2.0 * sigma2) * gamma(1.5) * gammaincc(1.5, vstar)  # ∫_v*^∞ ρ e^(−v) dv
        first = eta0 * stick + 0.5 * slide * gn * tail_rho
        second = eta0**2 * stick + 0.25 * slide**2 * gn**2 * math.exp(-vstar)
        return first * math.exp(-u), second * math.exp(-u)

    m1 = quad(lambda u: integrands(u)[0], 0.0, math.inf, epsabs=1e-13, epsrel=1e-11, limit=200)[0]
    m2 = quad(lambda u: integrands(u)[1], 0.0, math.inf, epsabs=1e-13, epsrel=1e-11, limit=200)[0]
    return m1, m2


@lru_cache(maxsize=256)
def _walton_shear_moments(e: float, mu: float, beta0: float, q: float, r: float) -> Any:
    """Rate-weighted Gaussian averages E[(g_n)⁺ h A] for Walton's rule at T_rot/T = r (T = m = 1, not per collision).

    Rows h = ηρ², η²ρ²; columns A = 1, (g_n² − 2)/4, ρ²/(2σ⁴) − 1/σ² (the Hermite weights of a second-order
    shift of the normal and the tangential contact velocity).  The ρ integrals are closed (incomplete gamma
    functions of v = ρ²/(2σ²), split at the sticking threshold as in :func:`_walton_moments`), the g_n integral
    is numerical.  Column 0 times √π is :func:`_walton_moments`.
    """
    import numpy as np
    from scipy.integrate import quad
    from scipy.special import gamma, gammainc, gammaincc

    sigma2 = 2.0 * (1.0 + r / q)
    eta0 = q * (1.0 + beta0) / (2.0 * (1.0 + q))
    slide = mu * (1.0 + e)

    def upper(a: float, x: float) -> float:  # Γ(a, x)
        return gamma(a) * gammaincc(a, x)

    def lower(a: float, x: float) -> float:  # γ(a, x)
        return gamma(a) * gammainc(a, x)

    def integrand(gn: float, row: int, col: int) -> float:
        vstar = (slide * (1.0 + 1.0 / q) * gn / (1.0 + beta0)) ** 2 / (2.0 * sigma2)
        if row == 0:  # ηρ²: 2σ²η0 v sticking, (slide g_n/2) √(2σ² v) sliding
            stick = 2.0 * sigma2 * eta0 * (lower(2.0, vstar) if col != 2 else lower(3.0, vstar) - lower(2.0, vstar))
            base = 0.5 * slide * gn * math.sqrt(2.0 * sigma2)
            sl = base * (upper(1.5, vstar) if col != 2 else upper(2.5, vstar) - upper(1.5, vstar))
        else:  # η²ρ²: 2σ²η0² v sticking, slide² g_n²/4 sliding
            stick = 2.0 * sigma2 * eta0**2 * (lower(2.0, vstar) if col != 2 else lower(3.0, vstar) - lower(2.0, vstar))
            sl = 0.25 * slide**2 * gn**2 * math.exp(-vstar) * (1.0 if col != 2 else vstar)
        value = stick + sl
        if col == 1:
            value *= (gn * gn - 2.0) / 4.0
        elif col == 2:
            value /= sigma2
        return gn * math.exp(-gn * gn / 4.0) / math.sqrt(4.0 * math.pi) * value

    out = np.array([[quad(integrand, 0.0, math.inf, args=(row, col), epsabs=1e-14, epsrel=1e-11, limit=200)[0]
                     for col in range(3)] for row in range(2)])
    out.setflags(write=False)  # cached: shared by every caller
    return out


@dataclass(frozen=True)
class WaltonRestitution(FrictionPart):
    """Coulomb friction μ with a sticking tangential restitution β0 (Walton's collision rule), Maxwellian closure.

    Walton, Mech. Mater. 16, 239 (1993) (the rule used by Jenkins & Zhang 2002): a collision has
    tangential restitution β = min(β0, −1 + μ(1 + e)(1 + 1/q) |g_n|/|g_ct|) — it sticks (β0) when friction
    can stop the contact, and slides otherwise.  Averaging the energy changes over Maxwellian
    translational (T) and rotational (T_rot) velocities, as for :class:`RoughSphereRestitution`, with
    ⟨ΔE_rot⟩ = m[⟨η²ρ²⟩/q − f⟨ηρ²⟩], ⟨ΔE_tr⟩ = −(1 − e²)T − m[(1 − f)⟨ηρ²⟩ − ⟨η²ρ²⟩],
    f = r/(q + r), r = T_rot/T, ρ = |g_ct| (our derivation; the averages are done by
    :func:`_walton_moments`, checked against a Monte Carlo of the collision rule in the tests).  In steady
    uniform shear ⟨ΔE_rot⟩ = 0 fixes r, and ⟨ΔE_tr⟩ = −(1 − e_eff²)T gives the inelasticity.

    Unlike the constant-β law it needs no fitted roughness: μ and β0 are contact properties.
    Limits (tested): μ = 0 is smooth (e_eff = e, T_rot = 0); μ → ∞ always sticks and gives
    :class:`RoughSphereRestitution` with β = β0.  Default β0 = 1: a linear tangential spring without
    damping and k_t/k_n = 2/7 (the shared DEM's contact) oscillates at the normal frequency for solid
    spheres, so a sticking contact reverses its tangential velocity.  NumPy/SciPy only (quadrature), scalars.
    """

    beta0: float = 1.0
    q: float = 0.4
    key: ClassVar[str] = "walton"
    label: ClassVar[str] = "Coulomb friction + sticking β0 (Walton)"
    reference: ClassVar[str] = "Walton, Mech. Mater. 16, 239 (1993); Maxwellian averages: docs/friction.md"

    def __post_init__(self) -> None:
        check_range("sticking tangential restitution beta0", self.beta0, low=-1.0, high=1.0, low_open=True)
        check_range("reduced moment of inertia q", self.q, low=0.0, high=2.0 / 3.0, low_open=True,
                    why="q = 4I/(m d^2); 2/3 is a hollow shell")

    def _rotational_balance(self, e: float, mu: float, r: float) -> float:
        m1, m2 = _walton_moments(float(e), float(mu), self.beta0, self.q, float(r))
        return m2 / self.q - r / (self.q + r) * m1

    @_memoised
    def rotational_ratio(self, e: Any, mu: Any) -> float:
        """T_rot/T with the rotational energy balance of steady homogeneous shear (0 at μ = 0)."""
        from scipy.optimize import brentq

        if float(mu) == 0.0:
            return 0.0
        # the balance is positive at r = 0 (friction spins the particles up) and negative for large r
        high = 1.0
        while self._rotational_balance(e, mu, high) > 0.0:
            high *= 2.0
            if high > 1e12:  # pragma: no cover - the balance turns negative for every β0 > −1
                raise RuntimeError(f"no rotational steady state found for e = {e}, mu = {mu}, beta0 = {self.beta0}")
        return brentq(lambda r: self._rotational_balance(e, mu, r), 0.0, high, xtol=1e-13, rtol=1e-12)

    def inelasticity(self, e: Any, mu: Any) -> float:
        """1 − e_eff² at the steady rotational ratio."""
        if float(mu) == 0.0:
            return 1.0 - float(e) ** 2
        r = self.rotational_ratio(e, mu)
        m1, m2 = _walton_moments(float(e), float(mu), self.beta0, self.q, r)
        return (1.0 - float(e) ** 2) + (self.q / (self.q + r)) * m1 - m2

    def effective_restitution(self, e: Any, mu: Any) -> float:
        """e_eff = √(1 − inelasticity) (NaN if the inelasticity exceeds 1)."""
        loss = self.inelasticity(e, mu)
        return math.sqrt(1.0 - loss) if loss <= 1.0 else math.nan

    def _energy_changes(self, e: float, mu: float, r: float) -> tuple[float, float]:
        """(⟨ΔE_tr⟩, ⟨ΔE_rot⟩) per collision at T = m = 1, T_rot/T = r (class docstring; same prefactor)."""
        m1, m2 = _walton_moments(float(e), float(mu), self.beta0, self.q, float(r))
        f = r / (self.q + r)
        return -(1.0 - float(e) ** 2) - ((1.0 - f) * m1 - m2), m2 / self.q - f * m1

    def tangential_shear_share(self, e: Any, mu: Any, r: float | None = None) -> float:
        """Collisional shear stress of the tangential impulses over that of the normal ones, in steady uniform shear.

        Our derivation (docs/friction.md §7.1), for the local-equilibrium (Maxwellian) collisional transfer: to
        first order in the mean strain E, the mean relative contact velocity −d E·k (spins about half the
        vorticity) shifts the Gaussian of g_c, and Stein's lemma turns the change of ⟨(g·k)⁺ J k⟩ into moments at
        E = 0.  The normal impulse gives (1 + e)/(15√π) s, the tangential one ⟨η ρ²⟩/(20 σ²√π) s (orientation
        averages ⟨k_x²k_y²⟩ = 1/15, ⟨k_y²(1/2 − k_x²)⟩ = 1/10), so the share is

            3 ⟨η ρ²⟩ / (4 σ² (1 + e)),   σ² = 2(1 + r/q),  r = T_rot/T (:meth:`rotational_ratio`),

        with ⟨η ρ²⟩ of :func:`_walton_moments` (``r``: another ratio, e.g. the homogeneous cooling state's).
        Limits: 0 at μ = 0; for constant β (μ → ∞) ⟨η ρ²⟩ = 2σ²η0 and
        the share is 3η0/(2(1 + e)), η0 = q(1 + β0)/(2(1 + q)) (0.252 at β0 = 1, e = 0.7, q = 0.4).  Checked against
        a Monte Carlo of the collision rule under shear in the tests (0.1613 at μ = 0.5, e = 0.7, β0 = 1).
        Used through the friction option ``tangential_stress`` (:meth:`Friction.tangential_coefficients`).
        """
        if float(mu) == 0.0:
            return 0.0
        r = self.rotational_ratio(e, mu) if r is None else float(r)
        m1, _ = _walton_moments(float(e), float(mu), self.beta0, self.q, r)
        return 3.0 * m1 / (8.0 * (1.0 + r / self.q) * (1.0 + float(e)))

    def _shear_balances(self, e: float, mu: float, r: float) -> dict[str, float]:
        """Rate-weighted rotational and tangential-translational energy changes and the tangential work, at
        s = 0 and their s² coefficients (s = γ̇d/√T), at T_rot/T = r (:meth:`tangential_work_fraction`)."""
        mom = _walton_shear_moments(e, mu, self.beta0, self.q, r)
        sigma2, f = 2.0 * (1.0 + r / self.q), r / (self.q + r)
        shifted = 0.5 * (mom[:, 1] / 15.0 + mom[:, 2] / 10.0)  # ⟨δ_n²⟩ = s²/15, ⟨|δ_t|²⟩ = s²/10
        work = mom[0, 0] / (20.0 * sigma2)
        return {"rot0": -f * mom[0, 0] + mom[1, 0] / self.q, "rot2": -f * shifted[0] + shifted[1] / self.q + f * work,
                "tr0": -(1.0 - f) * mom[0, 0] + mom[1, 0], "tr2": -(1.0 - f) * shifted[0] + shifted[1] + (1.0 - f) * work,
                "work2": work}

    @_memoised
    def _shear_expansion(self, e: float, mu: float, dr: float = 1e-4) -> tuple[float, float]:
        """(c_r, f): the steady ratio's shift Δr = c_r s² and the tangential work fraction, both to O(s²)."""
        r = self.rotational_ratio(e, mu)
        b = self._shear_balances(e, mu, r)
        up, down = self._shear_balances(e, mu, r + dr), self._shear_balances(e, mu, r - dr)
        shift = -b["rot2"] * 2.0 * dr / (up["rot0"] - down["rot0"])
        return shift, (b["tr2"] + (up["tr0"] - down["tr0"]) / (2.0 * dr) * shift) / b["work2"]

    def tangential_work_fraction(self, e: Any, mu: Any) -> float:
        """The part of the tangential impulses' shear work that heats translation, in steady uniform shear as s → 0.

        Our derivation (docs/friction.md §7.1), per unit time and to O(s²), s = γ̇d/√T.  Conditioned on the contact
        velocity g, the spins' share of g_t is f_r = r/(q + r) of its deviation from the mean, so the tangential
        impulse J_t = −η g_t changes the pair's translational energy by −(1 − f_r)ηρ² + η²ρ² + (1 − f_r)η g_t·δ_t
        and the rotational one by −f_r ηρ² + η²ρ²/q + f_r η g_t·δ_t, δ = −d E·k the mean contact velocity; η g_t·δ_t
        is the mean flow's work.  The shift δ of the Gaussian of g is expanded to second order (Hermite weights,
        :func:`_walton_shear_moments`).  The rotational balance moves the steady ratio by Δr = −s² R₂/∂_r R₀
        (:meth:`rotational_shear_shift`), and the fraction is (X₂ + ∂_r X₀ Δr/s²)/W₂: the translational change over
        the work, both O(s²).  The rest of the work is dissipated.  0.179 at μ = 0.5, e = 0.7, β0 = 1 (Monte Carlo:
        0.167–0.198 at s = 1–2.2).  NaN at μ = 0 (no tangential impulse, no work).
        """
        if float(mu) == 0.0:
            return math.nan
        return self._shear_expansion(float(e), float(mu))[1]

    def rotational_shear_shift(self, e: Any, mu: Any) -> float:
        """c_r in T_rot/T = r + c_r s² of steady uniform shear, s = γ̇d/√T (our derivation, docs/friction.md §7.1).

        The mean strain adds −d E·k to the contact velocity, whose tangential part spins the particles up: the
        rotational balance R(r, s) = R₀(r) + s² R₂(r) + O(s⁴) (:meth:`_shear_balances`) vanishes at
        r + Δr with Δr = −s² R₂/∂_r R₀.  This is the same shift that :meth:`tangential_work_fraction` carries into
        the translational energy balance, so a model with both is consistent to O(s²).  0.0139 at μ = 0.5,
        e = 0.7, β0 = 1 (the Monte Carlo's steady ratios: 0.5007, 0.5107, 0.5617 at s = 0.5, 1, 2.2 against
        0.5008, 0.5112, 0.5646).  0 at μ = 0.
        """
        if float(mu) == 0.0:
            return 0.0
        return self._shear_expansion(float(e), float(mu))[0]

    @_memoised
    def hcs_rotational_ratio(self, e: Any, mu: Any) -> float:
        """T_rot/T of the homogeneous cooling state: both temperatures decay at the same relative rate.

        With dT/dτ ∝ ⟨ΔE_tr⟩ T and dT_rot/dτ ∝ ⟨ΔE_rot⟩ T (equal prefactors: for constant β these are
        −4(A T − B T_rot) and 4(B T − C T_rot), :class:`RoughSphereRestitution`), r = T_rot/T obeys
        dr/dτ ∝ ⟨ΔE_rot⟩(r) − r ⟨ΔE_tr⟩(r); its positive root is returned (0 at μ = 0).  When the drift
        stays positive up to r = 10³ there is no finite ratio in this Maxwellian closure — weak sliding
        friction drains rotation more slowly than the normal restitution cools translation, so T_rot/T grows
        without bound — and ``inf`` is returned (e = 0.7, β0 = 1: μ = 0.1 gives inf, μ = 0.5 gives 1.6).
        Limit (tested): μ → ∞ gives the rough-sphere value of Huthmann & Zippelius (1997) with β = β0.
        """
        from scipy.optimize import brentq

        if float(mu) == 0.0:
            return 0.0

        def drift(r: float) -> float:
            tr, rot = self._energy_changes(e, mu, r)
            return rot - r * tr

        high = 1.0
        while drift(high) > 0.0:  # friction spins a rotation-free gas up; the drift turns negative, or never
            high *= 2.0
            if high > 1e3:
                return math.inf
        return brentq(drift, 0.0, high, xtol=1e-13, rtol=1e-12)

    def hcs_inelasticity(self, e: Any, mu: Any) -> float:
        """1 − e_HCS² = −⟨ΔE_tr⟩ at the HCS ratio: the translational cooling of the HCS in units of the smooth (1 − e²).

        Haff's law for frictional spheres: dT/dt = −(1 − e_HCS²)/(1 − e²) × (smooth cooling rate), since
        translational and rotational temperature decay together at that rate.  NaN where the ratio is infinite.
        """
        if float(mu) == 0.0:
            return 1.0 - float(e) ** 2
        r = self.hcs_rotational_ratio(e, mu)
        return math.nan if math.isinf(r) else -self._energy_changes(e, mu, r)[0]

    def hcs_friction_threshold(self, e: Any, *, mu_high: float = 100.0) -> float:
        """Smallest μ with a finite HCS ratio at this e (bisection on :meth:`hcs_rotational_ratio`, to 10⁻³).

        Below it :meth:`hcs_rotational_ratio` returns ``inf`` (the drift stays positive to r = 10³); used to
        state the valid range in error messages.  ``mu_high`` if even that has no finite ratio.
        """
        low, high = 0.0, float(mu_high)
        if math.isinf(self.hcs_rotational_ratio(e, high)):
            return high
        while high - low > 1e-3:
            mid = 0.5 * (low + high)
            low, high = (mid, high) if math.isinf(self.hcs_rotational_ratio(e, mid)) else (low, mid)
        return high

    def check(self, e: Any, mu: Any) -> None:
        """Raise :class:`~ktgf.errors.InputError` for μ < 0."""
        check_friction_coefficient(mu)


RESTITUTION_LAWS: dict[str, type[FrictionPart]] = {
    cls.key: cls for cls in (ChialvoSundaresanRestitution, RoughSphereRestitution, WaltonRestitution)
}
