"""Linear stability of the homogeneous cooling state (model.md §8).

Perturbations about the HCS are written as ρ_k = δn/n, θ_k = δθ/θ_H(t), w_k = δu/√(2θ_H)
in the time τ = ∫ν0 dt and wavenumber k* = kℓ, ℓ = 5√(2π)d/(96φ).  In these variables the
problem is autonomous and every coefficient is a reduced one (:class:`~ktgf.closures.Reduced`).

Transverse (vortex, shear) modes:   s⊥ = ζ0*/2 − η*k*²/2
Longitudinal modes:                 dy/dτ = −M y,  y = (ρ_k, θ_k, w∥)

    M = [[ 0,                      0,                        i k*                   ],
         [ ζ0* g + (5/4) μ* k*²,   ζ0*/2 + (5/4) κ* k*²,     i k* ((2/3) p* + ζ_U)  ],
         [ (i k*/2) C,             (i k*/2) p*,              ((2/3)η* + λ_b*/2) k*² − ζ0*/2 ]]

The growth rates are the eigenvalues of −M.  det M = −k*²(A p* − B C)/2 vanishes at

    k⊥*² = ζ0*/η*,      k∥*² = (2/5) ζ0* (2 g p* − C)/(κ* C − μ* p*)

and a periodic cube of side L is stable to a mode while 2π/L > k_c, i.e. L/d < 0.8202922/(φ k*).
References: Brey, Ruiz-Montero & Cubero, PRE 54, 3664 (1996); Garzó, PRE 72, 021106 (2005).
"""

from __future__ import annotations

import math
from typing import Any

from .._array import namespace
from ..closures.coefficients import MEAN_FREE_PATH_CONSTANT, Reduced

#: L/d = BOX_CONSTANT/(φ k*): 2π ℓφ/d = 2π·5√(2π)/96.
BOX_CONSTANT = 2.0 * math.pi * MEAN_FREE_PATH_CONSTANT


def transverse_growth_rate(r: Reduced, kstar: Any) -> Any:
    """Growth rate s⊥(k*) = ζ0*/2 − η*k*²/2 of the transverse (vortex) mode, in units of ν0."""
    return 0.5 * (r.zeta0 - r.eta * kstar**2)


def longitudinal_matrix(r: Reduced, kstar: Any) -> Any:
    """The 3×3 longitudinal matrix M(k*) (shape ``(..., 3, 3)``, complex); dy/dτ = −M y."""
    xp = namespace(r.p, kstar)
    # Broadcast every coefficient to the full (state × k*) shape so the matrix can be stacked.
    p, eta, lam, kap, mu, z0, zu, g, big_c, k = xp.broadcast_arrays(
        *(xp.asarray(v, dtype=float) for v in (r.p, r.eta, r.lambda_b, r.kappa, r.mu, r.zeta0, r.zeta_u, r.g, r.C, kstar))
    )
    zero = 0.0 * k
    ik = 1j * k
    rows = [
        [zero + 0j, zero + 0j, ik],
        [z0 * g + 1.25 * mu * k**2 + 0j, 0.5 * z0 + 1.25 * kap * k**2 + 0j, ik * (2.0 / 3.0 * p + zu)],
        [0.5 * ik * big_c, 0.5 * ik * p, ((2.0 / 3.0) * eta + 0.5 * lam) * k**2 - 0.5 * z0 + 0j],
    ]
    return xp.stack([xp.stack(row, axis=-1) for row in rows], axis=-2)


def longitudinal_growth_rates(r: Reduced, kstar: Any) -> Any:
    """Eigenvalues of −M(k*) (shape ``(..., 3)``), sorted by decreasing real part, in units of ν0."""
    xp = namespace(r.p, kstar)
    s = xp.linalg.eigvals(-longitudinal_matrix(r, kstar))
    order = xp.argsort(-s.real, axis=-1)
    return xp.take_along_axis(s, order, axis=-1)


def critical_wavenumbers(r: Reduced) -> tuple[Any, Any]:
    """Closed-form critical reduced wavenumbers (k⊥*, k∥*) (model.md §8).

    Modes with k* below k⊥* (vortex) or k∥* (cluster) grow.  With N = 2gp* − C and
    D = κ*C − μ*p*, det M = (5/8) k*² (D k*² − (2/5) ζ0* N): a longitudinal eigenvalue is zero
    only at k∥*² = (2/5)ζ0* N/D.  At k* → 0 the rates are (ζ0*/2, 0⁻, −ζ0*/2), so

    - N > 0, D > 0 (every paper model except RET/Proposed at e ≲ 0.18): one real eigenvalue
      crosses zero at k∥*, and the modes are stable beyond;
    - N > 0, D ≤ 0: det M never vanishes for k* > 0, the heat mode stays unstable at every
      wavenumber (its rate tends to a positive constant) and k∥* is ``inf`` (L∥ = 0);
    - N ≤ 0 (no paper model: N = 1 + 2φχ'/χ + 2(1 + e)φ²χ' for their p*; possible for a user
      model): not covered here, k∥* is NaN — use :func:`ktgf.hcs.critical.critical_wavenumbers_eig`.

    In the elastic limit ζ0* = 0 both are 0 (every box is stable).
    """
    xp = namespace(r.p)
    k_perp = xp.sqrt(r.zeta0 / r.eta)
    num = 2.0 * r.g * r.p - r.C
    den = r.kappa * r.C - r.mu * r.p
    safe_den = xp.where(den > 0, den, 1.0)
    k2 = 0.4 * r.zeta0 * num / safe_den
    k_par = xp.where(
        num > 0,
        xp.where(den > 0, xp.sqrt(xp.maximum(k2, 0.0)), xp.where(r.zeta0 > 0, xp.inf, 0.0)),
        xp.nan,
    )
    return k_perp, k_par


def critical_box_size(phi: Any, kstar: Any) -> Any:
    """Side of the periodic cube, in particle diameters, whose lowest mode 2π/L is k*: L/d = 0.8202922/(φk*).

    ``inf`` where k* = 0 (no instability at any size), 0 where k* = inf (unstable at every
    size), NaN where k* is NaN.
    """
    xp = namespace(phi, kstar)
    safe = xp.where(kstar > 0, kstar, 1.0)
    return xp.where(kstar > 0, BOX_CONSTANT / (phi * safe), xp.where(kstar == 0, xp.inf, xp.nan))


def box_wavenumber(phi: Any, box: Any) -> Any:
    """Reduced wavenumber k* = 2πℓ/L of the lowest mode of a periodic cube of side ``box`` = L/d.

    The inverse of :func:`critical_box_size`: k* = 0.8202922/(φ L/d).
    """
    return BOX_CONSTANT / (phi * box)
