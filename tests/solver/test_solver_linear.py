"""The solver against the linear stability theory of the HCS (model.md §8; ktgf.hcs.stability).

A single Fourier eigenmode of the linearised equations is put on the HCS with a tiny
amplitude; its complex amplitude, projected on the eigenvector, is fitted against the
collision time τ = ∫ν0 dt of Haff's law.  In the co-cooling variables (ρ_k, θ_k/θ_H,
w = δu/√(2θ_H)) the linear rates are constant, so log(amplitude) must be a straight line in τ
whose slope is the eigenvalue of −M (longitudinal) or s⊥ (transverse).  The oracle is the
eigenvalue problem, computed outside the solver.  Tolerance 2 % of |s| on a resolved grid.
The default IMEX scheme is used throughout; one case repeats on a fine grid where its step is
many times the explicit diffusive limit, and one with SSP-RK3.
"""

from __future__ import annotations

import pytest
from helpers.growth import measure_rate

pytestmark = pytest.mark.analytic


@pytest.mark.parametrize(
    "kind, kstar, branch",
    [
        ("transverse", 0.2, 0),     # vortex mode, unstable (k* < k⊥* = 0.349)
        ("transverse", 0.5, 0),     # vortex mode, damped
        ("longitudinal", 0.1, 0),   # heat (cluster) mode, unstable (k* < k∥* = 0.185)
        ("longitudinal", 0.1, 1),   # sound mode: complex rate (damped oscillation)
        ("longitudinal", 0.3, 0),   # heat mode, damped
    ],
)
def test_growth_rates_1d(kind: str, kstar: float, branch: int) -> None:
    measured, theory = measure_rate("ret", (64,), (1,), kstar, kind, branch)
    print(f"relative error {abs(measured - theory) / abs(theory):.4f}", measured, theory)
    assert abs(measured - theory) <= 0.02 * abs(theory), (measured, theory)


@pytest.mark.parametrize("kind, branch", [("transverse", 0), ("longitudinal", 1)])
def test_growth_rates_2d_oblique(kind: str, branch: int) -> None:
    """A mode along the diagonal of a 2D box: the same rates as in 1D (isotropy of the scheme)."""
    measured, theory = measure_rate("proposed", (32, 32), (1, 1), 0.15, kind, branch, tau_end=12.0)
    print(f"relative error {abs(measured - theory) / abs(theory):.4f}", measured, theory)
    assert abs(measured - theory) <= 0.02 * abs(theory), (measured, theory)


@pytest.mark.parametrize("kind, kstar, branch", [("transverse", 0.2, 0), ("longitudinal", 0.1, 1)])
def test_growth_rates_with_steps_far_beyond_the_diffusive_limit(kind: str, kstar: float, branch: int) -> None:
    """512 cells per wavelength (Δx ≈ 0.06 ℓ): the IMEX step is ~20× the explicit diffusive limit."""
    measured, theory = measure_rate("ret", (512,), (1,), kstar, kind, branch)
    print(f"relative error {abs(measured - theory) / abs(theory):.4f}", measured, theory)
    assert abs(measured - theory) <= 0.02 * abs(theory), (measured, theory)


def test_growth_rate_explicit_scheme() -> None:
    measured, theory = measure_rate("ret", (64,), (1,), 0.2, "transverse", scheme="ssprk3")
    print(f"relative error {abs(measured - theory) / abs(theory):.4f}", measured, theory)
    assert abs(measured - theory) <= 0.02 * abs(theory), (measured, theory)
