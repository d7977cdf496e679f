"""Runs from configs: validation before compiling, outputs, Ctrl-C + resume, divergence diagnosis, CLI."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from helpers.vti import read_vti
from typer.testing import CliRunner

from ktgf.cli import app
from ktgf.errors import DivergenceError, InputError
from ktgf.solver.config import load_config, parse_config
from ktgf.solver.grid import Grid
from ktgf.solver.io import load_checkpoint, write_vti
from ktgf.solver.run import CHECKPOINT, Simulation

TIMESERIES = "cooling.nc"  # the time series of a cooling run

BASE = {
    "model": {"name": "ret", "restitution": 0.8},
    "initial": {"solid_fraction": 0.25, "temperature": 1e-4, "amplitude": 0.05, "seed": 2},
    "grid": {"cells": [8, 8], "relative_to": "transverse", "factor": 1.5},
    "time": {"end": 4.0, "outputs": 4, "max_steps_per_call": 7},
    "output": {"checkpoint_every": 1, "vtk_every": 2},
}


pytestmark = pytest.mark.contract


def _cfg(**changes: dict) -> dict:
    cfg = {k: dict(v) for k, v in BASE.items()}
    for section, values in changes.items():
        cfg.setdefault(section, {}).update(values)
    return cfg


@pytest.mark.parametrize(
    "section, values, words",
    [
        ("grid", {"cells": [2, 8]}, ["grid.cells", "cells[0] = 2", ">= 4"]),
        ("initial", {"solid_fraction": 1.2}, ["initial.solid_fraction", "1.2"]),
        ("initial", {"temperature": 0.0}, ["initial.temperature", "greater than 0"]),
        ("initial", {"temperature": -1.0}, ["initial.temperature"]),
        ("model", {"restitution": 1.5}, ["model.restitution"]),
        ("model", {"name": "nonsense"}, ["model.name", "nonsense"]),
        ("numerics", {"limiter": "superbee"}, ["numerics.limiter", "vanleer"]),
        ("time", {"outputs": 0}, ["time.outputs"]),
        ("grid", {"length": 0.01}, ["grid", "exactly one"]),
        ("initial", {"colour": "red"}, ["initial.colour"]),
    ],
)
def test_config_errors_name_the_field(section: str, values: dict, words: list[str]) -> None:
    with pytest.raises(InputError) as exc:
        parse_config(_cfg(**{section: values}))
    for w in words:
        assert w in str(exc.value), str(exc.value)


def test_packing_limit_of_the_model_is_checked() -> None:
    with pytest.raises(InputError, match=r"initial.solid_fraction = 0.64 .*packing limit"):
        parse_config(_cfg(model={"name": "proposed"}, initial={"solid_fraction": 0.64}))
    parse_config(_cfg(model={"name": "ret"}, initial={"solid_fraction": 0.6}))  # CS allows it


def test_example_config_is_valid() -> None:
    cfg = load_config(Path(__file__).resolve().parents[2] / "examples" / "hcs_3d.toml")
    assert len(cfg.grid.cells) == 3


@pytest.mark.parametrize("scheme", ["imex", "ssprk3"])
def test_run_writes_outputs_and_resume_reproduces_the_run_exactly(tmp_path: Path, scheme: str) -> None:
    cfg = parse_config(_cfg(time={"scheme": scheme}))
    full = Simulation(cfg, tmp_path / "full")
    ds_full = full.run(progress=False)
    U_full = np.asarray(full.state)

    sim = Simulation(cfg, tmp_path / "split")
    calls = []

    def interrupt(info: dict) -> None:  # Ctrl-C in the middle of the second output interval
        calls.append(info)
        if len(calls) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sim.run(progress=False, on_chunk=interrupt)
    ck = load_checkpoint(tmp_path / "split" / CHECKPOINT)
    assert 0 < ck["t"] < float(ds_full.time[-1]) and ck["steps"] == calls[-1]["steps"]
    resumed = Simulation(cfg, tmp_path / "split")
    ds_res = resumed.run(progress=False, resume=tmp_path / "split" / CHECKPOINT)
    assert np.array_equal(np.asarray(resumed.state), U_full)
    assert resumed.steps == full.steps
    for name in ("theta_mean", "ke_transverse", "density_variance", "mode_density"):
        assert np.array_equal(ds_res[name].values, ds_full[name].values)

    ds = xr.open_dataset(tmp_path / "full" / TIMESERIES)
    assert ds.attrs["model"] == "ret" and "parameters" in ds.attrs
    assert ds.attrs["time_scheme"] == scheme and ds.attrs["step_count"] == full.steps > 0
    assert ds.attrs["binding_step_limit"] in ("cfl", "viscous", "conductive", "cooling")
    assert ds.attrs["wall_time_per_step_s"] > 0 and ds.dt_cfl.attrs["units"] == "s"
    assert ds.sizes["time"] == 5 and ds.time.attrs["units"] == "s"
    # A uniform-ish gas follows Haff's law closely over τ = 4 (amplitude 5 %).
    assert abs(float(ds.theta_mean[-1] / ds.theta_haff[-1]) - 1.0) < 0.01
    assert sorted(p.name for p in (tmp_path / "full").glob("*.vti")) == [
        "fields_00000.vti", "fields_00002.vti", "fields_00004.vti"]
    assert (tmp_path / "full" / "slice_00004.png").stat().st_size > 1000


def test_resume_refuses_another_config(tmp_path: Path) -> None:
    sim = Simulation(parse_config(_cfg()), tmp_path)
    sim.run(progress=False)
    other = Simulation(parse_config(_cfg(model={"restitution": 0.9})), tmp_path)
    with pytest.raises(InputError, match="different configuration"):
        other.run(progress=False, resume=tmp_path / CHECKPOINT)


def test_divergence_is_diagnosed_and_last_good_state_kept(tmp_path: Path) -> None:
    # A strong shear wave on a uniform density: its second-order compression pushes some
    # cell past phi_stop = phi0 + 1e-4.
    stop = 0.25 + 1e-4
    ini = {"perturbation": "mode", "mode": [1, 0], "kind": "transverse", "amplitude": 0.5}
    sim = Simulation(parse_config(_cfg(initial=ini, numerics={"phi_stop": stop})), tmp_path)
    with pytest.raises(DivergenceError) as exc:
        sim.run(progress=False)
    err = exc.value
    assert err.field == "solid_fraction" and err.value >= stop and len(err.cell) == 2
    assert "t = " in str(err) and "cell" in str(err) and str(tmp_path / CHECKPOINT) in str(err)
    ck = load_checkpoint(tmp_path / CHECKPOINT)
    assert ck["t"] == err.time and ck["t"] > 0
    assert ck["U"][0].max() / 2500.0 < stop  # the kept state is the last good one


def test_initial_state_beyond_phi_stop_is_an_input_error() -> None:
    sim = Simulation(parse_config(_cfg(initial={"amplitude": 0.3}, numerics={"phi_stop": 0.33})))
    with pytest.raises(InputError, match="initial state.*solid fraction"):
        sim.run(progress=False, write_files=False)


def test_nonfinite_state_is_rejected() -> None:
    from ktgf.solver.stepping import advance

    sim = Simulation(parse_config(_cfg()))
    U = np.array(sim.initial_state())
    U[4, 3, 3] = np.nan
    _, t, n, status, _ = advance(U, 0.0, 1.0, 10, sim.grid, sim.phys, sim.num)
    assert int(status) == 1 and int(n) == 0 and float(t) == 0.0


def test_vti_roundtrip_is_x_fastest(tmp_path: Path) -> None:
    grid = Grid((4, 5, 6), (1.0, 1.0, 1.0))
    f = np.arange(120, dtype=float).reshape(4, 5, 6)
    v = np.stack([f, 2 * f, 3 * f])
    write_vti(tmp_path / "a.vti", grid, {"f": f, "v": v}, time=1.5)
    back = read_vti(tmp_path / "a.vti")
    assert np.array_equal(back["f"], f.transpose(2, 1, 0).ravel())  # i fastest, then j, then k
    assert np.array_equal(back["v"][:3], [f[0, 0, 0], 2 * f[0, 0, 0], 3 * f[0, 0, 0]])
    assert np.array_equal(back["v"][3:6], [f[1, 0, 0], 2 * f[1, 0, 0], 3 * f[1, 0, 0]])
    assert back["TimeValue"][0] == 1.5


def test_cli_run_and_bad_config(tmp_path: Path) -> None:
    case = tmp_path / "case.toml"
    case.write_text(
        '[model]\nname = "enskog"\nrestitution = 0.8\n[initial]\nsolid_fraction = 0.2\ntemperature = 1e-4\n'
        '[grid]\ncells = [8]\nlength_d = 20.0\n[time]\nend = 1.0\nunit = "haff"\noutputs = 2\n'
        f'[output]\ndirectory = "{tmp_path / "out"}"\n'
    )
    runner = CliRunner()
    res = runner.invoke(app, ["run", str(case), "--no-progress"])
    assert res.exit_code == 0, res.output
    assert "theta/theta_Haff" in res.output and (tmp_path / "out" / TIMESERIES).is_file()
    res = runner.invoke(app, ["plot", "run", str(tmp_path / "out" / TIMESERIES), "-o", str(tmp_path / "p.png")])
    assert res.exit_code == 0 and (tmp_path / "p.png").is_file()
    case.write_text(case.read_text().replace("solid_fraction = 0.2", "solid_fraction = -0.2"))
    res = runner.invoke(app, ["run", str(case), "--no-progress"])
    assert res.exit_code == 2 and "initial.solid_fraction" in res.output
    assert len(res.output.strip().splitlines()) == 1


@pytest.mark.parametrize("scheme", ["imex", "ssprk3"])
def test_float32_run_lands_on_the_output_times_and_agrees_with_float64(scheme: str) -> None:
    results = {}
    for precision in ("float32", "float64"):
        sim = Simulation(parse_config(_cfg(numerics={"precision": precision}, time={"scheme": scheme})))
        ds = sim.run(progress=False, write_files=False)
        assert str(sim.state.dtype) == precision
        results[precision] = ds
    a, b = results["float32"], results["float64"]
    assert np.array_equal(a.time.values, b.time.values)
    assert np.allclose(a.theta_mean.values, b.theta_mean.values, rtol=1e-4)
