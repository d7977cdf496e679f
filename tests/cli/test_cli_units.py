"""The CLI keeps its units: every help text and every table header, plus the CLI's small promises.

Rich reads "[m]" or "[kg/(m s)]" as markup tags and drops them; these tests walk every command.
"""

from __future__ import annotations

import csv
import io
import json
import re

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.cli._common import OutputFormat, deprecated_alias, emit, parse_values
from ktgf.errors import InputError

runner = CliRunner()
BRACKETS = re.compile(r"\[[^\]\[]+\]")
ROOT_CMD = typer.main.get_command(app)


pytestmark = pytest.mark.contract


def _flat(text: str) -> str:
    return " ".join(text.split())


def _commands(cmd=ROOT_CMD, path: tuple[str, ...] = ()) -> list:
    out = [(path, cmd)]
    if getattr(cmd, "commands", None):  # a group (typer may vendor its own click: no isinstance)
        for name, sub in cmd.commands.items():
            if not sub.hidden:
                out += _commands(sub, (*path, name))
    return out


COMMANDS = _commands()


def test_every_command_is_walked() -> None:
    names = {" ".join(p) for p, _ in COMMANDS}
    assert {"models", "coefficients", "hcs haff", "hcs map", "reproduce", "plot coefficients"} <= names
    assert len(names) >= 15


@pytest.mark.parametrize("path, cmd", COMMANDS, ids=[" ".join(p) or "ktgf" for p, _ in COMMANDS])
def test_help_keeps_bracketed_units(path: tuple[str, ...], cmd) -> None:
    result = runner.invoke(app, [*path, "--help"], terminal_width=200)
    assert result.exit_code == 0, result.output
    shown = _flat(result.output)
    texts = [cmd.help or ""] + [p.help or "" for p in cmd.params if p.param_type_name == "option" and not p.hidden]
    for text in texts:
        for unit in BRACKETS.findall(_flat(text)):
            assert unit in shown, f"{' '.join(path)} --help lost {unit!r}"
        # no other text vanishes either: every word of the option help is shown
        for word in re.findall(r"[A-Za-z]{4,}", text):
            assert word in shown, f"{' '.join(path)} --help lost {word!r}"
    fmt = next((p for p in cmd.params if "--format" in getattr(p, "opts", [])), None)
    if fmt is not None:
        assert all(f.value in fmt.help for f in OutputFormat), f"{' '.join(path)} --format help: {fmt.help!r}"


def _table_and_csv(args: list[str]) -> tuple[str, list[str]]:
    table = runner.invoke(app, [*args, "--format", "table"], terminal_width=200)
    assert table.exit_code == 0, table.output
    as_csv = runner.invoke(app, [*args, "--format", "csv"])
    assert as_csv.exit_code == 0, as_csv.output
    header = next(csv.reader(io.StringIO(as_csv.stdout)))
    return table.stdout, header


TABLE_COMMANDS = [
    ["models"],
    ["coefficients", "--model", "ret", "--phi", "0.1,0.3", "--e", "0.9"],
    ["hcs", "haff", "--model", "ret,enskog", "--phi", "0.1", "--e", "0.9", "--theta0", "1e-2", "--d", "1e-3"],
    ["hcs", "stability", "--model", "ret", "--phi", "0.2", "--e", "0.8", "--box", "10"],
]


@pytest.mark.parametrize("args", TABLE_COMMANDS, ids=[" ".join(a[:2]) for a in TABLE_COMMANDS])
def test_table_headers_keep_units(args: list[str]) -> None:
    table, header = _table_and_csv(args)
    units = [u for h in header for u in BRACKETS.findall(h)]
    flat = table.replace("┃", " ").replace("│", " ")
    for h in header:
        for unit in BRACKETS.findall(h):
            # a header may wrap inside its column; the unit's characters must all be there, in order
            assert unit in flat or _in_column(flat, unit), f"{' '.join(args)}: table lost {unit!r} of {h!r}"
    if args[0] in ("coefficients", "hcs") and args[1] != "stability":  # stability's headers are all reduced (k*, L/d)
        assert units, f"{' '.join(args)}: no unit in the headers at all"


def _in_column(table: str, unit: str) -> bool:
    squeezed = re.sub(r"\s+", "", table)
    return re.sub(r"\s+", "", unit) in squeezed


def test_emit_keeps_markup_like_text(capsys) -> None:
    rows = [{"t0 [s]": 1.0, "kappa [kg/(m s)]": 2.0, "name [bold]": "[red]x[/red]"}]
    emit(rows, OutputFormat.table, title="title [m]")
    out = capsys.readouterr().out
    for text in ("t0 [s]", "kappa [kg/(m s)]", "name [bold]", "[red]x[/red]", "title [m]"):
        assert text in out


def test_models_table_shows_full_rdf_names() -> None:
    from ktgf.closures import list_models

    out = runner.invoke(app, ["models"]).stdout
    for m in list_models():
        for word in m.rdf.describe().split():
            assert word in out, f"ktgf models cut {word!r}"


def test_haff_default_end_time_is_ten_longest_haff_times() -> None:
    res = runner.invoke(app, ["hcs", "haff", "--model", "ret,enskog", "--phi", "0.1", "--e", "0.9", "--theta0", "1e-2",
                              "--d", "1e-3", "--format", "json"])
    rows = json.loads(res.stdout)
    t0 = max(r["t0 [s]"] for r in rows)
    assert t0 < 1.0  # the old default (10 s) would not equal 10 t0 here
    for r in rows:
        assert r["t_end [s]"] == pytest.approx(10 * t0, rel=1e-12)


@pytest.mark.parametrize("text, expected", [
    ("0.3", [0.3]), ("0.1,0.2", [0.1, 0.2]), ("0:1:3", [0.0, 0.5, 1.0]),
    ("log:0.001:1:4", [0.001, 0.01, 0.1, 1.0]), ("LOG:1:100:3", [1.0, 10.0, 100.0]),
])
def test_ranges(text: str, expected: list[float]) -> None:
    np.testing.assert_allclose(parse_values(text, "x"), expected, rtol=1e-12)


@pytest.mark.parametrize("text, words", [
    ("log:0:1:3", ["--x", "start > 0"]), ("log:1:2", ["--x", "log:start:stop:num"]), ("a:b:c", ["--x", "start:stop:num"]),
    ("0:1:0", ["--x"]),
])
def test_bad_ranges_name_the_option(text: str, words: list[str]) -> None:
    with pytest.raises(InputError) as exc:
        parse_values(text, "x")
    for w in words:
        assert w in str(exc.value)


def test_log_range_through_the_cli() -> None:
    res = runner.invoke(app, ["hcs", "stability", "--model", "ret", "--phi", "log:0.01:0.1:3", "--e", "0.9", "--format", "json"])
    assert res.exit_code == 0, res.output
    np.testing.assert_allclose(sorted({r["phi"] for r in json.loads(res.stdout)}), [0.01, 0.1 ** 1.5, 0.1], rtol=1e-12)


def test_one_name_for_dask_and_the_old_one_hidden() -> None:
    for path in (("hcs", "map"), ("couette", "sweep")):
        cmd = ROOT_CMD
        for p in path:
            cmd = cmd.commands[p]
        opts = {o: p.hidden for p in cmd.params for o in getattr(p, "opts", [])}
        assert opts.get("--dask") is False, path
    help_text = runner.invoke(app, ["hcs", "map", "--help"]).output
    assert "--dask" in help_text and "--scheduler" not in help_text
    assert deprecated_alias(None, "tcp://a:1", "--scheduler", "--dask") == "tcp://a:1"
    with pytest.raises(InputError, match="--scheduler is the deprecated name of --dask"):
        deprecated_alias("tcp://b:1", "tcp://a:1", "--scheduler", "--dask")


def test_model_option_is_the_same_everywhere() -> None:
    """Every --model takes comma-separated names and defaults to the paper's four models (single-model commands excepted).

    The default is resolved at run time (None: the paper's four models, or only the --model-file model).
    """
    from ktgf.cli._common import resolve_models
    from ktgf.closures.models import PAPER_MODELS, get_model

    seen = 0
    for path, cmd in COMMANDS:
        for p in cmd.params:
            if "--model" in getattr(p, "opts", []):
                seen += 1
                if path in (("plot", "dispersion"), ("calibrate",), ("validate",)):  # one model's dispersion relation / fit / table
                    continue
                assert p.default is None and "paper's four models" in p.help, (path, p.default)
                assert resolve_models(p.default) == [get_model(n) for n in PAPER_MODELS]
                assert "--models" in p.opts, path
    assert seen >= 6


def test_shipped_couette_example_stays_below_random_close_packing() -> None:
    pytest.importorskip("ktgf.couette")
    from pathlib import Path

    from ktgf.closures.models import PAPER_MODELS
    from ktgf.couette.config import load_config, run_config

    cfg = load_config(Path(__file__).resolve().parents[2] / "examples" / "couette_planar.toml")
    for m in PAPER_MODELS:
        ds = run_config(cfg.model_copy(update={"model": m}))
        assert float(ds.phi.max()) < 0.62, (m, float(ds.phi.max()))


def test_progress_clock_names_the_case_and_its_time_unit() -> None:
    """The progress line of a sheared run counts strain γ̇t, not the cooling box's τ (and says which case)."""
    from ktgf.solver.cases import get_case
    from ktgf.solver.run import _Progress

    assert get_case("cooling").clock(0.5, tau=3.25) == "t = 0.5 s  τ = 3.25"
    assert get_case("uniform-shear").clock(0.02, shear_rate=250.0) == "t = 0.02 s  γ̇t = 5"
    assert get_case("couette").clock(0.02, shear_rate=100.0) == "t = 0.02 s  γ̇t = 2"
    assert get_case("chute").clock(1.5) == "t = 1.5 s"  # no imposed shear rate, no strain clock
    assert get_case("uniform-shear").label != get_case("cooling").label == "HCS"
    bar = _Progress(False, 0.04, None, 0.3, None, case="uniform-shear", shear_rate=250.0)
    assert bar.clock_text(0.04) == "t = 0.04 s  γ̇t = 10"
    assert "τ" not in bar.clock_text(0.04)


def test_run_eta_ignores_compilation_and_follows_collisions() -> None:
    """`ktgf run`'s time left: a 100 s compile in the first chunk, then 1 s per equal step in τ."""
    pytest.importorskip("jax")
    from ktgf.solver.config import parse_config
    from ktgf.solver.initial import t_of_tau
    from ktgf.solver.run import Simulation, _Progress

    sim = Simulation(parse_config({
        "model": {"name": "ret", "restitution": 0.8},
        "initial": {"solid_fraction": 0.25, "temperature": 1e-4},
        "grid": {"cells": [8, 8], "relative_to": "transverse", "factor": 1.5},
        "time": {"end": 20.0, "outputs": 4}, "output": {"vtk": False, "png": False},
    }))
    clock = [0.0]
    bar = _Progress(False, float(sim.output_times[-1]), sim.phys, sim.phi0, sim.theta0, clock=lambda: clock[0])
    n = 50  # chunks, equal in τ
    taus = np.linspace(0.0, bar.tau_end, n + 1)[1:]
    times = np.asarray(t_of_tau(taus, sim.phys, sim.phi0, sim.theta0), dtype=float)
    for i, t in enumerate(times[:10]):
        clock[0] += 100.0 if i == 0 else 1.0
        bar.update(float(t), 10, 100.0 if i == 0 else 1.0)
    assert bar.remaining == pytest.approx(n - 10, rel=0.02)  # 40 chunks of 1 s left
