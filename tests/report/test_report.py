"""The reproduction report: completeness, cache reuse, interruption, bad input, missing data.

one ``--quick`` report is built per test session (conftest) and copied where a test needs to change it.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import shutil
from pathlib import Path

import pytest

from ktgf.errors import InputError
from ktgf.report import ReportInterrupted, ReportSettings, build_report, check_report, framework, locate_data_dir
from ktgf.report.page import PAGE_NAME

pytestmark = pytest.mark.contract


def small(out: Path, **kw) -> ReportSettings:
    """The ``--quick`` settings (so the CLI test finds the module's report cached)."""
    return ReportSettings.preset(quick=True, out=out, **kw)


def log(out: Path) -> list[dict]:
    return [json.loads(ln) for ln in (out / ".cache" / "log.jsonl").read_text().splitlines()]


def counting(monkeypatch: pytest.MonkeyPatch, key: str, effect=None) -> list[int]:
    """Replace section ``key``'s run by a wrapper that counts calls (and optionally raises ``effect``)."""
    sec = framework._SECTIONS[key]
    calls: list[int] = []

    @functools.wraps(sec.run)  # keeps __module__, so the cache key is the real section's
    def run(ctx):
        calls.append(1)
        if effect is not None:
            raise effect
        return sec.run(ctx)

    monkeypatch.setitem(framework._SECTIONS, key, dataclasses.replace(sec, run=run))
    return calls


def without_solvers(monkeypatch: pytest.MonkeyPatch) -> None:
    """Mark the Couette and 3D sections unavailable: tests of the framework that rebuild from an
    empty cache need not rerun the solvers (their sections have tests of their own)."""
    for key in ("couette", "cooling_gas"):
        sec = framework._SECTIONS[key]
        monkeypatch.setitem(framework._SECTIONS, key, dataclasses.replace(sec, available=lambda: "skipped in this test"))


@pytest.fixture
def built(quick_report):
    """The session's ``--quick`` report (tests copy it before changing anything)."""
    return quick_report


def test_quick_report_is_complete(built) -> None:
    assert built.problems == []
    assert check_report(built.out) == []
    st = built.statuses
    assert st["coefficients"] == st["hcs"] == "computed"
    page = (built.out / PAGE_NAME).read_text()
    # every section is part of every build (an installed wheel included): all computed, every DEM comparison made
    assert set(st.values()) == {"computed"}, st
    assert "Not available in this build." not in page and "particle simulations are left out" not in page
    # every figure has its netCDF file with run metadata
    import xarray as xr

    for r in built.results:
        for f in r.figures:
            assert f.data is not None
            with xr.open_dataset(built.out / f.data) as ds:
                assert "ktgf_version" in ds.attrs and "parameters" in ds.attrs


def test_second_run_recomputes_nothing(built, tmp_path, monkeypatch) -> None:
    out = tmp_path / "r"
    shutil.copytree(built.out, out)
    calls = {k: counting(monkeypatch, k) for k in ("coefficients", "hcs")}
    again = build_report(small(out))
    assert sum(map(len, calls.values())) == 0
    assert again.statuses["coefficients"] == again.statuses["hcs"] == "cached"
    assert [e["status"] for e in log(out)[-len(framework.sections()):] if e["section"] in ("coefficients", "hcs")] == ["cached", "cached"]
    assert again.problems == []


def test_changed_input_recomputes_only_its_section(built, tmp_path, monkeypatch) -> None:
    out = tmp_path / "r"
    shutil.copytree(built.out, out)
    calls = {k: counting(monkeypatch, k) for k in ("coefficients", "hcs")}
    again = build_report(small(out, stability_points=25))
    assert (len(calls["coefficients"]), len(calls["hcs"])) == (0, 1)
    assert again.problems == []


def test_interrupted_run_keeps_finished_sections_and_resumes(tmp_path, monkeypatch) -> None:
    out = tmp_path / "r"
    without_solvers(monkeypatch)
    counting(monkeypatch, "hcs", effect=KeyboardInterrupt())
    with pytest.raises(ReportInterrupted) as info:
        build_report(small(out))
    msg = str(info.value)
    assert "'hcs'" in msg and "coefficients" in msg and "again" in msg
    assert isinstance(info.value, KeyboardInterrupt)
    assert not (out / "figures" / "hcs").exists()  # half-written outputs removed
    monkeypatch.undo()
    without_solvers(monkeypatch)
    calls = {k: counting(monkeypatch, k) for k in ("coefficients", "hcs")}
    resumed = build_report(small(out))
    assert (len(calls["coefficients"]), len(calls["hcs"])) == (0, 1)
    assert resumed.statuses["coefficients"] == "cached" and resumed.statuses["hcs"] == "computed"
    assert resumed.problems == []


def test_failing_section_is_reported_not_cached(built, tmp_path, monkeypatch) -> None:
    out = tmp_path / "r"
    shutil.copytree(built.out, out)
    shutil.rmtree(out / ".cache")
    (out / ".cache").mkdir()
    without_solvers(monkeypatch)
    counting(monkeypatch, "hcs", effect=ValueError("boom"))
    rep = build_report(small(out))
    assert rep.statuses["hcs"] == "failed" and "ValueError: boom" in rep.failed[0].reason
    assert rep.problems == []  # the page is still consistent (no stale hcs figures)
    assert not (out / ".cache" / "hcs.json").exists()
    assert "This section failed" in (out / PAGE_NAME).read_text()


def test_unwritable_out_dir_is_one_clear_error(tmp_path) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    with pytest.raises(InputError, match="cannot write the report to .*a-file/report"):
        build_report(small(blocker / "report"))


def test_foreign_index_html_is_not_overwritten(tmp_path) -> None:
    (tmp_path / PAGE_NAME).write_text("<html>my own page</html>")
    with pytest.raises(InputError, match="index.html that ktgf did not write"):
        build_report(small(tmp_path))
    assert (tmp_path / PAGE_NAME).read_text() == "<html>my own page</html>"


def test_cli_ctrl_c_message_and_exit_code(built, tmp_path, monkeypatch) -> None:
    from typer.testing import CliRunner

    from ktgf.cli import app

    out = tmp_path / "r"
    shutil.copytree(built.out, out)
    shutil.rmtree(out / "figures" / "hcs")  # hcs must run again, and is interrupted
    counting(monkeypatch, "hcs", effect=KeyboardInterrupt())
    res = CliRunner().invoke(app, ["reproduce", "--quick", "--out", str(out)])
    text = " ".join(res.output.split())
    assert res.exit_code == 130
    assert "Interrupted: interrupted during section 'hcs'" in text and "Run the same command again" in text
    assert (out / ".cache" / "coefficients.json").is_file()


def test_missing_data_dir_gives_notes_not_failure(built, tmp_path) -> None:
    shutil.copytree(built.out, tmp_path / "r")
    rep = build_report(small(tmp_path / "r", data_dir=tmp_path / "no-such-folder"))
    assert rep.statuses["coefficients"] == rep.statuses["hcs"] == "computed"  # data content is part of the key
    assert rep.problems == [] and not rep.failed
    page = (rep.out / PAGE_NAME).read_text()
    assert "does not exist: comparisons with particle simulations are left out" in page
    assert "dem_hcs_cooling.csv not found" in page
    assert not any(f.file.endswith("cooling_rate_vs_dem.png") for r in rep.results for f in r.figures)


@pytest.fixture(scope="module")
def dem_dir() -> Path:
    """The DEM data folder as the report finds it by default (also from a git worktree)."""
    found, why = locate_data_dir(None)
    if found is None:
        pytest.skip(why)
    return found


def test_data_dir_from_environment(built, tmp_path, monkeypatch, dem_dir) -> None:
    shutil.copytree(built.out, tmp_path / "r")
    only = tmp_path / "dem"
    only.mkdir()
    shutil.copy(dem_dir / "dem_hcs_cooling.csv", only)
    monkeypatch.setenv("KTGF_DATA", str(only))
    rep = build_report(small(tmp_path / "r"))
    page = (rep.out / PAGE_NAME).read_text()
    assert "cooling_rate_vs_dem.png" in page  # the file that is there is used
    assert "dem_uniform_shear.csv not found" in page  # the one that is not is noted
    assert rep.problems == []


def test_check_report_finds_missing_stray_and_sections(built, tmp_path) -> None:
    out = tmp_path / "r"
    shutil.copytree(built.out, out)
    fig = next(out.glob("figures/hcs/*.png"))
    fig.unlink()
    (out / "figures" / "hcs" / "stray.png").write_bytes(b"x")
    page = out / PAGE_NAME
    page.write_text(page.read_text().replace('id="sec-discussion"', 'id="gone"'))
    problems = " | ".join(check_report(out))
    assert f"missing: figures/hcs/{fig.name}" in problems
    assert "not referenced by the page: figures/hcs/stray.png" in problems
    assert "section 'discussion' is missing" in problems


def test_settings_errors_name_the_field() -> None:
    with pytest.raises(InputError, match="stability_e"):
        ReportSettings.preset(stability_e=(0.7, 1.5))
    with pytest.raises(InputError, match="unknown model 'nope'"):
        ReportSettings.preset(models=("ret", "nope"))


def test_cli_reproduce_and_unwritable(built, tmp_path) -> None:
    from typer.testing import CliRunner

    from ktgf.cli import app

    out = tmp_path / "r"
    shutil.copytree(built.out, out)  # cached: the CLI path is exercised without recomputing
    res = CliRunner().invoke(app, ["reproduce", "--quick", "--out", str(out)])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())  # rich wraps lines at the terminal width
    assert "Completeness check passed" in text
    available = sum(1 for status in built.statuses.values() if status == "computed")
    assert text.count("cached (inputs unchanged)") == available
    blocker = tmp_path / "file"
    blocker.write_text("")
    res = CliRunner().invoke(app, ["reproduce", "--quick", "--out", str(blocker / "x")])
    assert res.exit_code == 2
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: cannot write the report")


@pytest.mark.skipif(not Path("/usr/bin/chromium").exists(), reason="Chromium (/usr/bin/chromium) is not installed")
def test_page_renders_in_headless_chromium(built, tmp_path) -> None:
    import subprocess

    import matplotlib.image as mpimg
    import numpy as np

    shot = tmp_path / "page.png"
    profile = tmp_path / "profile"
    profile.mkdir()
    cmd = ["/usr/bin/chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
           "--disable-background-networking", "--disable-component-update", "--disable-sync",
           f"--user-data-dir={profile}", "--window-size=1200,2400", f"--screenshot={shot}",
           (built.out / PAGE_NAME).resolve().as_uri()]
    subprocess.run(cmd, capture_output=True, timeout=120, check=False)
    assert shot.is_file(), "Chromium wrote no screenshot"
    img = mpimg.imread(shot)
    assert img.shape[0] == 2400 and img.shape[1] == 1200
    # A displayed page has text and figures: many distinct colours, not a blank or error page.
    colours = np.unique((img[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 200


def test_page_headings_are_numbered_once_each(built) -> None:
    """Result sections, discussion and rerun part carry the numbers 1, 2, ..., N without a repeat."""
    import re

    page = (built.out / PAGE_NAME).read_text()
    numbers = [int(n) for n in re.findall(r"<h2>(\d+)\. ", page)]
    assert numbers == list(range(1, len(numbers) + 1)), numbers
    assert len(numbers) == len(built.statuses) + 2
