"""The paper's third-dimension test (model.md §9): a cooling gas in a periodic box stays
homogeneous below the critical size and grows vortices, then clusters, above it.

L⊥ and L∥ come from the linear stability analysis (ktgf.hcs.stability, model.md §8) of each
model at (φ, e) = (0.5, 0.7), where RET and the Proposed model differ (φ > φ_f = 0.49).
Seeded random velocity and density perturbations of the lowest Fourier modes, amplitude
3·10⁻⁴, integrated to τ = 16 (CI: 2D, 16² cells; full size: 3D 32³, marked slow):

* L = 0.7 L⊥: transverse kinetic energy / θ and density variance both decay;
* L = 1.5 L⊥: vortices grow (K⊥/θ up by orders of magnitude), clusters do not (L < L∥);
* L = 1.3 L∥: clusters grow (density variance up).
"""

from __future__ import annotations

import pytest

from ktgf.solver.config import parse_config
from ktgf.solver.run import Simulation


def _run(model: str, relative_to: str, factor: float, cells: list[int]) -> tuple[float, float]:
    cfg = parse_config({
        "model": {"name": model, "restitution": 0.7},
        "initial": {"solid_fraction": 0.5, "temperature": 1e-4, "amplitude": 3e-4, "max_mode": 1, "seed": 3},
        "grid": {"cells": cells, "relative_to": relative_to, "factor": factor},
        "time": {"end": 16.0, "unit": "tau", "outputs": 4},
    })
    ds = Simulation(cfg).run(progress=False, write_files=False)
    kperp = (ds.ke_transverse / ds.theta_mean).values
    var = ds.density_variance.values
    return kperp[-1] / kperp[0], var[-1] / var[0]


def _check(model: str, cells: list[int]) -> None:
    k, v = _run(model, "transverse", 0.7, cells)
    assert k < 1e-3 and v < 1e-3, ("0.7 L_perp should stay homogeneous", k, v)
    k, v = _run(model, "transverse", 1.5, cells)
    assert k > 1e2, ("1.5 L_perp should grow vortices", k)
    assert v < 0.5, ("1.5 L_perp < L_par should not cluster", v)
    k, v = _run(model, "longitudinal", 1.3, cells)
    assert k > 1e2 and v > 5.0, ("1.3 L_par should grow vortices and clusters", k, v)


@pytest.mark.parametrize("model", ["ret", "proposed"])
def test_critical_box_sizes_2d(model: str) -> None:
    _check(model, [16, 16])


@pytest.mark.slow
@pytest.mark.parametrize("model", ["ret", "proposed"])
def test_critical_box_sizes_3d(model: str) -> None:
    _check(model, [32, 32, 32])
