"""The OpenFOAM comparison case (benchmarks/openfoam/, docs/openfoam.md).

Default suite: the case writer puts the config's values into the dictionaries (no OpenFOAM
needed) — box, cells, e, d, ρ_s, the end time from Haff's cooling time, the initial fields cell
by cell in OpenFOAM's order.  Slow and only where ``twoPhaseEulerFoam`` is installed: a tiny
case runs in both codes and both follow Haff's law.
"""

from __future__ import annotations

import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks" / "openfoam"))
import make_case  # noqa: E402

from ktgf.hcs.haff import cooling_time, haff_temperature  # noqa: E402
from ktgf.solver.config import parse_config  # noqa: E402

D, PHI, E, THETA0, SIDE_D, N = 1e-3, 0.1, 0.9, 1e-4, 20.0, 8


def _cfg(**initial):
    return parse_config({
        "model": {"name": "enskog", "restitution": E},
        "particles": {"diameter": D, "density": 2500.0},
        "initial": {"solid_fraction": PHI, "temperature": THETA0, "amplitude": 0.05, "seed": 1, "max_mode": 1, **initial},
        "grid": {"cells": [N] * 3, "length_d": SIDE_D},
        "time": {"end": 0.5, "unit": "haff", "outputs": 5},
    })


def _entry(text: str, key: str) -> str:
    m = re.search(rf"^\s*{re.escape(key)}\s+([^;]+);", text, flags=re.M)
    assert m, key
    return m.group(1).strip()


def _scalar_list(text: str) -> np.ndarray:
    m = re.search(r"nonuniform List<scalar>\s*(\d+)\s*\(\s*(.*?)\)\s*;", text, flags=re.S)
    vals = np.array(m.group(2).split(), float)
    assert len(vals) == int(m.group(1))
    return vals


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    out = tmp_path_factory.mktemp("foam")
    info = make_case.write_case(_cfg(), out)
    return out, info


@pytest.mark.contract
def test_dictionaries_hold_the_config(case) -> None:
    root, info = case
    read = lambda rel: (root / rel).read_text()  # noqa: E731
    t0 = float(cooling_time("enskog", PHI, E, THETA0, d=D))
    assert float(_entry(read("system/controlDict"), "endTime")) == pytest.approx(0.5 * t0, rel=1e-9)
    kt = read("constant/turbulenceProperties.particles")
    assert float(_entry(kt, "e")) == E
    assert (_entry(kt, "RASModel"), _entry(kt, "radialModel"), _entry(kt, "granularPressureModel")) == (
        "kineticTheory", "CarnahanStarling", "Lun")
    assert float(_entry(kt, "alphaMinFriction")) > 0.6  # no frictional stress in a φ = 0.1 box
    phase = read("constant/phaseProperties")
    assert float(re.search(r"constantCoeffs \{ d ([^;]+);", phase).group(1)) == D
    solid = read("constant/thermophysicalProperties.particles")
    assert float(_entry(solid, "rho")) == 2500.0 and _entry(solid, "equationOfState") == "rhoConst"
    assert float(_entry(read("constant/thermophysicalProperties.air"), "mu")) == make_case.GAS["mu"]
    assert "value           (0 0 0)" in read("constant/g")
    mesh = read("system/blockMeshDict")
    assert f"({N} {N} {N})" in mesh and mesh.count("type cyclic;") == 6
    corners = np.array(re.findall(r"^\s*\(([-\d.e]+) ([-\d.e]+) ([-\d.e]+)\)", mesh, flags=re.M), float)
    assert corners.max() == pytest.approx(SIDE_D * D, rel=1e-12)
    for name in ("U.particles", "U.air", "Theta.particles", "p", "p_rgh", "T.air", "alpha.air"):
        assert read(f"0/{name}").count("type            cyclic;") == 6, name
    # the drag is far too weak to cool the gas: its dissipation over the collisional one at θ0
    assert info["drag_over_collisional_dissipation"] < 1e-4


@pytest.mark.contract
def test_initial_fields_are_the_ktgf_seed(case) -> None:
    """φ: mean φ0 (mass) and rms perturbation = amplitude (ktgf's definition of the random seed);
    θ uniform θ0; the velocity has rms ≈ amplitude·√θ0 per component."""
    root, _ = case
    alpha = _scalar_list((root / "0/alpha.particles").read_text())
    assert alpha.size == N**3
    assert alpha.mean() == pytest.approx(PHI, rel=1e-12)
    assert np.sqrt(np.mean((alpha / PHI - 1) ** 2)) == pytest.approx(0.05, rel=1e-9)
    air = _scalar_list((root / "0/alpha.air").read_text())
    assert np.allclose(alpha + air, 1.0, atol=1e-12)
    theta = _scalar_list((root / "0/Theta.particles").read_text())
    assert np.allclose(theta, THETA0, rtol=1e-12)
    u = np.array(re.findall(r"^\(([-\d.e]+) ([-\d.e]+) ([-\d.e]+)\)$", (root / "0/U.particles").read_text(), flags=re.M), float)
    assert u.shape == (N**3, 3)
    assert np.allclose(np.sqrt(np.mean(u**2, axis=0)), 0.05 * np.sqrt(THETA0), rtol=0.1)


@pytest.mark.contract
@pytest.mark.parametrize("axis", [0, 2])
def test_cell_order_is_openfoams(tmp_path, axis: int) -> None:
    """A longitudinal HCS mode along x (or z) varies with the fastest (or slowest) OpenFOAM cell index only."""
    mode = [0, 0, 0]
    mode[axis] = 1
    make_case.write_case(_cfg(perturbation="mode", kind="longitudinal", mode=mode, amplitude=0.01), tmp_path)
    alpha = _scalar_list((tmp_path / "0/alpha.particles").read_text()).reshape(N, N, N)  # [k, j, i]
    along = 2 - axis  # x is the last (fastest) index
    spread = alpha.std(axis=along).max()
    across = max(alpha.std(axis=a).max() for a in range(3) if a != along)
    assert spread > 1e-4 * PHI and across < 1e-12 * PHI, (spread, across)


@pytest.mark.analytic
@pytest.mark.slow
@pytest.mark.skipif(shutil.which("twoPhaseEulerFoam") is None, reason="OpenFOAM twoPhaseEulerFoam is not installed")
def test_tiny_case_runs_in_both_codes_and_follows_haff(tmp_path) -> None:
    import run_compare

    cfg = tmp_path / "tiny.toml"
    cfg.write_text('[model]\nname = "enskog"\nrestitution = 0.9\n[initial]\nsolid_fraction = 0.1\ntemperature = 1e-4\n'
                   'amplitude = 0.05\nseed = 1\nmax_mode = 1\n[grid]\ncells = [8, 8, 8]\nlength_d = 20.0\n'
                   '[time]\nend = 0.3\nunit = "haff"\noutputs = 3\n')
    out = run_compare.main(["--config", str(cfg), "--work", str(tmp_path / "work"), "--segments", "1"])
    th = out["theta"]
    print(th)
    # Haff's law θ0/(1 + t/t0)²: θ(0.3 t0) = 0.59 θ0; both within 1 %
    assert float(haff_temperature(0.3, 1.0, 1.0)) == pytest.approx(1 / 1.69)
    assert th["max_ktgf_haff_dev"] < 0.01 and th["max_openfoam_haff_dev"] < 0.01, th
    assert out["openfoam"]["steps"] > 0 and out["ratio_wall"] > 0
