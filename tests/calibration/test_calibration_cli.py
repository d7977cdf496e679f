"""``ktgf calibrate`` and model files: written, described, read back by every command that takes --model; bad input exits 2."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from helpers.calibration_synthetic import synthetic_shear
from ktgf import get_model
from ktgf.data import file_hash
from ktgf.cli import app

runner = CliRunner()
ROOT = Path(__file__).resolve().parents[2]
TRUE = {"phi_c": 0.625, "beta": 2.1}


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A model file from `ktgf calibrate` on synthetic data of proposed with φ_c = 0.625, β = 2.1."""
    d = tmp_path_factory.mktemp("cal")
    data = synthetic_shear(d / "shear.csv", get_model("proposed", **TRUE), [0.3, 0.52, 0.55, 0.58, 0.6])
    out = d / "fit.toml"
    r = runner.invoke(app, ["calibrate", "--model", "proposed", "--data", str(data), "--fit", "phi_c,beta", "--out", str(out),
                            "--format", "json"])
    assert r.exit_code == 0, r.output
    return out, data, json.loads(r.stdout)


@pytest.mark.analytic
def test_calibrate_prints_values_errors_correlations_residuals_and_cost(fitted):
    out, data, res = fitted
    assert res["success"] and res["cost"] < 1e-12
    assert {p["parameter"]: p["value"] for p in res["parameters"]} == pytest.approx(TRUE, rel=1e-6)
    assert all("std_error" in p for p in res["parameters"])
    assert [c["parameter"] for c in res["correlation"]] == ["phi_c", "beta"]
    assert len(res["points"]) == 15 and "residual" in res["points"][0]
    assert "residual variance" in res["standard_errors"]


@pytest.mark.contract
def test_model_file_holds_values_and_provenance(fitted):
    out, data, _ = fitted
    f = tomllib.loads(out.read_text())
    assert f["model"]["base"] == "proposed"
    assert f["model"]["options"] == pytest.approx(TRUE, rel=1e-6)
    prov = f["provenance"]
    assert prov["data"][0]["sha256"] == file_hash(data) and prov["ktgf_version"]
    assert prov["cost"] == f["fit"]["cost"] and prov["created"].endswith("Z")


@pytest.mark.contract
def test_models_describes_the_file(fitted):
    out, _, _ = fitted
    r = runner.invoke(app, ["models", "--model-file", str(out), "--format", "json"])
    assert r.exit_code == 0, r.output
    row = json.loads(r.stdout)[0]
    assert row["base"] == "proposed" and "phi_c=0.625" in row["rdf"] and "shear.csv" in row["data"]


@pytest.mark.contract
def test_coefficients_with_model_file_equal_the_model_with_those_options(fitted):
    out, _, _ = fitted
    r = runner.invoke(app, ["coefficients", "--model-file", str(out), "--phi", "0.55,0.6", "--e", "0.9", "--format", "json"])
    assert r.exit_code == 0, r.output
    rows = json.loads(r.stdout)
    ref = get_model("proposed", **TRUE).reduced(np.array([0.55, 0.6]), 0.9)
    np.testing.assert_allclose([row["eta*"] for row in rows], ref.eta, rtol=1e-6)
    assert rows[0]["eta*"] != pytest.approx(float(get_model("proposed").reduced(0.55, 0.9).eta), rel=1e-3)


@pytest.mark.contract
def test_shear_with_model_file_predicts_the_synthetic_data(fitted):
    """`ktgf shear --model-file` reproduces the uniform-shear data the file was fitted on."""
    out, data, _ = fitted
    r = runner.invoke(app, ["shear", "--model-file", str(out), "--phi", "0.55,0.6", "--e", "0.9", "--format", "json"])
    assert r.exit_code == 0, r.output
    rows = json.loads(r.stdout)
    assert {row["model"] for row in rows} == {"proposed-calibrated"}
    from ktgf.shear.steady import steady_shear

    ref = steady_shear(get_model("proposed", **TRUE), np.array([0.55, 0.6]), 0.9)
    np.testing.assert_allclose([row["eta_over_eta0"] for row in rows], ref.eta_over_eta0, rtol=1e-6)
    np.testing.assert_allclose([row["T"] for row in rows], ref.T, rtol=1e-6)


@pytest.mark.contract
def test_hcs_commands_take_the_model_file(fitted, tmp_path):
    out, _, _ = fitted
    r = runner.invoke(app, ["hcs", "stability", "--model-file", str(out), "--phi", "0.55", "--e", "0.9", "--format", "json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)[0]["model"] == "proposed-calibrated"
    r = runner.invoke(app, ["hcs", "haff", "--model", "ret", "--model-file", str(out), "--phi", "0.5", "--e", "0.9",
                            "--theta0", "1e-2", "--d", "1e-3", "--format", "json"])
    assert r.exit_code == 0, r.output
    assert [row["model"] for row in json.loads(r.stdout)] == ["ret", "proposed-calibrated"]
    nc = tmp_path / "map.nc"
    r = runner.invoke(app, ["hcs", "map", "--model", "proposed", "--model-file", str(out), "--n-phi", "5", "--n-e", "2", "-o", str(nc)])
    assert r.exit_code == 0, r.output
    with xr.open_dataset(nc) as ds:
        assert list(ds.model.values) == ["proposed", "proposed-calibrated"]
        a, b = ds.L_par.sel(model="proposed").values, ds.L_par.sel(model="proposed-calibrated").values
        assert not np.allclose(a[-1], b[-1], equal_nan=True)  # different φ_c, β: different sizes in the dense end
    r = runner.invoke(app, ["plot", "dispersion", "--model-file", str(out), "--phi", "0.3", "--e", "0.9", "-o", str(tmp_path / "d.png")])
    assert r.exit_code == 0, r.output


@pytest.mark.contract
def test_couette_run_and_compare_take_the_model_file(fitted, tmp_path):
    out, _, _ = fitted
    nc = tmp_path / "c.nc"
    r = runner.invoke(app, ["couette", "run", str(ROOT / "examples" / "couette_planar.toml"), "--model-file", str(out), "-o", str(nc)])
    assert r.exit_code == 0, r.output
    with xr.open_dataset(nc) as ds:
        assert ds.attrs["model"] == "proposed-calibrated"
        assert "phi_c=0.625" in ds.attrs["rdf"]
    r = runner.invoke(app, ["couette", "compare", str(ROOT / "examples" / "couette_planar.toml"),  
                            "--model-file", str(out), "-o", str(tmp_path / "c.png"), "--format", "json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)[0]["model"] == "proposed-calibrated"


def _model_file(tmp_path, text):
    f = tmp_path / "m.toml"
    f.write_text(text)
    return f


@pytest.mark.contract
@pytest.mark.parametrize("text, field", [
    ('[model]\nbase = "nosuch"\n', "model.base"),
    ('[model]\nbase = "proposed"\nrdf = "nosuch"\n', "model.rdf"),
    ('[model]\nbase = "proposed"\n[model.options]\nzzz = 1.0\n', "model.options.zzz"),
    ('[model]\nbase = "proposed"\n[model.options]\nphi_c = "high"\n', "model.options.phi_c"),
    ('[model]\nbase = "proposed"\ntheory = "lun"\n', "model.theory"),
    ('[model]\nbase = "proposed"\n[walls]\nspecularity = 2.0\n', "walls.specularity"),
    ('[modle]\nbase = "proposed"\n', "modle"),
    ('x = 1\n[model]\nbase = "proposed"\n', "x"),
])
@pytest.mark.parametrize("command", [["models"], ["coefficients", "--phi", "0.3", "--e", "0.9"],
                                     ["hcs", "stability", "--phi", "0.3", "--e", "0.9"]])
def test_bad_model_files_are_one_line_errors_naming_the_field(tmp_path, text, field, command):
    f = _model_file(tmp_path, text)
    r = runner.invoke(app, [*command, "--model-file", str(f)])
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and f"field '{field}'" in lines[0], r.output


@pytest.mark.contract
@pytest.mark.parametrize("extra, match", [
    (["--fit", "phi_c", "--start", "phi_c=0.9"], "phi_c = 0.9 is out of range"),
    (["--fit", "beta", "--start", "beta=-2"], "beta = -2 is out of range"),
    (["--fit", "zzz"], "'zzz' is not a parameter"),
    (["--fit", "beta", "--bounds", "beta=1"], "expected LOW:HIGH"),
])
def test_calibrate_bad_input_exits_2(fitted, tmp_path, extra, match):
    _, data, _ = fitted
    r = runner.invoke(app, ["calibrate", "--model", "proposed", "--data", str(data), "--out", str(tmp_path / "x.toml"), *extra])
    assert r.exit_code == 2, r.output
    assert match in r.output and len(r.output.strip().splitlines()) == 1
    assert not (tmp_path / "x.toml").exists()


@pytest.mark.contract
def test_calibrate_bad_data_file_exits_2(tmp_path):
    f = tmp_path / "bad.csv"
    f.write_text("# units d = m = 1; shear rate gdot = 1\nphi,e,T\n0.3,0.9,1.0\n")
    r = runner.invoke(app, ["calibrate", "--model", "proposed", "--data", str(f), "--fit", "beta", "--out", str(tmp_path / "x.toml")])
    assert r.exit_code == 2 and "missing column(s) dT" in r.output


@pytest.mark.contract
def test_calibrate_from_a_model_file_continues_from_its_values(fitted, tmp_path):
    out, data, _ = fitted
    out2 = tmp_path / "again.toml"
    r = runner.invoke(app, ["calibrate", "--model-file", str(out), "--data", str(data), "--fit", "beta", "--out", str(out2),
                            "--format", "json"])
    assert r.exit_code == 0, r.output
    res = json.loads(r.stdout)
    assert res["parameters"][0]["start"] == pytest.approx(TRUE["beta"], rel=1e-6)
    f = tomllib.loads(out2.read_text())
    assert f["model"]["base"] == "proposed" and f["model"]["options"]["phi_c"] == pytest.approx(TRUE["phi_c"], rel=1e-6)


@pytest.mark.contract
def test_calibrate_that_stops_early_writes_its_best_point_and_exits_1(fitted, tmp_path):
    _, data, _ = fitted
    out = tmp_path / "partial.toml"
    r = runner.invoke(app, ["calibrate", "--model", "proposed", "--data", str(data), "--fit", "phi_c,beta", "--out", str(out),
                            "--max-evaluations", "2"])
    assert r.exit_code == 1
    assert "best point written to" in r.output
    f = tomllib.loads(out.read_text())
    assert f["fit"]["success"] is False and "stopped" in f["fit"]["message"]
    assert "FIT FAILED" in out.read_text().splitlines()[0]


@pytest.mark.contract
def test_plot_coefficients_and_couette_sweep_take_the_model_file(fitted, tmp_path):
    out, _, _ = fitted
    png = tmp_path / "coef.png"
    r = runner.invoke(app, ["plot", "coefficients", "--models", "ret", "--model-file", str(out), "-o", str(png)])
    assert r.exit_code == 0, r.output
    assert png.is_file()
    cfg = tmp_path / "c.toml"
    cfg.write_text((ROOT / "examples" / "couette_planar.toml").read_text().replace("n_cells = 200", "n_cells = 40"))
    args = ["couette", "sweep", str(cfg), "--specularity", "0.1", "--format", "json"]
    plain = json.loads(runner.invoke(app, args).stdout)[0]
    r = runner.invoke(app, [*args, "--model-file", str(out)])
    assert r.exit_code == 0, r.output
    mine = json.loads(r.stdout)[0]
    assert mine["converged"] and mine["wall_shear_stress_Pa"] != pytest.approx(plain["wall_shear_stress_Pa"], rel=1e-3)


@pytest.mark.analytic
def test_couette_calibration_round_trip_walls_through_compare(tmp_path, data_dir):
    """Calibrate φ' and β on synthetic Couette data; `couette compare` with the file then uses its walls and reproduces the data."""
    from helpers.calibration_synthetic import synthetic_couette

    from ktgf.data import read_couette

    case = read_couette(data_dir / "dem_couette_e0.9_phi0.50.csv").case
    data = synthetic_couette(tmp_path / "c.csv", get_model("proposed", beta=2.0), 0.2, case, 60)
    out = tmp_path / "walls.toml"
    r = runner.invoke(app, ["calibrate", "--model", "proposed", "--data", str(data), "--fit", "specularity,beta", "--cells", "60",
                            "--out", str(out), "--format", "json"])
    assert r.exit_code == 0, r.output
    f = tomllib.loads(out.read_text())
    assert f["walls"] == pytest.approx({"specularity": 0.2, "wall_restitution": 0.9}, rel=1e-4)
    r = runner.invoke(app, ["couette", "compare", "--dem", str(data), "--model-file", str(out), "--cells", "60",
                            "-o", str(tmp_path / "c.png"), "--format", "json"])
    assert r.exit_code == 0, r.output
    (row,) = json.loads(r.stdout)
    assert row["specularity"] == pytest.approx(0.2, rel=1e-4)
    assert abs(row["tau_error"]) < 1e-4 and abs(row["p_error"]) < 1e-4
