"""The command-line cases of issue 11: each ends in a one-line error with exit code 2 (or strict
JSON), never a traceback."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.errors import InputError

ROOT = Path(__file__).resolve().parents[2]


pytestmark = pytest.mark.contract


def _refused(args: list[str], *words: str) -> None:
    res = CliRunner().invoke(app, args)
    assert res.exception is None or isinstance(res.exception, SystemExit), repr(res.exception)
    assert res.exit_code == 2, res.output
    err = res.stderr.strip()
    assert len(err.splitlines()) == 1 and err.startswith("Error: "), err
    for w in words:
        assert w in err, err


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("files")
    res = CliRunner().invoke(app, ["hcs", "map", "-o", str(d / "map.nc"), "--n-phi", "3", "--n-e", "2",
                                   "--model", "ret"])
    assert res.exit_code == 0, res.output
    (d / "empty.nc").write_bytes(b"")
    return {"map": d / "map.nc", "empty": d / "empty.nc", "toml": ROOT / "examples" / "hcs_3d.toml", "dir": d}


def test_wrong_kinds_of_files_for_plot(files: dict[str, Path], tmp_path: Path) -> None:
    _refused(["plot", "run", str(files["map"]), "-o", str(tmp_path / "a.png")], "not a time series", "lacks")
    _refused(["plot", "run", str(files["toml"])], "not a readable netCDF file")
    _refused(["plot", "run", str(files["empty"])], "not a readable netCDF file")
    _refused(["plot", "run", str(files["dir"])], "directory")
    _refused(["plot", "couette", str(files["map"])], "not a Couette profile")
    _refused(["plot", "stability-map", "--from", str(files["empty"]), "-o", str(tmp_path / "m.png")], "netCDF")


def test_figure_extension_is_checked(files: dict[str, Path], tmp_path: Path) -> None:
    _refused(["plot", "dispersion", "--phi", "0.3", "--e", "0.9", "--out", str(tmp_path / "x.txt")], ".txt")
    _refused(["plot", "coefficients", "--out", str(tmp_path / "x.txt")], ".txt")
    assert not list(tmp_path.iterdir())  # nothing half-written


@pytest.mark.parametrize("args, words", [
    (["hcs", "stability", "-m", "ret", "--phi", "0.3", "--e", "0.9", "--box", "1e-300"], ["--box = 1e-300", "1 <= --box"]),
    (["hcs", "stability", "-m", "ret", "--phi", "1e-9", "--e", "0.9", "--box", "2"], ["k_box*"]),
    (["hcs", "stability", "-m", "ret", "--phi", "", "--e", "0.9"], ["--phi ''", "gives no value"]),
    (["hcs", "stability", "-m", "ret", "--phi", ",", "--e", "0.9"], ["gives no value"]),
    (["hcs", "stability", "-m", ",", "--phi", "0.3", "--e", "0.9"], ["--model ','", "names nothing"]),
    (["hcs", "stability", "-m", "ret", "--phi", "0:0.5:100000000000", "--e", "0.9"], ["1e+11 points", "800 GB"]),
    (["hcs", "stability", "-m", "ret", "--phi", "0.1:0.5:5000", "--e", "0.1:1:5000"], ["2.5e+07 points"]),
    (["hcs", "stability", "-m", "ret", "--phi", "nan", "--e", "0.9"], ["non-finite"]),
    (["hcs", "map", "-o", "m.nc", "--n-phi", "100000", "--n-e", "100000"], ["1e+10 points", "80 GB"]),
    (["hcs", "haff", "--phi", "0.3", "--e", "0.9", "--theta0", "1", "--d", "1e-3", "--n", "1000000000"], ["1e+09 points"]),
    (["hcs", "haff", "--phi", "0.3", "--e", "0.9", "--theta0", "1e122", "--d", "1e-3"], ["theta = 1e+122"]),
    (["hcs", "haff", "--phi", "5e-324", "--e", "0.5", "--theta0", "1", "--d", "1"], ["phi = 4.94066e-324"]),
    (["coefficients", "-m", "ret", "--phi", "5e-324", "--e", "0.5"], ["phi = 4.94066e-324", "1e-10"]),
    (["coefficients", "-m", "ret", "--phi", "", "--e", "0.9"], ["gives no value"]),
    (["couette", "compare", "--models", ","], ["--models ','", "names nothing"]),
    (["plot", "dispersion", "--phi", "0.3", "--e", "0.9", "--k-max", "1e300"], ["k-max = 1e+300"]),
])
def test_bad_options_give_one_line(args: list[str], words: list[str], tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    _refused(args, *words)


def test_unreachable_dask_scheduler(tmp_path: Path) -> None:
    _refused(["hcs", "map", "-o", str(tmp_path / "m.nc"), "--n-phi", "2", "--n-e", "2", "--model", "ret",
              "--dask", "tcp://127.0.0.1:1"], "Dask scheduler 'tcp://127.0.0.1:1' is unreachable")


def test_grid_too_large_for_the_machine_is_refused_with_an_estimate(tmp_path: Path) -> None:
    text = (ROOT / "examples" / "hcs_3d.toml").read_text().replace("cells = [32, 32, 32]", "cells = [4096, 4096, 4096]")
    (tmp_path / "big.toml").write_text(text)
    _refused(["run", str(tmp_path / "big.toml"), "-o", str(tmp_path / "out")], "needs about 55 TB", "this machine has")
    assert not (tmp_path / "out" / "checkpoint.npz").exists()


def test_json_is_strict() -> None:
    res = CliRunner().invoke(app, ["hcs", "stability", "-m", "ret", "--phi", "0.3", "--e", "1", "--format", "json"])
    assert res.exit_code == 0
    assert "Infinity" not in res.stdout and "NaN" not in res.stdout

    def reject(name: str):
        raise AssertionError(name)

    rows = json.loads(res.stdout, parse_constant=reject)
    assert rows[0]["L_perp/d"] == "inf" and rows[0]["k_perp*"] == 0.0


def test_emit_writes_null_for_nan_and_strings_for_infinities(capsys) -> None:
    import numpy as np

    from ktgf.cli._common import OutputFormat, emit

    emit([{"a": float("nan"), "b": np.float64("-inf"), "c": np.inf, "d": 1.5, "e": np.array([1.0, np.nan])}],
         OutputFormat.json)
    assert json.loads(capsys.readouterr().out) == [{"a": None, "b": "-inf", "c": "inf", "d": 1.5, "e": [1.0, None]}]


@pytest.mark.parametrize("phi", [None, "0.3", True, [], object()])
def test_public_coefficients_refuse_non_numbers(phi) -> None:
    from ktgf.closures import get_model

    with pytest.raises(InputError, match="phi"):
        get_model("ret").coefficients(phi, 0.9, 1.0, d=1e-3, rho_s=2500.0)
