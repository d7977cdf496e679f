"""Reproduce the rotation figures of docs/friction.md §7 ("Rotation": issue 33's T_rot/T and τ/p gap).

Run from the repository root:  python docs/rotation_check.py        (≈ 20 s, NumPy + SciPy)

Walton's collision rule (μ = 0.5, e = 0.7, β0 = 1, q = 2/5: the shipped frictional DEM's contact) averaged over
Maxwellian translational (T) and rotational (T_rot) velocities, as ``WaltonRestitution`` does, but with the
mean flow of uniform shear kept in the relative contact velocity (our derivation, not a published closure):
particle 2 sits at r1 + d k, so v1 − v2 = c1 − c2 − γ̇ d k_y x̂; both spins are Ω + w with Ω = −(γ̇/2) ẑ (half the
vorticity; the DEM's T_rot = I⟨w'²⟩/3 is the fluctuation about it).  The mean relative contact velocity is then
−d E·k (E the strain rate), of relative size s = γ̇d/√θ = 1/√T; s = 0 is WaltonRestitution.  Monte Carlo over
(c1, c2, w1, w2, k) with collision weight max(g·k, 0), fixed seed; the steady ratio solves ⟨ΔE_rot⟩ = 0 with
ΔE_rot the change of the fluctuating rotational energy.

Printed: (1) per DEM state the measured T_rot/T, Walton's 0.497 and the finite-shear value at the DEM's s;
(2) Walton's translational loss at the DEM's T_rot/T (how much the collisional cooling of translation falls
if rotation is hotter) and what it would do to T and τ/p; (3) the tangential impulse's share of the collisional shear stress, with the constant-β
check against the first-order-in-s result 3η/(2(1 + e)) derived in docs/friction.md §7.1, and what that
share would do to T and τ/p; (4) the part of the tangential impulse's work that heats translation (the rest
is dissipated through rotation), and the fit / leave-one-state-out errors with that share and that part.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from scipy.optimize import brentq

from ktgf.calibration.registry_fits import frictional_states
from ktgf.closures.friction.collisions import WaltonRestitution

Q, E, MU, BETA0 = 0.4, 0.7, 0.5, 1.0
#: μ_Z, k of the registration before the tangential stress (docs/friction.md §6.0), the base of the what-ifs.
PREVIOUS = {"mu_scale": 0.6202, "amplitude_growth": 5.772}
INERTIA = Q / 4.0  # I/(m d²) with q = 4I/(m d²)
N = 300_000


class ShearedWalton:
    """Monte Carlo averages of Walton's rule in uniform shear at s = γ̇d/√θ (m = d = θ = 1)."""

    def __init__(self, mu: float = MU, beta0: float = BETA0, seed: int = 1) -> None:
        rng = np.random.default_rng(seed)
        self.mu, self.beta0 = mu, beta0
        self.c1, self.c2, self.z1, self.z2 = (rng.standard_normal((N, 3)) for _ in range(4))
        k = rng.standard_normal((N, 3))
        self.k = k / np.linalg.norm(k, axis=1)[:, None]

    def _collide(self, r: float, s: float):
        k = self.k
        w1, w2 = self.z1 * np.sqrt(r / INERTIA), self.z2 * np.sqrt(r / INERTIA)
        spin = np.array([0.0, 0.0, -0.5 * s])
        v12 = self.c1 - self.c2
        v12[:, 0] -= s * k[:, 1]
        g = v12 + 0.5 * np.cross(w1 + w2 + 2.0 * spin, k)
        gn = np.einsum("ij,ij->i", g, k)
        weight = np.clip(gn, 0.0, None)
        gt = g - gn[:, None] * k
        rho = np.linalg.norm(gt, axis=1)
        beta = np.minimum(self.beta0, -1.0 + self.mu * (1.0 + E) * (1.0 + 1.0 / Q) * gn / np.maximum(rho, 1e-300))
        eta = Q * (1.0 + beta) / (2.0 * (1.0 + Q))
        jn = -0.5 * (1.0 + E) * gn[:, None] * k  # impulse on particle 1 (m = 1)
        jt = -eta[:, None] * gt
        return w1, w2, weight, jn, jt

    def rotational_change(self, r: float, s: float) -> float:
        """⟨ΔE_rot⟩ of the fluctuating spins per collision."""
        w1, w2, weight, jn, jt = self._collide(r, s)
        dw = 0.5 * np.cross(self.k, jn + jt) / INERTIA
        de = 0.5 * INERTIA * (np.sum((w1 + dw) ** 2 - w1**2, 1) + np.sum((w2 + dw) ** 2 - w2**2, 1))
        return float(np.sum(weight * de) / np.sum(weight))

    def ratio(self, s: float) -> float:
        """Steady T_rot/T: ⟨ΔE_rot⟩ = 0."""
        return brentq(lambda r: self.rotational_change(r, s), 0.05, 5.0, xtol=1e-4)

    def _translational_parts(self, r: float, s: float, normal: bool, per_collision: bool) -> tuple[float, float]:
        """The tangential (``normal``: the normal) impulse's change of the pair's peculiar translational energy,
        and its work against the mean flow, per unit time (``per_collision``: per collision).

        With J = J_n + J_t on particle 1 (m = 1) the pair's peculiar energy changes by J·(c1 − c2) + |J|², whose
        tangential part is J_t·(c1 − c2) + |J_t|² (J_n ⊥ J_t); the mean flow does the work −J_t·m12 on it, m12 =
        −s k_y x̂ the mean part of v1 − v2.  Per unit time: averages of rate × quantity (the collision rate grows
        with s); per collision: the same over the mean rate.
        """
        _, _, weight, jn, jt = self._collide(r, s)
        jt = jn if normal else jt
        c12 = self.c1 - self.c2
        total = np.sum(weight) if per_collision else weight.size
        change = np.sum(weight * (np.einsum("ij,ij->i", jt, c12) + np.sum(jt**2, 1))) / total
        work = np.sum(weight * s * jt[:, 0] * self.k[:, 1]) / total
        return float(change), float(work)

    def translational_fraction(self, s: float, normal: bool = False, per_collision: bool = False) -> float:
        """The part of the tangential impulse's work that heats translation: the change of the tangential
        impulse's translational energy gain from (s = 0, Walton's ratio) to (s, the steady ratio at s), over its
        work against the mean flow at s.  The rest goes to rotation, which, steady, dissipates it.  ``normal``:
        the same for the normal impulse (the rest is then the O(s²) change of the normal loss)."""
        change0, _ = self._translational_parts(self.ratio(0.0), 0.0, normal, per_collision)
        change, work = self._translational_parts(self.ratio(s), s, normal, per_collision)
        return (change - change0) / work

    def tangential_share(self, r: float, s: float) -> float:
        """⟨J_t,x k_y⟩/⟨J_n,x k_y⟩: the tangential impulse's collisional shear stress over the normal impulse's.

        Antithetic in s (the same samples at +s and −s, halved difference): the isotropic part, zero on
        average but noisy, cancels sample by sample.
        """
        ky = self.k[:, 1]
        sums = []
        for sign in (1.0, -1.0):
            _, _, weight, jn, jt = self._collide(r, sign * s)
            sums.append((np.sum(weight * jt[:, 0] * ky), np.sum(weight * jn[:, 0] * ky)))
        return float((sums[0][0] - sums[1][0]) / (sums[0][1] - sums[1][1]))


def main() -> None:
    t0 = time.perf_counter()
    walton = WaltonRestitution(beta0=BETA0, q=Q)
    r0 = walton.rotational_ratio(E, MU)
    mc = ShearedWalton()
    print(f"Walton's Maxwellian T_rot/T (quadrature) {r0:.4f}; this Monte Carlo at s = 0: {mc.ratio(0.0):.4f}\n")
    states = frictional_states()
    print("| φ | DEM T | s = 1/√T | DEM T_rot/T | Walton (err) | finite shear at s (err) "
          "| translational loss/(1 − e²) at DEM T_rot/T (Walton: %.3f) |" % (walton.inelasticity(E, MU) / (1 - E**2)))
    print("|---|---|---|---|---|---|---|")
    for phi, temp, rdem in zip(states["phi"], states["T"], states["Trot_over_T"]):
        s = 1.0 / np.sqrt(temp)
        rs = mc.ratio(s)
        loss = -walton._energy_changes(E, MU, float(rdem))[0] / (1 - E**2)
        print(f"| {phi:.2f} | {temp:.3f} | {s:.2f} | {rdem:.3f} | {r0:.3f} ({100 * (r0 / rdem - 1):+.1f} %) "
              f"| {rs:.3f} ({100 * (rs / rdem - 1):+.1f} %) | {loss:.3f} |")
    print()
    for s in (0.5, 2.2):
        print(f"Walton μ = 0.5: tangential/normal collisional shear impulse at s = {s}: "
              f"{mc.tangential_share(mc.ratio(s), s):.3f}")
    rough = ShearedWalton(mu=1e6)  # always sticks: constant β = β0
    eta = Q * (1.0 + BETA0) / (2.0 * (1.0 + Q))
    print(f"constant β = {BETA0:g} (μ → ∞): {rough.tangential_share(0.5, 0.2):.3f} at s = 0.2 "
          f"against 3η/(2(1 + e)) = {1.5 * eta / (1 + E):.3f}")
    print("\nPart of the impulses' work that heats translation, per unit time (per collision):")
    print("| s | tangential | normal |")
    print("|---|---|---|")
    for s in (0.5, 1.0, 1.5, 2.2):
        cells = [f"{mc.translational_fraction(s, normal):.3f} ({mc.translational_fraction(s, normal, True):.3f})"
                 for normal in (False, True)]
        print(f"| {s} | " + " | ".join(cells) + " |")
    fraction = walton.tangential_work_fraction(E, MU)
    share = walton.tangential_shear_share(E, MU)
    print(f"\nclosed forms (WaltonRestitution): tangential share {share:.4f}, part of its work heating translation "
          f"per unit time as s → 0 {fraction:.4f}")
    states = frictional_states()
    loss = np.array([-walton._energy_changes(E, MU, float(r))[0] for r in states["Trot_over_T"]])
    what_if("ζ0* × (translational loss at the DEM's T_rot/T)/(Walton's)", zeta_factor=loss / walton.inelasticity(E, MU))
    what_if(f"0.6 λ_b* × (1 + {share:.3f}), the tangential share", eta_share=share)
    per_unit_time, per_collision = (mc.translational_fraction(2.2, per_collision=flag) for flag in (False, True))
    for value, part in ((0.0, 1.0), (share, 1.0), (share, fraction), (share, per_unit_time), (share, per_collision)):
        cross_validate(value, part)
    print(f"\n{time.perf_counter() - t0:.1f} s wall")


def what_if(label: str, *, zeta_factor: Any = 1.0, eta_share: float = 0.0) -> None:
    """``frictional`` before the tangential stress (μ_Z, k of :data:`PREVIOUS`) at μ = 0.5 with its ζ0* scaled or its
    Maxwellian collisional viscosity raised.

    Not a closure: a measure of how far (a) a hotter rotation (less translational loss, ``zeta_factor``) or (b) the
    tangential impulse's collisional shear stress, missing from the transport coefficients (0.6 λ_b* raised by
    ``eta_share``; p is unchanged: a tangential impulse has no normal part), could move T and τ/p.  Same closed
    forms as ``ktgf.shear.steady`` (EKT length included), no refit, T_rot/T still Walton's.
    """
    import math

    from ktgf.calibration.registry_fits import family_model, registered_parameters
    from ktgf.shear.steady import SHEAR_PER_ASTAR, steady_shear

    states = frictional_states()
    phi = states["phi"]
    params = {**registered_parameters(), **PREVIOUS}
    model = family_model(mu=MU, **params).with_options(tangential_stress="none")
    today = steady_shear(model, phi, E)
    red = model.reduced(phi, E)
    eta = red.eta + eta_share * 0.6 * red.lambda_b
    a0 = np.sqrt(1.5 * red.zeta0 * zeta_factor / eta)
    lam = model.dissipation.coefficient(phi, E, model.chi(phi))
    k = SHEAR_PER_ASTAR * phi
    a = np.where(lam * k * a0 > 1.0, (a0**2 / (lam * k)) ** (1.0 / 3.0), a0)
    temp = 25.0 * math.pi / (9216.0 * phi**2 * a**2)
    ratio = eta * a / red.p
    print(f"\nwhat if {label} (frictional before the tangential stress, no refit):")
    print("| φ | ζ0 factor | 0.6 λ_b*/η* | T today → what-if | τ/p today → what-if |")
    print("|---|---|---|---|---|")
    factor = np.broadcast_to(zeta_factor, phi.shape)
    for i in range(phi.size):
        print(f"| {phi[i]:.2f} | {factor[i]:.3f} | {0.6 * red.lambda_b[i] / red.eta[i]:.2f} "
              f"| {100 * (today.T[i] / states['T'][i] - 1):+.1f} % → {100 * (temp[i] / states['T'][i] - 1):+.1f} % "
              f"| {100 * (today.tau_over_p[i] / states['tau_over_p'][i] - 1):+.1f} % → "
              f"{100 * (ratio[i] / states['tau_over_p'][i] - 1):+.1f} % |")

def cross_validate(share: float, fraction: float = 1.0) -> None:
    """Fit and leave-one-state-out errors of the family (μ_Z, k refitted, a, b, c held) with 0.6 λ_b* × (1 + share) at μ > 0.

    share = 0 is ``frictional`` before the tangential stress; share and fraction of the closed forms are the registered
    ``frictional`` (its table in docs/friction.md §6.0, by another route: ζ0* scaled instead of the sink); T_rot/T is
    Walton's in all.
    ``fraction``: the part of the extra shear work Δη* a*² that heats translation; the rest is dissipated (through
    rotation), i.e. ζ0* gains (1 − fraction) Δη* a*²/(3/2), which in steady shear is ζ0* × η*/(η* − (1 − fraction) Δη*).
    """
    from dataclasses import dataclass

    import ktgf.calibration.registry_fits as rf
    from ktgf.closures.dissipation import CorrelationLength
    from ktgf.closures.friction.model_slot import Friction
    from ktgf.closures.garzo_dufty1999 import GarzoDufty1999
    from ktgf.closures.jamming import FrictionalPowerLaw
    from ktgf.closures.models import Model

    @dataclass(frozen=True)
    class TangentialShare(GarzoDufty1999):
        share: float = 0.0

        fraction: float = 1.0

        def reduced(self, phi: Any, e: Any, chi: Any, dchi: Any) -> Any:
            red = super().reduced(phi, e, chi, dchi)
            extra = self.share * 0.6 * red.lambda_b
            return red._replace(eta=red.eta + extra,
                                zeta0=red.zeta0 * (red.eta + extra) / (red.eta + self.fraction * extra))

    def family(name: str = "family", *, mu: float = 0.0, a: float, exponent: float, c: float, mu_scale: float = 0.1,
               amplitude_growth: float = 0.0) -> Model:
        rdf = FrictionalPowerLaw(mu=mu, a=a, exponent=exponent, mu_scale=mu_scale, amplitude_growth=amplitude_growth)
        model = Model(name, TangentialShare(share=share, fraction=fraction), rdf, dissipation=CorrelationLength(c=c))
        return model.replace(friction=Friction(mu=mu, restitution="walton", beta0=BETA0))

    original = rf.family_model
    rf.family_model = family  # without the registered tangential stress: this one adds its own
    try:
        params = rf.registered_parameters()
        frictionless = {k: params[k] for k in rf.FRICTIONLESS_PARAMETERS}
        states = rf.frictional_states()
        fit = rf.fit_frictional(frictionless, states)
        loo = rf.leave_one_out(lambda sub: {**frictionless, **rf.fit_frictional(frictionless, sub).values}, states)
    finally:
        rf.family_model = original
    res = np.expm1(fit.residuals)
    pstar_fit, pstar_loo = (1 + res[0]) * (1 + res[1]) - 1, (1 + loo[0]) * (1 + loo[1]) - 1
    trot = WaltonRestitution(beta0=BETA0, q=Q).rotational_ratio(E, MU) / states["Trot_over_T"] - 1
    values = ", ".join(f"{k} = {v:.4g}" for k, v in fit.values.items())
    print(f"\ntangential share {share:.3f}, {fraction:.3f} of its work to translation: refit {values}; "
          "fit / leave-one-state-out errors")
    print("| φ | T | p* | p/(nT) | τ/p | T_rot/T |")
    print("|---|---|---|---|---|---|")
    for i in range(states["phi"].size):
        cells = [(res[0, i], loo[0, i]), (pstar_fit[i], pstar_loo[i]), (res[1, i], loo[1, i]), (res[2, i], loo[2, i])]
        print(f"| {states['phi'][i]:.2f} | " + " | ".join(f"{100 * a:+.1f} / {100 * b:+.1f} %" for a, b in cells)
              + f" | {100 * trot[i]:+.1f} % |")
    means = [np.nanmean(abs(x)) for x in (loo[0], pstar_loo, loo[1], loo[2], trot)]
    print("| mean abs. LOO | " + " | ".join(f"{100 * m:.1f} %" for m in means) + " |")

if __name__ == "__main__":
    main()
