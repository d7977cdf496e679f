"""The paper's third-dimension test (model.md §9): a cooling gas in a periodic box stays
homogeneous below the critical size and grows vortices, then clusters, above it.

L⊥ and L∥ come from the linear stability analysis (ktgf.hcs.stability, model.md §8) of each
model at (φ, e) = (0.5, 0.7), where RET and the Proposed model differ (φ > φ_f = 0.49).
Seeded random velocity and density perturbations of the lowest Fourier modes, amplitude
3·10⁻⁴, integrated to τ = 16 with the IMEX scheme (CI: 2D, 16² cells; full size: 3D, marked
slow, at about one mean free path ℓ per cell — below ℓ Navier–Stokes hydrodynamics has no
meaning, above it the modes near the critical size are under-resolved: 16³ for 0.7 L⊥
(Δx = 0.96 ℓ), 32³ for 1.5 L⊥ (1.03 ℓ) and 1.3 L∥ (1.53 ℓ RET, 1.33 ℓ Proposed; 48³ would
cost 3.4× more)):

* L = 0.7 L⊥: transverse kinetic energy / θ and density variance both decay;
* L = 1.5 L⊥: vortices grow (K⊥/θ up by orders of magnitude), clusters do not (L < L∥);
* L = 1.3 L∥: clusters grow (density variance up).
"""

from __future__ import annotations

import pytest

import time

from ktgf.closures.coefficients import mean_free_path
from ktgf.solver.config import parse_config
from ktgf.solver.run import Simulation


def _run(model: str, relative_to: str, factor: float, cells: list[int]) -> tuple[float, float]:
    cfg = parse_config({
        "model": {"name": model, "restitution": 0.7},
        "initial": {"solid_fraction": 0.5, "temperature": 1e-4, "amplitude": 3e-4, "max_mode": 1, "seed": 3},
        "grid": {"cells": cells, "relative_to": relative_to, "factor": factor},
        "time": {"end": 16.0, "unit": "tau", "outputs": 4, "scheme": "imex"},
    })
    sim = Simulation(cfg)
    wall = time.perf_counter()
    ds = sim.run(progress=False, write_files=False)
    wall = time.perf_counter() - wall
    dx = sim.grid.spacing[0] / mean_free_path(0.5, sim.phys.diameter)
    print(f"{model} {factor} {relative_to} {cells}: dx = {dx:.2f} mean free paths, {sim.steps} steps, "
          f"{wall:.1f} s wall ({ds.attrs['wall_time_per_step_s'] * 1e3:.1f} ms/step), binding {ds.attrs['binding_step_limit']}")
    kperp = (ds.ke_transverse / ds.theta_mean).values
    var = ds.density_variance.values
    print(f"    K_perp/theta ratio {kperp[-1] / kperp[0]:.3g}, density variance ratio {var[-1] / var[0]:.3g}")
    return kperp[-1] / kperp[0], var[-1] / var[0]


def _check(model: str, cells: tuple[list[int], list[int], list[int]]) -> None:
    k, v = _run(model, "transverse", 0.7, cells[0])
    assert k < 1e-3 and v < 1e-3, ("0.7 L_perp should stay homogeneous", k, v)
    k, v = _run(model, "transverse", 1.5, cells[1])
    assert k > 1e2, ("1.5 L_perp should grow vortices", k)
    assert v < 0.5, ("1.5 L_perp < L_par should not cluster", v)
    k, v = _run(model, "longitudinal", 1.3, cells[2])
    assert k > 1e2 and v > 5.0, ("1.3 L_par should grow vortices and clusters", k, v)


@pytest.mark.parametrize("model", ["ret", "proposed"])
def test_critical_box_sizes_2d(model: str) -> None:
    _check(model, ([16, 16],) * 3)


@pytest.mark.slow
@pytest.mark.parametrize("model", ["ret", "proposed"])
def test_critical_box_sizes_3d(model: str) -> None:
    _check(model, ([16] * 3, [32] * 3, [32] * 3))
