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

import math

import numpy as np
import pytest
from helpers.growth import fit_rate

from ktgf.closures import get_model
from ktgf.closures.coefficients import mean_free_path
from ktgf.solver.diagnostics import fourier_coefficient
from ktgf.solver.grid import Grid
from ktgf.solver.initial import single_mode, t_of_tau
from ktgf.solver.physics import Physics
from ktgf.solver.state import primitive
from ktgf.solver.stepping import Numerics, advance, limits

PHI0, E, D, RHO_S, THETA0 = 0.25, 0.8, 1e-3, 2500.0, 1e-4


pytestmark = pytest.mark.analytic


def measure_rate(model: str, cells: tuple[int, ...], mode: tuple[int, ...], kstar: float, kind: str,
                 branch: int = 0, tau_end: float | None = None, scheme: str = "imex", mixed: bool = False,
                 amplitude: float = 1e-6) -> tuple[complex, complex]:
    """(measured, theoretical) growth rate in units of ν0 of one eigenmode (``mixed``: float32 state,
    ``numerics.precision = "mixed"``)."""
    m = get_model(model)
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max)
    kmode = math.sqrt(sum(n * n for n in mode))
    L = 2.0 * math.pi * kmode * mean_free_path(PHI0, D) / kstar  # |k| = 2π|n|/L gives k*
    grid = Grid(cells, (L,) * len(cells))
    U, s, vec = single_mode(grid, phys, PHI0, THETA0, mode, kind, amplitude, branch)
    if mixed:
        U = U.astype(np.float32)
    khat = np.array(mode + (0,) * (3 - len(mode)), float) / kmode
    perp = np.cross([0.0, 0.0, 1.0], khat)
    taus = np.linspace(0.0, tau_end or min(3.0 / abs(s.real), 30.0), 9)
    t, proj = 0.0, []
    num = Numerics(scheme=scheme, mixed=mixed)
    lim = np.asarray(limits(U, grid, phys, num))
    print(f"{model} {cells} {kind} k*={kstar}: acoustic/diffusive step limit {lim[0] / min(lim[1], lim[2]):.2f}")
    for target in t_of_tau(taus, phys, PHI0, THETA0):
        U, t, _, status, _ = advance(U, t, float(target), 10**6, grid, phys, num)
        assert int(status) == 0
        W = np.asarray(primitive(U.astype(np.float64)))
        th = W[4].mean()
        u_dir = np.tensordot(perp if kind == "transverse" else khat, W[1:4], axes=1)
        y = np.array([
            fourier_coefficient(W[0] / W[0].mean(), grid, mode),
            fourier_coefficient(W[4] / th, grid, mode),
            fourier_coefficient(u_dir / math.sqrt(2.0 * th), grid, mode),
        ])
        proj.append(np.vdot(vec, y) / np.vdot(vec, vec))
    return fit_rate(taus, np.array(proj)), s


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
