"""The cases of the 3D solver are objects found by name (ktgf.solver.cases): the config, the run and the
CLI ask the case, so a case registered here, in one class, is validated, run and written without an
edit to the numerics; a boundary that does not fit its case is one line naming the field (exit 2)."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import ktgf
from ktgf.errors import InputError
from ktgf.solver.cases import CASES, Case, get_case, register
from ktgf.solver.config import parse_config
from ktgf.solver.outdir import run_files

pytestmark = pytest.mark.contract

SOLVER = Path(__file__).resolve().parents[2] / "src" / "ktgf" / "solver"
KINDS = ("cooling", "uniform-shear", "couette", "chute")
BASE = ('[initial]\nsolid_fraction = 0.2\ntemperature = 1e-4\n[grid]\ncells = [8, 8]\nlength_d = 5.0\n'
        '[time]\nend = 1.0\nunit = "s"\n[output]\nvtk = false\npng = false\n')
WALLS = 'walls = { type = "johnson-jackson", specularity = 0.1 }'


def test_every_case_is_registered_under_its_config_name() -> None:
    assert tuple(CASES) == KINDS
    for kind in KINDS:
        case = get_case(kind)
        assert isinstance(case, Case) and case.name == kind and case.timeseries == f"{kind}.nc"
    with pytest.raises(InputError, match=r"field case\.kind: Input should be 'cooling', 'uniform-shear', 'couette' "
                                         r"or 'chute' \(got 'box'\)"):
        parse_config(tomllib.loads(BASE + '[case]\nkind = "box"\n'))


def test_the_numerics_never_compare_a_case_name() -> None:
    """No ``==``/``!=``/``in`` against a case's name in solver/ outside solver/cases/, nor in ``ktgf run``."""
    hits = []
    for path in [*SOLVER.glob("*.py"), SOLVER.parent / "cli" / "solver.py"]:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Compare):
                consts = [c for c in ast.walk(node) if isinstance(c, ast.Constant) and c.value in KINDS]
                hits += [f"{path.name}:{node.lineno}" for _ in consts[:1]]
    assert hits == []


MISFITS = [  # (case and boundaries, the field the one-line error names)
    ('[case]\nkind = "cooling"\n[boundaries]\ny = { kind = "lees-edwards", shear_rate = 5.0, flow = "x" }',
     "field boundaries.y.kind = 'lees-edwards' needs case.kind = 'uniform-shear' or 'couette'"),
    ('[case]\nkind = "uniform-shear"\n[boundaries]\ny = { kind = "wall", flow = "x", wall_speed = 1.0, ' + WALLS + " }",
     "field case.kind = 'uniform-shear' needs one boundaries.<axis> with kind = 'lees-edwards'"),
    ('[case]\nkind = "couette"\n[boundaries]\ny = { kind = "lees-edwards", shear_rate = 5.0, flow = "x" }',
     "field case.kind = 'couette' needs one boundaries.<axis> with kind = 'wall'"),
    ('[case]\nkind = "couette"\n[boundaries]\ny = { kind = "wall", flow = "x", wall_speed = 0.0, ' + WALLS + " }",
     "field boundaries.y.wall_speed = 0 is out of range: valid wall_speed > 0 m/s"),
    ('[case]\nkind = "chute"\ninclination_deg = 20.0\n[boundaries]\nx = { kind = "wall", flow = "y", wall_speed = 1.0, '
     + WALLS + " }", "field boundaries.x.wall_speed = 1 is out of range: valid wall_speed = 0 for a chute"),
    ('[case]\nkind = "couette"\ninclination_deg = 20.0\n[boundaries]\ny = { kind = "wall", flow = "x", wall_speed = 1.0, '
     + WALLS + " }", "field case.inclination_deg applies to case.kind = 'chute' only"),
]


@pytest.mark.parametrize(("text", "message"), MISFITS)
def test_a_boundary_that_does_not_fit_the_case_is_one_line_naming_the_field(text: str, message: str) -> None:
    with pytest.raises(InputError) as exc:
        parse_config(tomllib.loads(BASE + text))
    assert message in str(exc.value) and "\n" not in str(exc.value), str(exc.value)


def test_ktgf_run_exits_2_on_a_misfitted_boundary(tmp_path: Path) -> None:
    text, message = MISFITS[0]
    (tmp_path / "bad.toml").write_text(BASE + text)
    env = {**os.environ, "PYTHONPATH": str(Path(ktgf.__file__).parents[1])}  # this ktgf, from any folder
    res = subprocess.run([sys.executable, "-m", "ktgf", "run", "bad.toml", "--no-progress"], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300, check=False)
    lines = res.stderr.strip().splitlines()
    assert res.returncode == 2 and len(lines) == 1 and message in lines[0], res.stderr
    assert not (tmp_path / "ktgf-run").exists()


class DriftBox(Case):
    """A case written in the test only: a periodic box (no Haff clock) recording its mass, which refuses
    an amplitude above 0.1 (its own config check)."""

    name, label = "drift-box", "drift box"
    columns, units = ("mass_per_area",), {"mass_per_area": "kg m-2"}

    def check(self, cfg, source, shear, wall) -> None:
        if cfg.initial.amplitude > 0.1:
            raise InputError(f"{source}: field initial.amplitude = {cfg.initial.amplitude:g} is out of range for a "
                             "drift box: valid <= 0.1")

    def diagnostics(self, U, t, grid, phys) -> dict:
        return {"mass_per_area": float(np.sum(np.asarray(U[0])) * np.prod(grid.spacing))}


@pytest.fixture
def drift_box():
    register(DriftBox)
    yield CASES["drift-box"]
    del CASES["drift-box"]


def test_a_case_registered_in_one_class_is_validated_run_and_written(drift_box: Case, tmp_path: Path) -> None:
    from ktgf.solver.run import Simulation

    data = {**tomllib.loads(BASE + '[case]\nkind = "drift-box"\n'), "time": {"end": 0.02, "unit": "s", "outputs": 2}}
    with pytest.raises(InputError, match=r"field initial\.amplitude = 0\.2 .*drift box"):
        parse_config({**data, "initial": {**data["initial"], "amplitude": 0.2}})
    with pytest.raises(InputError, match="time.unit = 'tau' is for the cooling case"):  # a shared check: not hcs
        parse_config({**data, "time": {**data["time"], "unit": "tau"}})
    sim = Simulation(parse_config(data), directory=tmp_path / "run")
    assert sim.case is drift_box and not sim.phys.hcs
    sim.run(progress=False)
    ds = xr.load_dataset(tmp_path / "run" / "drift-box.nc")
    mass = ds["mass_per_area"].values
    assert ds["mass_per_area"].attrs["units"] == "kg m-2" and len(mass) == 3
    np.testing.assert_allclose(mass, mass[0], rtol=1e-12)  # the periodic box conserves its mass
    assert run_files(tmp_path / "run")[-1].name == "drift-box.nc"


@pytest.mark.parametrize("kind", KINDS)
def test_each_case_writes_its_own_time_series_and_an_earlier_one_guards_the_folder(kind: str, tmp_path: Path) -> None:
    """The file is named for the case, and a folder holding any case's time series belongs to a run."""
    assert get_case(kind).timeseries == f"{kind}.nc"
    (tmp_path / get_case(kind).timeseries).write_bytes(b"")
    (tmp_path / "notes.nc").write_bytes(b"")  # not a run's file: --overwrite leaves it
    assert [p.name for p in run_files(tmp_path)] == [f"{kind}.nc"]
