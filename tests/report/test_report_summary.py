"""The report's first screen and the page details a reader relies on.

Summary numbers are recomputed here from the netCDF files the summary links (traceability);
the recommendation and caveat logic is checked on manufactured section numbers.
"""

from __future__ import annotations

import dataclasses
import re
import shutil
import stat

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from ktgf.errors import InputError
from ktgf.report import ReportSettings, build_report, couette, framework
from ktgf.report.coefficients import step_sentence
from ktgf.report.cooling_gas import identical_runs, slices_caption
from ktgf.report.framework import SectionResult
from ktgf.report.overlap import coincide_below, overlap_groups, overlap_sentence
from ktgf.report.page import PAGE_NAME
from ktgf.report.summary import summarise

pytestmark = pytest.mark.contract


def _without_solvers(monkeypatch) -> None:
    for key in ("couette", "cooling_gas"):
        sec = framework._SECTIONS[key]
        monkeypatch.setitem(framework._SECTIONS, key, dataclasses.replace(sec, available=lambda: "skipped in this test"))


# -- the summary against its files ------------------------------------------------------------
def test_summary_is_first_and_every_number_comes_from_its_netcdf(quick_report, data_dir) -> None:
    page = (quick_report.out / PAGE_NAME).read_text()
    assert page.index('id="sec-summary"') < page.index('id="sec-coefficients"')
    s = summarise(quick_report.results)
    cases = [r.case for r in s.rows]
    assert any(c.startswith("Homogeneous cooling") for c in cases) and any(c.startswith("Uniform shear") for c in cases)
    walls = [r for r in s.rows if r.measure.startswith("wall")]
    assert walls and all("dense" in r.errors for r in walls)  # the dense section's model reaches the first screen
    for row in s.rows:
        path = quick_report.out / row.data
        assert path.is_file(), row
        assert row.data in page  # linked from the table
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            for name, err in row.errors.items():
                m = ds.sel(model=name) if "model" in ds.dims else ds
                if row.measure.startswith("cooling rate"):
                    again = float(np.mean(np.abs(m.A_model / m.A_early - 1)))
                elif row.measure.startswith("pressure"):
                    again = float(np.mean(np.abs(m.p_model / m.p_dem - 1)))
                elif row.measure.startswith("wall"):  # Couette wall stresses of the dense section
                    k = "tau" if "shear" in row.measure else "p"
                    again = abs(float(m[f"{k}_wall" if k == "tau" else "p"] / m[f"{k}_wall_dem" if k == "tau" else "p_dem"] - 1))
                elif row.measure.startswith("shear viscosity"):
                    phi = float(row.case.split("=")[1])
                    k = int(np.argmin(np.abs(ds.phi.values - phi)))
                    again = abs(float(m.eta_model[k] / m.eta_dem[k] - 1))
                elif row.measure.startswith("mean |model/DEM"):  # fitted models against all DEM files
                    what, role = row.case.removeprefix("Fitted models, ").removesuffix(" rows").split(": ")
                    pick = (ds.model == name) & (ds.role == role) & np.isfinite(ds.error)
                    if what != "all DEM files":
                        pick &= ds.case == what
                    again = float(np.mean(np.abs(ds.error.values[pick.values])))
                else:  # Couette profiles: recomputed from the model and DEM profiles in the file
                    dem = {"y": ds.y_dem.values, "ux": ds.u_dem.values, "phi": ds.phi_dem.values, "theta": ds.theta_dem.values}
                    e = couette.profile_errors(ds.y.values, {k: m[k].values for k in ("u", "phi", "theta")}, dem,
                                               next(r for r in quick_report.results if r.key == "couette").inputs["height"], float(ds.wall_speed))
                    key = {"φ": "phi_rms", "θ": "theta_rms_rel", "u": "u_rms_over_U"}[row.measure[0]]
                    again = e[key]
                assert again == pytest.approx(err, rel=1e-9), (row.case, row.measure, name)
    assert s.recommendations and all("closest" in t for t in s.recommendations)
    assert "Recommended model per regime" in page and "Caveats" in page


def _result(key: str, numbers: dict, datasets=(), inputs=None) -> SectionResult:
    return SectionResult(key, key, numbers=numbers, datasets=list(datasets), inputs=inputs or {})


def test_recommendation_follows_the_numbers() -> None:
    """Manufactured errors: the model with the most closest-to-DEM rows per regime is recommended, ties together."""
    hcs = _result("hcs", {"cooling_mean_abs_error": {"ret": 0.01, "enskog": 0.05, "proposed": 0.01},
                          "cooling_best": {"0.1,0.9": ["ret", "proposed"]}, "cooling_signed_mean": {"ret": 0.01, "enskog": 0.05, "proposed": 0.01}},
                  ["data/hcs/cooling_rate_vs_dem.nc"])
    coef = _result("coefficients", {"eta_shear_error": {"ret": {"0.5": -0.3}, "enskog": {"0.5": 0.2}, "proposed": {"0.5": -0.1}}},
                   ["data/coefficients/eta_vs_dem_uniform_shear.nc"])
    cou = _result("couette", {"couette_errors": {n: {"u_rms_over_U": u, "phi_rms": p, "theta_rms_rel": t} for n, u, p, t in
                                                 (("ret", 0.01, 0.03, 0.2), ("enskog", 0.02, 0.05, 0.3), ("proposed", 0.005, 0.02, 0.25))},
                              "couette_max_phi": {"ret": 0.6, "enskog": 0.63, "proposed": 0.58}},
                  ["data/couette/couette_profiles.nc"], {"phi_mean": 0.5})
    s = summarise([hcs, coef, cou])
    dilute, dense = s.recommendations
    assert dilute.split(":")[1].strip().startswith("RET and Proposed") and "1 of 1" in dilute
    assert dense.split(":")[1].strip().startswith("Proposed") and "3 of 4" in dense  # η, φ and u; RET wins θ
    assert [r.data for r in s.rows][0] == "data/hcs/cooling_rate_vs_dem.nc"
    text = " ".join(s.caveats)
    assert "cools faster than the DEM" in text and "RET and Proposed" in text and "Enskog reaches 0.630" in text
    # and with other numbers, another answer
    coef.numbers["eta_shear_error"]["ret"]["0.5"] = -0.01
    cou.numbers["couette_errors"]["ret"].update(u_rms_over_U=0.001, phi_rms=0.001)
    assert summarise([hcs, coef, cou]).recommendations[1].split(":")[1].strip().startswith("RET")


def test_split_verdict_is_not_a_recommendation() -> None:
    hcs = _result("hcs", {"cooling_mean_abs_error": {"ret": 0.032, "enskog": 0.034}, "cooling_best": {"0.1,0.9": ["ret"]}})
    coef = _result("coefficients", {"eta_shear_error": {"ret": {"0.3": 0.04}, "enskog": {"0.3": 0.02}},
                                    "pstar_mean_abs_error": {"ret": 0.018, "enskog": 0.018}})
    (dilute,) = summarise([hcs, coef]).recommendations
    assert "no single best model" in dilute and "all models equal in pressure p*" in dilute
    assert "RET closest in cooling rate ζ0 (3.2 %)" in dilute and "Enskog closest in shear viscosity η (2.0 %)" in dilute


def test_no_dem_no_error_table() -> None:
    s = summarise([_result("hcs", {"eta_star": {}}), _result("couette", {"couette_max_phi": {"ret": 0.6}})])
    assert s.rows == [] and s.recommendations == [] and "No DEM reference data" in s.caveats[0]


# -- page details ---------------------------------------------------------------------------------
def test_discussion_subsections_numbered_continuously_and_page_readable(quick_report) -> None:
    page = (quick_report.out / PAGE_NAME).read_text()
    disc = page[page.index('id="sec-discussion"'):page.index('id="sec-rerun"')]
    heads = re.findall(r"<h3>([\d.]+) ", disc)
    number = re.search(r"<h2>(\d+)\. Discussion", disc).group(1)
    assert heads == [f"{number}.{i}" for i in range(1, len(heads) + 1)] and len(heads) >= 2
    assert stat.S_IMODE((quick_report.out / PAGE_NAME).stat().st_mode) == 0o644
    assert "√(m/…)" not in page


def test_couette_without_dem_is_not_called_an_error(monkeypatch, tmp_path, quick_report) -> None:
    def fake(model, *, phi_mean, e, height, wall_speed, d, rho_s, n_cells, dem_path=None):
        y = np.linspace(-height / 2, height / 2, 11)
        return xr.Dataset({"u": ("y", wall_speed * y / height), "phi": ("y", phi_mean + 0 * y), "theta": ("y", 1 + 0 * y)},
                          coords={"y": y}, attrs={"valid": 1})

    monkeypatch.setattr(couette, "report_profiles", fake)
    sec = framework._SECTIONS["cooling_gas"]
    monkeypatch.setitem(framework._SECTIONS, "cooling_gas", dataclasses.replace(sec, available=lambda: "skipped"))
    out = tmp_path / "r"
    shutil.copytree(quick_report.out, out)
    rep = build_report(ReportSettings.preset(quick=True, out=out, data_dir=tmp_path / "absent"))
    cou = next(r for r in rep.results if r.key == "couette")
    (table,) = cou.tables
    assert "DEM" not in table.columns[-1] and "error against DEM" not in table.title and "calibrated on" not in table.note
    assert "no DEM data" in table.title
    page = (out / PAGE_NAME).read_text()
    assert "No DEM reference data were found" in page


def test_empty_data_folder_is_warned_about(monkeypatch, tmp_path, quick_report) -> None:
    _without_solvers(monkeypatch)
    empty = tmp_path / "empty"
    empty.mkdir()
    out = tmp_path / "r"
    shutil.copytree(quick_report.out, out)
    rep = build_report(ReportSettings.preset(quick=True, out=out, data_dir=empty))
    assert rep.data_note.startswith("WARNING") and "holds none of the reference files" in rep.data_note
    assert "holds none of the reference files" in (out / PAGE_NAME).read_text()
    from ktgf.cli import app

    res = CliRunner().invoke(app, ["reproduce", "--quick", "--out", str(out), "--data", str(empty)])
    assert "holds none of the reference files" in " ".join(res.output.split())


# -- settings file and overrides ------------------------------------------------------------------
def test_config_file_and_set_overrides(tmp_path) -> None:
    cfg = tmp_path / "report.toml"
    cfg.write_text('quick = true\ncouette_cells = 30\nmodels = ["ret", "proposed"]\ncooling_phi = 0.2\n')
    s = ReportSettings.from_sources(config=cfg, sets=["cooling_phi=0.5", "stability_e=0.7,0.9", "cooling_models=ret"])
    assert s.quick and s.couette_cells == 30 and s.models == ("ret", "proposed")
    assert s.cooling_phi == 0.5 and s.stability_e == (0.7, 0.9) and s.cooling_models == ("ret",)  # --set wins over the file
    assert s.coefficient_points == ReportSettings.preset(quick=True).coefficient_points  # the rest: the quick preset
    assert ReportSettings.from_sources(sets=["haff_states=[[0.2, 0.8]]"]).haff_states == ((0.2, 0.8),)


@pytest.mark.parametrize("sets, words", [
    (["coolng_phi=0.3"], ["coolng_phi", "cooling_phi"]),
    (["cooling_phi=2"], ["cooling_phi", "0.64"]),
    (["models=foo"], ["models", "foo"]),
    (["nokey"], ["key=value"]),
    (["haff_states=[[0.1, 1.5]]"], ["haff_states", "0 < e <= 1"]),
    (["stability_phi=0.5,0.1"], ["stability_phi"]),
])
def test_bad_settings_name_the_key(sets, words) -> None:
    with pytest.raises(InputError) as exc:
        ReportSettings.from_sources(sets=sets)
    assert "\n" not in str(exc.value)
    for w in words:
        assert w in str(exc.value)


def test_every_listed_setting_can_be_set() -> None:
    """Each field of the page's Settings table is accepted by --set with its own current value."""
    import json

    base = ReportSettings.preset(quick=True)
    for key, value in base.model_dump(mode="json").items():
        if value is None or key in ("out",):
            continue
        text = json.dumps(value) if not isinstance(value, str) else f'"{value}"'
        again = ReportSettings.from_sources(quick=True, sets=[f"{key}={text}"])
        assert getattr(again, key) == getattr(base, key), key
    assert len(type(base).model_fields) >= 25


def test_cli_bad_set_is_one_line_exit_2(tmp_path) -> None:
    from ktgf.cli import app

    res = CliRunner().invoke(app, ["reproduce", "--out", str(tmp_path / "r"), "--set", "cooling_phi=0.9"])
    assert res.exit_code == 2
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "cooling_phi" in lines[0]


# -- overlap and step statements come from the numbers -----------------------------------------------
def test_overlap_detection() -> None:
    a = np.linspace(1, 2, 50)
    groups = overlap_groups({"ret": a, "proposed": a * (1 + 1e-3), "enskog": a * 1.2})
    assert groups == [["ret", "proposed"]]
    assert "All 2 curves overlap" in overlap_sentence({"ret": a, "proposed": a}, "x")
    assert overlap_sentence({"ret": a, "enskog": 2 * a}, "x") == ""
    phi = np.linspace(0, 0.6, 61)
    b = np.where(phi > 0.49, 1.5, 1.0)
    assert coincide_below(phi, np.ones_like(phi), b) == pytest.approx(0.49)
    assert coincide_below(phi, np.ones_like(phi), 2 * np.ones_like(phi)) is None


def test_step_is_mentioned_only_when_measured() -> None:
    smooth = {"proposed": {"phi_f": 0.49, "p": 1e-9, "mu": 2e-9, "chi": 1e-9, "dchi": 1e-9}}
    assert "Steps measured" not in step_sentence(smooth) and "continuous" in step_sentence(smooth)
    stepped = {"proposed": {"phi_f": 0.49, "p": 1e-9, "mu": 1.39, "chi": 1e-9, "dchi": 1.2}}
    text = step_sentence(stepped)
    assert "μ* +139 %" in text and "slope" in text


def test_3d_captions_follow_the_numbers() -> None:
    sl = xr.Dataset({"phi_slice": (("run", "i", "j"), np.full((2, 2, 2), 0.1))})
    weak = {"ret/above": {"phi_growth": 1.23}, "ret/below": {"phi_growth": 1.0}}
    assert "no clusters are visible" in slices_caption(sl, weak)
    strong = {"ret/above": {"phi_growth": 5.0}}
    assert "clusters show in φ" in slices_caption(sl, strong)
    same = {"ret/below": {"x": 1.0}, "ret/above": {"x": 2.0}, "proposed/below": {"x": 1.0}, "proposed/above": {"x": 2.0},
            "enskog/below": {"x": 1.5}, "enskog/above": {"x": 2.0}}
    assert "RET and Proposed give identical numbers" in identical_runs(same)
    assert identical_runs({"ret/below": {"x": 1.0}, "proposed/below": {"x": 1.1}}) == ""


@pytest.mark.skipif(shutil.which("chromium") is None, reason="Chromium is not installed")
def test_summary_renders_in_headless_chromium(quick_report, tmp_path) -> None:
    """The browser's DOM of the page holds the summary table, first, with one row per test case."""
    import subprocess

    profile = tmp_path / "profile"
    profile.mkdir()
    dom = subprocess.run([shutil.which("chromium"), "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                          f"--user-data-dir={profile}", "--dump-dom", (quick_report.out / PAGE_NAME).resolve().as_uri()],
                         capture_output=True, text=True, timeout=120).stdout
    assert "Summary: which model, where, and how wrong" in dom
    table = dom.split('class="summary"', 1)[1].split("</table>", 1)[0]
    assert table.count("<tr>") == 1 + len(summarise(quick_report.results).rows)
    assert dom.index("sec-summary") < dom.index("sec-coefficients")
