"""The package as a user gets it: a wheel carrying LICENSE and metadata, installable into a fresh venv."""

from __future__ import annotations

import email
import os
import subprocess
import sys
import tomllib
import venv
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


pytestmark = pytest.mark.contract


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    pytest.importorskip("build")
    out = tmp_path_factory.mktemp("wheel")
    proc = subprocess.run([sys.executable, "-m", "build", "--wheel", "--outdir", str(out), str(ROOT)],
                          capture_output=True, text=True, timeout=600)
    if proc.returncode != 0 and "Could not find a version" in proc.stdout + proc.stderr:
        pytest.skip("no package index reachable to fetch the build backend")
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    (whl,) = out.glob("ktgf-*.whl")
    return whl


def test_wheel_carries_license_and_metadata(wheel: Path) -> None:
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        meta_name = next(n for n in names if n.endswith(".dist-info/METADATA"))
        meta = email.message_from_bytes(z.read(meta_name))
        lic = next(n for n in names if n.endswith("/licenses/LICENSE"))
        assert z.read(lic) == (ROOT / "LICENSE").read_bytes()
    assert "ktgf/py.typed" in names
    # the DEM reference files and their README ship inside the package (ktgf.data)
    from ktgf.data import DEM_FILES

    assert {f"ktgf/data/dem/{f}" for f in (*DEM_FILES, "README.md")} <= set(names)
    assert meta["License-Expression"] == "BSD-3-Clause"
    assert meta["License-File"] == "LICENSE"
    assert "BSD" in (ROOT / "LICENSE").read_text().splitlines()[0]
    classifiers = meta.get_all("Classifier")
    assert "Typing :: Typed" in classifiers and "Topic :: Scientific/Engineering :: Physics" in classifiers
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert meta["Version"] == project["version"]
    assert set(meta.get_all("Requires-Dist")) >= set(project["dependencies"])
    # the readme is the long description
    assert "ktgf" in meta.get_payload()


def test_build_requirement_supports_spdx_license() -> None:
    """An SPDX ``license`` string (PEP 639) needs setuptools >= 77."""
    req = tomllib.loads((ROOT / "pyproject.toml").read_text())["build-system"]["requires"]
    (st,) = [r for r in req if r.startswith("setuptools")]
    assert int(st.split(">=")[1].split(".")[0]) >= 77


def test_citation_and_changelog_present() -> None:
    cff = (ROOT / "CITATION.cff").read_text()
    assert "cff-version:" in cff and "BSD-3-Clause" in cff
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert f"version: {version}" in cff
    assert f"## [{version}]" in (ROOT / "CHANGELOG.md").read_text()


@pytest.mark.slow(minutes=1.5)
def test_wheel_installs_into_fresh_venv(wheel: Path, tmp_path: Path) -> None:
    """`pip install ktgf-*.whl` (with its dependencies) in a new venv, then import and run the CLI, and
    ``ktgf reproduce --quick`` outside any checkout: a complete report with every DEM comparison (~3 min)."""
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    py = env_dir / "bin" / "python"
    subprocess.run([str(py), "-m", "pip", "install", "-q", str(wheel)], check=True, timeout=900)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    code = ("import ktgf, ktgf.cli, ktgf.io; from importlib.resources import files; "
            "assert files('ktgf').joinpath('py.typed').is_file(); print(ktgf.__version__, ktgf.get_model('ret').name)")
    out = subprocess.run([str(py), "-c", code], check=True, capture_output=True, text=True, env=env, cwd=tmp_path).stdout
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert out.split() == [version, "ret"]
    cli = subprocess.run([str(env_dir / "bin" / "ktgf"), "--version"], check=True, capture_output=True, text=True, env=env, cwd=tmp_path)
    assert cli.stdout.strip() == f"ktgf {version}"
    # no checkout, no $KTGF_DATA: the report compares with the DEM files shipped in the wheel
    env.pop("KTGF_DATA", None)
    rep = subprocess.run([str(env_dir / "bin" / "ktgf"), "reproduce", "--quick", "--out", str(tmp_path / "report")],
                         capture_output=True, text=True, env=env, cwd=tmp_path, timeout=1800)
    assert rep.returncode == 0, rep.stdout[-2000:] + rep.stderr[-2000:]
    page = (tmp_path / "report" / "index.html").read_text()
    assert "Not available in this build" not in page and "particle simulations are left out" not in page
    assert "shipped with ktgf" in page
    for name in ("dem_hcs_cooling.csv", "dem_uniform_shear.csv", "dem_uniform_shear_friction.csv",
                 "dem_couette_e0.9_phi0.50.csv"):
        assert name in page and f"{name} not found" not in page
