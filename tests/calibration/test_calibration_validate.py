"""``ktgf validate``: one table of a model against every shared DEM file, rows marked fitted or predicted; bad input.

Oracles: the DEM values are read here with the csv module (not ktgf's readers); the fitted/predicted
marks follow what the registered models' docs say they were fitted to, and a model file's provenance.
"""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from ktgf import get_model
from ktgf.calibration.validate import detect_case, fit_sources, validate
from ktgf.cli import app
from ktgf.errors import InputError
from ktgf.shear.steady import steady_shear

pytestmark = pytest.mark.contract

runner = CliRunner()
CELLS = "60"
SHEAR_FILES = ("dem_uniform_shear.csv", "dem_uniform_shear_extra.csv")


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))


def test_cases_recognised_from_the_columns(data_dir):
    assert {f.name: detect_case(f) for f in sorted(data_dir.glob("*.csv"))} == {
        "dem_couette_e0.9_phi0.50.csv": "couette", "dem_hcs_cooling.csv": "homogeneous-cooling",
        "dem_uniform_shear.csv": "uniform-shear", "dem_uniform_shear_extra.csv": "uniform-shear",
        "dem_uniform_shear_friction.csv": "frictional-shear", "dem_uniform_shear_friction_extra.csv": "frictional-shear"}


@pytest.fixture(scope="module")
def dense_table(data_dir):
    r = runner.invoke(app, ["validate", "--model", "dense", "--data", str(data_dir), "--cells", CELLS, "--format", "json"])
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


def test_every_file_and_state_has_rows(dense_table, data_dir):
    rows = dense_table["rows"]
    files = {r["file"] for r in rows}
    assert files == {f.name for f in data_dir.glob("*.csv")}
    for name in (*SHEAR_FILES, "dem_hcs_cooling.csv"):
        states = {r["state"] for r in rows if r["file"] == name}
        assert len(states) == len(_rows(data_dir / name))
    assert {r["quantity"] for r in rows if r["case"] == "couette"} == {"tau_wall", "p_wall"}


def test_dem_columns_and_errors(dense_table, data_dir):
    rows = dense_table["rows"]
    for name in SHEAR_FILES:
        for d in _rows(data_dir / name):
            state = f"phi={float(d['phi']):g} e={float(d['e']):g}"
            got = {r["quantity"]: r for r in rows if r["file"] == name and r["state"] == state}
            for q in ("T", "eta_over_eta0", "p_over_nT"):
                assert got[q]["dem"] == float(d[q]) and got[q]["dem_sigma"] == float(d["d" + q])
                assert got[q]["error"] == pytest.approx(got[q]["model"] / float(d[q]) - 1, rel=1e-12)
            s = steady_shear(get_model("dense"), np.array([float(d["phi"])]), float(d["e"]))
            assert got["eta_over_eta0"]["model"] == pytest.approx(s.eta_over_eta0[0], rel=1e-12)
    fr = {(r["state"], r["quantity"]): r for r in rows if r["file"] == "dem_uniform_shear_friction.csv"}
    d = next(x for x in _rows(data_dir / "dem_uniform_shear_friction.csv") if float(x["mu"]) == 0.5 and float(x["phi"]) == 0.4)
    assert fr[("mu=0.5 phi=0.4 e=0.7", "p_star")]["dem"] == float(d["p_star"])


def test_rows_marked_from_what_dense_was_fitted_to(dense_table):
    """docs/dense.md §3: a, b, c, A of dense fitted on the frictionless uniform shear (base + extra file) and on p/(nT)
    of the cooling states (not their cooling rates): the rest is predicted."""
    for r in dense_table["rows"]:
        fitted = r["file"] in SHEAR_FILES or (r["file"] == "dem_hcs_cooling.csv" and r["quantity"] == "p_over_nT")
        assert r["role"] == ("fitted" if fitted else "predicted"), r
    roles = {(s["case"], s["quantity"], s["role"]) for s in dense_table["summary"]}
    assert ("homogeneous-cooling", "p_over_nT", "fitted") in roles
    assert ("homogeneous-cooling", "A_main", "predicted") in roles
    assert ("uniform-shear", "T", "fitted") in roles and ("frictional-shear", "T", "predicted") in roles


def test_frictional_fitted_on_its_mu_half_rows(data_dir):
    """docs/friction.md §6.0: μ_Z and k fitted on every μ = 0.5 row; the μ = 0, e = 0.7 row is a prediction."""
    files = [data_dir / "dem_uniform_shear_friction.csv", data_dir / "dem_uniform_shear_friction_extra.csv"]
    res = validate(get_model("frictional"), files, sources=fit_sources(model_name="frictional"))
    fitted = {r["state"] for r in res.rows if r["role"] == "fitted"}
    want = {f"mu=0.5 phi={x['phi']} e=0.7" for f in files for x in _rows(f) if float(x["mu"]) == 0.5}
    assert len(want) == 7 and fitted == want
    assert {r["state"] for r in res.rows if r["role"] == "predicted"} == {"mu=0 phi=0.5 e=0.7"}


def test_model_file_provenance_marks_its_fit_data(data_dir, tmp_path):
    out = tmp_path / "m.toml"
    r = runner.invoke(app, ["calibrate", "--model", "dense", "--data", str(data_dir / "dem_uniform_shear_extra.csv"),
                            "--fit", "exponent", "--out", str(out)])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["validate", "--model-file", str(out), "--data", str(data_dir / SHEAR_FILES[0]),
                            "--data", str(data_dir / SHEAR_FILES[1]), "--format", "csv"])
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader(r.stdout.split("\n\n")[0].splitlines()))
    assert {row["role"] for row in rows if row["file"] == SHEAR_FILES[1]} == {"fitted"}
    assert {row["role"] for row in rows if row["file"] == SHEAR_FILES[0]} == {"predicted"}
    # the same file under another name with other bytes is not the fit data
    other = tmp_path / SHEAR_FILES[1]
    other.write_text((data_dir / SHEAR_FILES[1]).read_text().replace("0.92376", "0.92377"))
    r = runner.invoke(app, ["validate", "--model-file", str(out), "--data", str(other), "--format", "json"])
    assert {row["role"] for row in json.loads(r.stdout)["rows"]} == {"predicted"}


def test_markdown_and_table_formats(data_dir):
    r = runner.invoke(app, ["validate", "--model", "dense", "--data", str(data_dir / "dem_hcs_cooling.csv"), "--format", "markdown"])
    assert r.exit_code == 0, r.output
    assert r.stdout.startswith("| file | case | state | quantity | model | dem | dem_sigma | error | role | note |")
    r = runner.invoke(app, ["validate", "--model", "ret", "--data", str(data_dir / "dem_hcs_cooling.csv")])
    assert r.exit_code == 0, r.output
    assert "no fit recorded for model 'ret'" in r.stdout


# -- bad input: one line naming it, exit 2 -------------------------------------------------------
def _one_line_exit_2(args, match):
    r = runner.invoke(app, args)
    assert r.exit_code == 2, r.output
    assert r.stderr.count("\n") == 1 and match in r.stderr, r.stderr


def test_unknown_columns(tmp_path):
    f = tmp_path / "x.csv"
    f.write_text("# units d = m = 1\na,b\n1,2\n3,4\n")
    _one_line_exit_2(["validate", "--model", "dense", "--data", str(f)], "data file x.csv: columns a, b match no DEM case")


@pytest.mark.parametrize("name, old, new, match", [
    ("dem_uniform_shear.csv", "units d = m = 1", "units d = 2, m = 1", "do not match the shared format"),
    ("dem_hcs_cooling.csv", "in units d=m=1", "in units d=1e-3 m", "header does not state the units d = m = 1"),
    ("dem_uniform_shear_friction.csv", "shear rate gdot = 1", "shear rate gdot = 2", "does not state the shear rate gdot = 1"),
    ("dem_uniform_shear_friction.csv", ",p_star,", ",pstar,", "missing column(s) p_star"),
])
def test_units_or_columns_that_do_not_match(data_dir, tmp_path, name, old, new, match):
    text = (data_dir / name).read_text()
    assert old in text
    f = tmp_path / name
    f.write_text(text.replace(old, new))
    _one_line_exit_2(["validate", "--model", "dense", "--data", str(f)], match)


def test_without_data_the_shipped_files_are_used(dense_table):
    r = runner.invoke(app, ["validate", "--model", "dense", "--cells", CELLS, "--format", "json"])
    assert r.exit_code == 0, r.output
    shipped = json.loads(r.stdout)["rows"]
    assert [(x["file"], x["state"], x["quantity"], x["dem"]) for x in shipped] == \
        [(x["file"], x["state"], x["quantity"], x["dem"]) for x in dense_table["rows"]]


def test_missing_data_and_model_choice(tmp_path, data_dir):
    _one_line_exit_2(["validate", "--model", "dense", "--data", str(tmp_path / "none.csv")], "does not exist")
    _one_line_exit_2(["validate", "--data", str(data_dir)], "give exactly one of --model NAME or --model-file FILE")


def test_model_file_from_another_version_with_unknown_options(tmp_path, data_dir):
    f = tmp_path / "future.toml"
    f.write_text('[model]\nbase = "dense"\n[model.options]\nphi_j_scale = 0.9\n[provenance]\nktgf_version = "9.9.0"\n')
    _one_line_exit_2(["validate", "--model-file", str(f), "--data", str(data_dir / "dem_uniform_shear.csv")],
                     "field 'model.options.phi_j_scale': model 'dense' has no such option (file written by ktgf 9.9.0, this is ktgf")
    with pytest.raises(InputError):
        validate(get_model("dense"), [tmp_path])  # a folder without .csv files


def test_a_state_the_model_refuses_keeps_its_rows(data_dir, tmp_path):
    """dense diverges at φ_J(0) = 0.634: a state at 0.65 is in the table with NaN and the refusal, the others are answered."""
    lines = (data_dir / "dem_uniform_shear.csv").read_text().splitlines()
    f = tmp_path / "dense_beyond.csv"
    f.write_text("\n".join([*lines, "0.65" + lines[-1][lines[-1].index(","):]]) + "\n")
    res = validate(get_model("dense"), [f])
    beyond = [r for r in res.rows if r["state"].startswith("phi=0.65")]
    assert len(beyond) == 3 and all(np.isnan(r["model"]) and "out of range" in r["note"] for r in beyond)
    assert all(np.isfinite(r["model"]) for r in res.rows if not r["state"].startswith("phi=0.65"))


def test_couette_file_with_a_broken_header_is_bad_input(data_dir, tmp_path):
    text = (data_dir / "dem_couette_e0.9_phi0.50.csv").read_text()
    f = tmp_path / "c.csv"
    f.write_text(text.replace("wall shear stress tau", "wall stress"))
    _one_line_exit_2(["validate", "--model", "dense", "--data", str(f)], "header field tau not found")


def test_couette_rows_use_the_dem_walls_when_the_header_states_them(dense_table, data_dir):
    """The shared cell's header states its wall spheres: validate runs the bumpy walls (nothing fitted) and its
    rows are compare_with_dem's with wall="bumpy"; without the header line it falls back to JJ fitted to the slip."""
    from ktgf.couette.compare import compare_with_dem

    name = "dem_couette_e0.9_phi0.50.csv"
    rows = {r["quantity"]: r for r in dense_table["rows"] if r["file"] == name}
    assert all(r["note"].startswith("bumpy walls") for r in rows.values())
    (ref,), _ = compare_with_dem(data_dir / name, ["dense"], n_cells=int(CELLS), wall="bumpy")
    assert rows["tau_wall"]["model"] == pytest.approx(ref["tau_wall"], rel=1e-9)
    assert rows["p_wall"]["model"] == pytest.approx(ref["p"], rel=1e-9)


def test_couette_without_wall_spheres_in_the_header_gets_jj_walls_fitted_to_the_slip(data_dir, tmp_path):
    name = "dem_couette_e0.9_phi0.50.csv"
    text = (data_dir / name).read_text().replace("walls = one hexagonal close-packed layer of 168 touching spheres each "
                                                 "(d = 1, rows along x)", "walls = rough")
    assert "walls = rough" in text
    (tmp_path / name).write_text(text)
    v = validate(get_model("dense"), [tmp_path / name], n_cells=int(CELLS))
    assert len(v.rows) == 2 and all(r["note"].startswith("JJ walls, specularity") for r in v.rows)
