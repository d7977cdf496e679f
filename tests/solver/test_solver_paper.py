"""The paper's third-dimension test (model.md §9): a cooling gas in a periodic box stays
homogeneous below the critical size and grows vortices, then clusters, above it.

L⊥ and L∥ come from the linear stability analysis (ktgf.hcs.stability, model.md §8) of each
model at (φ, e) = (0.5, 0.7), where RET and the Proposed model differ (φ > φ_f = 0.49).
Seeded random velocity and density perturbations of the lowest Fourier modes, amplitude
3·10⁻⁴, integrated to τ = 16 with the IMEX scheme (CI: 2D, 16² cells, float64; full size: 3D in mixed
precision — float32 state, float64 Krylov scalars; same verdicts and ratios as float64 — marked
slow, at about one mean free path ℓ per cell — below ℓ Navier–Stokes hydrodynamics has no
meaning, above it the modes near the critical size are under-resolved: 16³ for 0.7 L⊥
(Δx = 0.96 ℓ), 32³ for 1.5 L⊥ (1.03 ℓ) and 1.3 L∥ (1.53 ℓ RET, 1.33 ℓ Proposed; 48³ would
cost 3.4× more)):

* L = 0.7 L⊥: transverse kinetic energy / θ and density variance both decay;
* L = 1.5 L⊥: vortices grow (K⊥/θ up by orders of magnitude), clusters do not (L < L∥);
* L = 1.3 L∥: clusters grow (density variance up).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_dense_paper import CASES, run_case, verdict  # noqa: E402 - the one definition of the runs and verdicts


def _check(model: str, dim: int, precision: str) -> None:
    for relative_to, factor, n in CASES:
        r = run_case(model, relative_to, factor, [16] * 2 if dim == 2 else [n] * 3, precision=precision)
        print(f"{model} {r['box']} {r['cells']}: dx = {r['dx_mfp']:.2f} mean free paths, {r['steps']} steps, "
              f"{r['wall_s']:.1f} s wall, {r['cpu_s']:.1f} s CPU, binding {r['binding']}; "
              f"K_perp/theta ratio {r['kperp_ratio']:.3g}, density variance ratio {r['var_ratio']:.3g}")
        assert r["verdict"] == "pass", (r["box"], r["verdict"], r["kperp_ratio"], r["var_ratio"])


@pytest.mark.contract
def test_verdicts_are_the_papers() -> None:
    """The three verdicts: decay below L⊥; vortices without clusters between L⊥ and L∥; clusters above L∥."""
    assert verdict("transverse", 0.7, 1e-10, 1e-10) == "pass"
    assert verdict("transverse", 0.7, 1e-10, 1e-2) != "pass"  # a density variance that did not decay
    assert verdict("transverse", 1.5, 1e4, 0.01) == "pass"
    assert verdict("transverse", 1.5, 1e4, 2.0) != "pass"  # clusters below L_par
    assert verdict("transverse", 1.5, 10.0, 0.01) != "pass"  # no vortices above L_perp
    assert verdict("longitudinal", 1.3, 1e6, 8.0) == "pass"
    assert verdict("longitudinal", 1.3, 1e6, 1.0) != "pass"


@pytest.mark.analytic
@pytest.mark.parametrize("model", ["ret", "proposed"])
def test_critical_box_sizes_2d(model: str) -> None:
    _check(model, 2, "float64")


@pytest.mark.analytic
@pytest.mark.slow  # mixed precision: 5.2 min for both models under load 5-7 (docs/solver.md, "Dense paper test timing")
@pytest.mark.parametrize("model", ["ret", "proposed"])
def test_critical_box_sizes_3d(model: str) -> None:
    _check(model, 3, "mixed")
