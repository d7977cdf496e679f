"""The ``ktgf hcs`` commands and the HCS figures, through typer's CliRunner."""

from __future__ import annotations

import csv
import io
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.cli._progress import DelayedProgress

runner = CliRunner()


def _ok(args):
    result = runner.invoke(app, args)
    assert result.exit_code == 0, (result.stdout, result.stderr, result.exception)
    return result


def _fails(args, *fragments):
    result = runner.invoke(app, args)
    assert result.exit_code == 2, (result.stdout, result.stderr)
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    for f in fragments:
        assert f in lines[0], lines[0]
    return lines[0]


@pytest.mark.published
def test_stability_json_matches_oracle_table():
    rows = json.loads(_ok(["hcs", "stability", "--model", "ret", "--phi", "0.1,0.3", "--e", "0.9", "--format", "json"]).stdout)
    assert [r["phi"] for r in rows] == [0.1, 0.3]
    assert rows[0]["L_perp/d"] == pytest.approx(28.499, abs=5e-4) and rows[0]["L_par/d"] == pytest.approx(51.216, abs=5e-4)
    assert rows[1]["L_perp/d"] == pytest.approx(12.101, abs=5e-4) and rows[1]["L_par/d"] == pytest.approx(23.987, abs=5e-4)


@pytest.mark.published
def test_stability_box_growth_rates_and_verdicts():
    """L = 40 d at e = 0.9: homogeneous at φ = 0.05 (L⊥ = 57.3), vortices only at φ = 0.1 (28.5 < 40 < 51.2)."""
    out = _ok(["hcs", "stability", "-m", "ret", "--phi", "0.05,0.1,0.3", "--e", "0.9", "--box", "40", "--format", "csv"]).stdout
    rows = list(csv.DictReader(io.StringIO(out)))
    assert [r["state"] for r in rows] == ["homogeneous", "vortices", "vortices+clusters"]
    for r in rows:
        assert float(r["k_box*"]) == pytest.approx(2 * np.pi * 5 * np.sqrt(2 * np.pi) / 96 / (float(r["phi"]) * 40))
        assert (float(r["s_perp"]) > 0) == (float(r["L_perp/d"]) < 40)


@pytest.mark.analytic
def test_stability_eig_method_agrees_and_reports_no_crossing():
    closed = json.loads(_ok(["hcs", "stability", "-m", "proposed", "--phi", "0.2:0.5:4", "--e", "0.8", "--format", "json"]).stdout)
    eig = json.loads(_ok(["hcs", "stability", "-m", "proposed", "--phi", "0.2:0.5:4", "--e", "0.8", "--format", "json",
                          "--method", "eig"]).stdout)
    for a, b in zip(closed, eig):
        assert b["L_par/d"] == pytest.approx(a["L_par/d"], rel=1e-10)
    result = _ok(["hcs", "stability", "-m", "ret", "--phi", "0.1", "--e", "0.1", "--method", "eig", "--format", "csv"])
    assert "no crossing found" in result.stderr
    assert list(csv.DictReader(io.StringIO(result.stdout)))[0]["k_par*"] == "inf"


@pytest.mark.published
def test_haff_table_netcdf_and_figure(tmp_path):
    import xarray as xr

    out = _ok(["hcs", "haff", "--model", "ret", "--phi", "0.1", "--e", "0.9", "--theta0", "1", "--d", "1",
               "--format", "json", "--out", str(tmp_path / "haff.nc")]).stdout
    row = json.loads(out)[0]
    assert row["t0 [s]"] == pytest.approx(17.945375, rel=1e-6) and row["max rel. diff"] < 1e-8
    ds = xr.load_dataset(tmp_path / "haff.nc")
    assert ds["theta_numeric"].sizes["t"] == 200 and "ret" in ds.attrs["models"]
    _ok(["hcs", "haff", "--phi", "0.3", "--e", "0.7", "--theta0", "1e-2", "--d", "1e-3", "--t-end", "0.5",
         "--out", str(tmp_path / "haff.png")])
    assert (tmp_path / "haff.png").stat().st_size > 10_000


@pytest.mark.contract
def test_map_writes_netcdf(tmp_path):
    import xarray as xr

    result = _ok(["hcs", "map", "--out", str(tmp_path / "map.nc"), "--n-phi", "20", "--n-e", "5"])
    assert "4 models x 20 phi x 5 e" in result.stdout
    ds = xr.load_dataset(tmp_path / "map.nc")
    assert ds["L_par"].shape == (4, 20, 5) and json.loads(ds.attrs["parameters"])["e"]["n"] == 5


@pytest.mark.contract
def test_plots(tmp_path):
    _ok(["hcs", "map", "--out", str(tmp_path / "m.nc"), "--n-phi", "30", "--n-e", "3", "--e-min", "0.7", "--e-max", "0.9"])
    _ok(["plot", "stability-map", "--from", str(tmp_path / "m.nc"), "--e", "0.9,0.7", "--out", str(tmp_path / "a.png")])
    _ok(["plot", "stability-map", "--e", "0.8", "--n-phi", "50", "--out", str(tmp_path / "b.pdf")])
    _ok(["plot", "dispersion", "-m", "visc-div", "--phi", "0.3", "--e", "0.8", "--box", "20", "--out", str(tmp_path / "c.svg")])
    for name in ("a.png", "b.pdf", "c.svg"):
        assert (tmp_path / name).stat().st_size > 5_000


@pytest.mark.contract
@pytest.mark.parametrize(
    "args,fragments",
    [
        (["hcs", "stability", "-m", "ret", "--phi", "1.2", "--e", "0.9"], ["phi = 1.2", "phi < 1"]),
        (["hcs", "stability", "-m", "visc-div", "--phi", "0.65", "--e", "0.9"], ["phi = 0.65", "phi < 0.64"]),
        (["hcs", "stability", "-m", "ret", "--phi", "0.3", "--e", "1.5"], ["e = 1.5", "0 < e <= 1"]),
        (["hcs", "stability", "-m", "ret", "--phi", "0", "--e", "0.9"], ["phi = 0", "1e-10 <= phi"]),
        (["hcs", "stability", "-m", "ret", "--phi", "0.3", "--e", "0.9", "--box", "-5"], ["--box = -5", "1 <= --box"]),
        (["hcs", "stability", "-m", "nope", "--phi", "0.3", "--e", "0.9"], ["unknown model 'nope'"]),
        (["hcs", "stability", "-m", "ret", "--phi", "abc", "--e", "0.9"], ["--phi 'abc'"]),
        (["hcs", "stability", "-m", "ret", "--phi", "0.3", "--e", "0.9", "--method", "x"], ["--method 'x'", "closed or eig"]),
        (["hcs", "haff", "--phi", "0.3", "--e", "0.9", "--theta0", "-1", "--d", "1e-3"], ["theta = -1", "1e-20 <= theta <= 1e+08"]),
        (["hcs", "haff", "--phi", "0.3", "--e", "0.9", "--theta0", "1", "--d", "0"], ["d = 0", "1e-09 <= d <= 1"]),
        (["hcs", "haff", "--phi", "0.3", "--e", "0.9", "--theta0", "1", "--d", "1", "--out", "x.txt"], ["'.txt'", ".nc"]),
        (["hcs", "map", "--out", "m.nc", "--n-phi", "0"], ["--n-phi = 0", "1 <= --n-phi"]),
        (["hcs", "map", "--out", "m.nc", "--e-min", "0"], ["e-min = 0", "0 < e-min <= 1"]),
        (["hcs", "map", "--out", "m.nc", "--phi-min", "0.3", "--phi-max", "0.2"], ["phi-max = 0.2", "0.3 <= phi-max < 1"]),
        (["hcs", "map", "--out", "m.csv"], ["'.csv'", ".nc"]),
        (["plot", "dispersion", "--phi", "0.3", "--e", "0", "--out", "d.png"], ["e = 0", "0 < e <= 1"]),
        (["plot", "stability-map", "--from", "missing.nc", "--out", "s.png"], ["missing.nc", "no such file"]),
    ],
)
def test_bad_input_exits_2_with_one_line(args, fragments, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _fails(args, *fragments)


@pytest.mark.contract
def test_unwritable_output_is_one_line(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    _fails(["hcs", "map", "--out", str(blocker / "map.nc"), "--n-phi", "5", "--n-e", "2"], "cannot write output file")


@pytest.mark.contract
def test_progress_bar_only_for_sweeps_longer_than_a_second():
    from rich.console import Console

    now = [0.0]
    console = Console(file=io.StringIO(), force_terminal=False, width=80)
    fast = DelayedProgress("map", clock=lambda: now[0], console=console)
    for i in range(1, 5):
        now[0] += 0.1
        fast(i, 4)
    assert not fast.shown
    slow = DelayedProgress("map", clock=lambda: now[0], console=console)
    with slow:
        for i in range(1, 5):
            now[0] += 0.6
            slow(i, 4)
        assert slow.shown
    assert slow.bar.tasks[0].completed == 4
