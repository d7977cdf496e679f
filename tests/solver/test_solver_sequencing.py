"""Starting a run from an earlier run's result on another grid (``initial.from_run``, grid sequencing).

Oracles from outside the mapping: exact cell averages of linear and smooth profiles (the remap of
a linear profile is exact, of a smooth one second order), exact conservation of the integrals of
ρ, ρu and E (round-off), the energy a resolved linear shear profile must take from θ when total
energy is conserved ((γ̇h)²/48, h the old cell: the coarse cell's kinetic energy lacks the sub-cell
shear's ½ρ(γ̇h)²/12 and the refined cells resolve three quarters of it), and the closed-form
uniform shear (a mapped steady state returns to it).
"""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from ktgf.errors import InputError
from ktgf.solver.cases.uniform_shear import uniform_shear_reference
from ktgf.solver.config import parse_config
from ktgf.solver.io import load_checkpoint, save_checkpoint
from ktgf.solver.run import Simulation
from ktgf.solver.sequencing import map_state, remap_axis, totals

ROOT = Path(__file__).resolve().parents[2]


def _cell_averages(F, n: int) -> np.ndarray:
    """Exact averages over n equal cells of [0, 1] of the function with antiderivative F."""
    x = np.linspace(0.0, 1.0, n + 1)
    return np.diff(F(x)) * n


@pytest.mark.analytic
@pytest.mark.parametrize("periodic", [True, False])
@pytest.mark.parametrize("n_old, n_new", [(12, 24), (12, 36), (24, 12), (12, 7), (7, 12), (16, 5)])
def test_remap_conserves_the_integral_to_round_off(periodic: bool, n_old: int, n_new: int) -> None:
    rng = np.random.default_rng(3)
    f = 1.0 + rng.random((3, n_old, 2))
    for order in (1, 2):
        g = remap_axis(f, 1, n_new, periodic, order)
        assert g.shape == (3, n_new, 2)
        np.testing.assert_allclose(g.sum(axis=1) / n_new, f.sum(axis=1) / n_old, rtol=1e-14)


@pytest.mark.analytic
def test_remap_of_a_linear_profile_gives_its_exact_cell_averages() -> None:
    """Bounded axis (one-sided end slopes): refinement, coarsening and a non-integer ratio are exact."""
    F = lambda x: 0.3 * x + 0.7 * x * x / 2  # antiderivative of 0.3 + 0.7 x  # noqa: E731
    for n_old, n_new in ((8, 24), (24, 8), (10, 7)):
        got = remap_axis(_cell_averages(F, n_old), 0, n_new, periodic=False)
        np.testing.assert_allclose(got, _cell_averages(F, n_new), rtol=1e-13, atol=1e-15)


@pytest.mark.analytic
def test_remap_of_a_smooth_profile_converges_at_second_order() -> None:
    """sin(2πx) on a periodic axis, refined 2×: the error against the exact averages falls as h²."""
    F = lambda x: -np.cos(2 * np.pi * x) / (2 * np.pi)  # noqa: E731
    errs = []
    for n in (16, 32, 64, 128):
        got = remap_axis(_cell_averages(F, n), 0, 2 * n, periodic=True)
        errs.append(np.max(np.abs(got - _cell_averages(F, 2 * n))))
    orders = np.log2(np.asarray(errs[:-1]) / np.asarray(errs[1:]))
    assert np.all(orders > 1.8), (errs, orders)


@pytest.mark.analytic
def test_refinement_then_restriction_is_the_identity() -> None:
    f = 1.0 + np.random.default_rng(0).random((5, 9))
    for r in (2, 3):
        back = remap_axis(remap_axis(f, 1, 9 * r, periodic=False), 1, 9, periodic=False)
        np.testing.assert_allclose(back, f, rtol=1e-14)


def _state(cells: tuple[int, ...], seed: int = 1) -> np.ndarray:
    """A smooth non-uniform physical conservative state (ρ, ρu, E) with a shear profile along axis 1."""
    rng = np.random.default_rng(seed)
    x = np.meshgrid(*((np.arange(n) + 0.5) / n for n in cells), indexing="ij")
    rho = 1250.0 * (1.0 + 0.1 * np.sin(2 * np.pi * x[0]) + 0.05 * x[1] ** 2) * (1 + 0.01 * rng.random(cells))
    u = np.stack([0.5 * (x[1] - 0.5) + 0.01 * np.cos(2 * np.pi * x[2]), 0.01 * np.sin(2 * np.pi * x[0]),
                  0.02 * x[1] * (1 - x[1])])
    theta = 1e-3 * (1.0 + 2.0 * (x[1] - 0.5) ** 2)
    return np.stack([rho, *(rho * u), rho * (0.5 * np.sum(u * u, axis=0) + 1.5 * theta)])


@pytest.mark.analytic
def test_map_state_conserves_mass_momentum_and_energy_and_tiles_periodic_axes() -> None:
    """x periodic tiled 2× and coarsened, y (walls) refined 3×, z periodic 8 → 5: totals per tile to round-off."""
    old, L = (8, 8, 8), (4e-3, 1e-2, 4e-3)
    kinds = ("periodic", "wall", "periodic")
    U = _state(old)
    new, Ln = (12, 24, 5), (8e-3, 1e-2, 4e-3)
    V, order = map_state(U, old, L, new, Ln, kinds)
    assert order == 2 and V.shape == (5, *new)
    np.testing.assert_allclose(totals(V, Ln) / 2.0, totals(U, L), rtol=1e-13, atol=1e-13 * np.abs(totals(U, L)).max())
    same, order = map_state(U, old, L, old, L, kinds)
    assert np.array_equal(same, U)  # the same grid: the state itself, bit for bit


@pytest.mark.analytic
def test_map_state_falls_back_to_the_first_order_remap_when_the_slopes_would_make_theta_negative() -> None:
    """A cold cell next to a fast stream: the linear reconstruction of E − k overshoots below 0."""
    rho = np.full((8,), 1000.0)
    u = np.where(np.arange(8) < 4, 0.0, 1.0)
    theta = np.where(np.arange(8) == 3, 1e-9, 1e-3)
    U = np.stack([rho, rho * u, 0 * rho, 0 * rho, rho * (0.5 * u * u + 1.5 * theta)])
    V, order = map_state(U, (8,), (1.0,), (32,), (1.0,), ("wall",))
    assert order == 1
    th = (V[4] / V[0] - 0.5 * (V[1] / V[0]) ** 2) / 1.5
    assert th.min() > 0 and np.allclose(V.sum(axis=1) / 4, U.sum(axis=1), rtol=1e-14)


# -- runs ------------------------------------------------------------------------------------

def _couette(cells: list[int], length_d: list[float], directory: Path, **initial: object) -> dict:
    data = tomllib.loads((ROOT / "examples" / "couette_2d.toml").read_text())
    data["grid"] = {"cells": cells, "length_d": length_d}
    data["time"].update(end=1.0, outputs=2)
    data["time"].pop("steady_tol")
    data["output"] = {"directory": str(directory), "vtk": False, "png": False}
    if initial:
        data["initial"] = {"solid_fraction": 0.3, **initial}
    return data


def _write_run(data: dict, folder: Path, run: bool) -> None:
    """The run of ``data`` in ``folder`` (``run``), or without stepping (no compilation) its initial
    state written as the checkpoint a finished run leaves."""
    sim = Simulation(parse_config(data))
    if run:
        sim.run(progress=False)
        return
    folder.mkdir(parents=True)
    with sim.precision():
        U = np.asarray(sim.initial_state())
    save_checkpoint(folder / "checkpoint.npz", U, 0.0, 0, 1, {}, sim.config_json())


@pytest.fixture(scope="module")
def earlier(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """An earlier 4 × 8 Couette state (RET, φ̄ 0.3, random perturbation 0.02) that later runs start from."""
    folder = tmp_path_factory.mktemp("seq") / "coarse"
    data = _couette([4, 8], [4.0, 10.0], folder)
    _write_run(data, folder, run=False)
    return folder, data


def _initial(data: dict) -> np.ndarray:
    sim = Simulation(parse_config(data))
    with sim.precision():
        return np.asarray(sim.initial_state())


@pytest.mark.contract
def test_the_same_grid_gives_the_earlier_state_bit_for_bit(earlier, tmp_path: Path) -> None:
    folder, _ = earlier
    data = _couette([4, 8], [4.0, 10.0], tmp_path / "b", from_run=str(folder), perturbation="none")
    assert np.array_equal(_initial(data), load_checkpoint(folder / "checkpoint.npz")["U"])
    # the checkpoint file itself is a valid source too
    data["initial"]["from_run"] = str(folder / "checkpoint.npz")
    assert np.array_equal(_initial(data), load_checkpoint(folder / "checkpoint.npz")["U"])


@pytest.mark.analytic
def test_a_run_mapped_onto_a_finer_wider_grid_keeps_the_totals_and_records_the_sequence(earlier, tmp_path: Path) -> None:
    folder, _ = earlier
    U = load_checkpoint(folder / "checkpoint.npz")["U"]
    L_old = (4e-3, 1e-2)
    data = _couette([8, 16], [8.0, 10.0], tmp_path / "fine", from_run=str(folder), perturbation="none")
    V = _initial(data)
    np.testing.assert_allclose(totals(V, (8e-3, 1e-2)) / 2, totals(U, L_old), rtol=1e-13,
                               atol=1e-13 * np.abs(totals(U, L_old)).max())
    # perturbed: mass and momentum kept, θ cell by cell, the velocity changed
    data["initial"].update(perturbation="random", amplitude=0.05, seed=4)
    P = _initial(data)
    np.testing.assert_allclose(totals(P, (1, 1))[:4], totals(V, (1, 1))[:4], rtol=1e-13,
                               atol=1e-13 * np.abs(totals(V, (1, 1))).max())
    th = lambda W: (W[4] / W[0] - 0.5 * np.sum((W[1:4] / W[0]) ** 2, axis=0)) / 1.5  # noqa: E731
    np.testing.assert_allclose(th(P), th(V), rtol=1e-12)
    assert np.max(np.abs(P[2] / P[0] - V[2] / V[0])) > 1e-3
    sim = Simulation(parse_config(data))
    assert sim.started_from["cells"] == [4, 8] and sim.started_from["remap_order"] in (1, 2)


@pytest.mark.contract
@pytest.mark.parametrize("change, field", [
    (lambda d: d["boundaries"]["y"].update(wall_speed=2.0), "boundaries.y.wall_speed"),
    (lambda d: d["model"].update(restitution=0.8), "model.restitution"),
    (lambda d: d["model"].update(name="dense"), "model.name"),
    (lambda d: d["particles"].update(diameter=2e-3), "particles.diameter"),
    (lambda d: d["initial"].update(solid_fraction=0.35), "initial.solid_fraction"),
    (lambda d: d["grid"].update(length_d=[4.0, 12.0]), "grid length along y"),
    (lambda d: d["grid"].update(length_d=[6.0, 10.0]), "grid length along x"),
    (lambda d: d["grid"].update(length_d=[2.0, 10.0]), "grid length along x"),
    (lambda d: d["grid"].update(cells=[4, 8, 4], length_d=[4.0, 10.0, 4.0]), "grid.cells"),
    (lambda d: d.update(case={"kind": "uniform-shear"}, boundaries={"y": {
        "kind": "lees-edwards", "shear_rate": 100.0, "flow": "x"}}), "case.kind"),
])
def test_an_earlier_run_of_another_flow_is_refused_in_one_line_naming_the_field(earlier, tmp_path: Path, change,
                                                                                 field: str) -> None:
    folder, _ = earlier
    data = _couette([4, 16], [4.0, 10.0], tmp_path / "b", from_run=str(folder))
    change(data)
    with pytest.raises(InputError, match=f"field {field}") as exc:
        Simulation(parse_config(data))
    assert "\n" not in str(exc.value) and "from_run" in str(exc.value)


@pytest.mark.contract
def test_a_missing_or_unusable_source_is_refused_in_one_line(earlier, tmp_path: Path) -> None:
    folder, data = earlier
    for source, what in ((tmp_path / "nowhere", "does not exist"), (tmp_path, "holds no checkpoint.npz"),
                         (folder / "couette.nc", "netCDF time series holds no fields")):
        bad = _couette([4, 16], [4.0, 10.0], tmp_path / "b", from_run=str(source))
        with pytest.raises(InputError, match=f"field initial.from_run.*{what}"):
            Simulation(parse_config(bad))
    for extra in ({"temperature": 1e-3}, {"perturbation": "mode", "mode": [0, 1]}):
        bad = _couette([4, 16], [4.0, 10.0], tmp_path / "b", from_run=str(folder), **extra)
        with pytest.raises(InputError, match="field initial: from_run starts from the earlier run's state"):
            parse_config(bad)


def _uniform_shear_mapped(tmp_path: Path) -> tuple[Simulation, np.ndarray, np.ndarray, float, dict]:
    """The closed-form steady state of an 8-cell Lees–Edwards column (RET φ 0.3, 8 d) as an earlier run,
    and the run that starts from it on 16 cells: (sim, old U, mapped U, γ̇, reference)."""
    data = tomllib.loads((ROOT / "examples" / "uniform_shear.toml").read_text())
    rate = data["boundaries"]["y"]["shear_rate"]
    data["grid"] = {"cells": [8], "length_d": 8.0}
    data["boundaries"] = {"x": {"kind": "lees-edwards", "shear_rate": rate, "flow": "y"}}
    data["time"] = {"end": 0.1, "unit": "strain", "outputs": 1, "scheme": "ssprk3"}
    data["output"] = {"directory": str(tmp_path / "coarse"), "vtk": False, "png": False}
    sim = Simulation(parse_config({**data, "initial": {"solid_fraction": 0.3, "temperature": 1e-3,
                                                       "perturbation": "none"}}))
    ref = uniform_shear_reference(sim.phys, 0.3, rate)
    data["initial"] = {"solid_fraction": 0.3, "temperature": ref["theta"], "perturbation": "none"}
    _write_run(data, tmp_path / "coarse", run=False)
    old = load_checkpoint(tmp_path / "coarse" / "checkpoint.npz")["U"]
    fine = copy.deepcopy(data)
    fine["initial"] = {"solid_fraction": 0.3, "from_run": str(tmp_path / "coarse"), "perturbation": "none"}
    fine["grid"]["cells"] = [16]
    fine["time"] = {"end": 10.0, "unit": "strain", "outputs": 2, "scheme": "ssprk3"}
    fine["output"]["directory"] = str(tmp_path / "fine")
    sim = Simulation(parse_config(fine))
    with sim.precision():
        V = np.asarray(sim.initial_state())
    return sim, old, V, rate, ref


@pytest.mark.analytic
def test_a_mapped_uniform_shear_steady_state_keeps_the_linear_profile_and_loses_the_resolved_shear_energy(
        tmp_path: Path) -> None:
    """Mapped onto 16 cells, u stays the linear profile and θ drops by exactly (γ̇h)²/48 away from the
    Lees–Edwards ends (energy conservation, module docstring; 3.5 % of θ here)."""
    sim, old, V, rate, ref = _uniform_shear_mapped(tmp_path)
    y = sim.grid.centres(0)
    np.testing.assert_allclose(V[2] / V[0], rate * (y - 4e-3), rtol=1e-10, atol=1e-12)
    th = lambda W: (W[4] / W[0] - 0.5 * np.sum((W[1:4] / W[0]) ** 2, axis=0)) / 1.5  # noqa: E731
    assert np.allclose(th(old), ref["theta"], rtol=1e-6)
    drop = (rate * 1e-3) ** 2 / 48.0
    np.testing.assert_allclose(th(V)[2:-2], np.mean(th(old)) - drop, rtol=1e-9)


@pytest.mark.analytic
@pytest.mark.slow
def test_a_mapped_uniform_shear_steady_state_returns_to_the_closed_form(tmp_path: Path) -> None:
    """... and θ, η, p are the closed form's within 1e-4 after 10 strains (164 s under load 15)."""
    sim = _uniform_shear_mapped(tmp_path)[0]
    sim.run(progress=False)
    assert max(sim.verification["max_rel_error"].values()) < 1e-4, sim.verification["max_rel_error"]


# -- examples --------------------------------------------------------------------------------

SEQUENCE = ("couette_dense_seq32", "couette_dense_seq64", "couette_dense_seq128")


@pytest.mark.contract
def test_ktgf_run_help_lists_every_solver_example() -> None:
    """Every example config of the 3D solver (a [grid] table) is named in the help of `ktgf run`."""
    import inspect

    from ktgf.cli.solver import run

    listed = inspect.signature(run).parameters["case"].default.help
    solver = [p.stem for p in sorted((ROOT / "examples").glob("*.toml")) if "grid" in tomllib.loads(p.read_text())]
    assert "couette_dense_3d" in solver and set(SEQUENCE) <= set(solver)
    missing = [name for name in solver if not any(name == w.strip(" ,.(") for w in listed.replace(":", " ").split())]
    assert not missing, missing


@pytest.mark.contract
def test_the_sequencing_examples_chain_their_output_folders() -> None:
    configs = [parse_config(tomllib.loads((ROOT / "examples" / f"{n}.toml").read_text())) for n in SEQUENCE]
    assert [c.grid.cells[1] for c in configs] == [32, 64, 128]
    assert configs[0].initial.from_run is None
    for before, after in zip(SEQUENCE, configs[1:]):
        assert after.initial.from_run == f"{before}.toml" and after.initial.perturbation == "none"
    for slab, cube in (("couette_dense", "couette_dense_3d"), ("couette_dense055", "couette_dense055_3d")):
        cfg = parse_config(tomllib.loads((ROOT / "examples" / f"{cube}.toml").read_text()))
        assert cfg.initial.from_run == f"{slab}.toml" and cfg.grid.cells == [64, 64, 64]


@pytest.mark.analytic
@pytest.mark.slow(minutes=4.7)
def test_the_sequenced_dense_couette_at_128_cells_reaches_the_1d_solver_within_one_percent(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """φ̄ 0.55, 32 → 64 → 128 cells across the 10 d gap (the three examples as shipped, run from one
    folder): the last stage is within 1 % of the 1D Couette solver in u, φ, θ and in the wall stress,
    and its verification.json names the run it started from and adds up the steps and CPU time of the whole
    sequence."""
    from ktgf.solver.chain import run_chain

    monkeypatch.chdir(tmp_path)
    run_chain(ROOT / "examples" / f"{SEQUENCE[-1]}.toml", progress=False)  # runs the stages before it first
    stages = [json.loads((tmp_path / f"{name}_run" / "verification.json").read_text()) for name in SEQUENCE]
    for name, stage in zip(SEQUENCE, stages):
        assert stage["steady"]["reached"], (name, stage["steady"])
    ver = stages[-1]
    assert ver["cells_across_gap"] == 128
    assert Path(ver["started_from"]["from_run"]).name == f"{SEQUENCE[-2]}_run"
    assert ver["started_from"]["cells"][1] == 64
    for k in range(1, len(stages)):  # each stage's verification.json adds up the steps and CPU of those before it
        total = stages[k]["run"]["sequence"]
        assert total["steps"] == sum(stage["run"]["step_count"] for stage in stages[:k + 1])
        assert total["cpu_time_s"] == pytest.approx(sum(stage["run"]["cpu_time_s"] for stage in stages[:k + 1]))
    assert max(ver["max_rel_error"].values()) < 0.01, ver["max_rel_error"]
    tau = np.asarray(ver["wall_shear_stress_Pa"]["run"]) / np.asarray(ver["wall_shear_stress_Pa"]["reference"])
    assert np.max(np.abs(tau - 1.0)) < 0.01, ver["wall_shear_stress_Pa"]


@pytest.mark.contract
def test_the_cost_of_a_sequence_counts_every_earlier_run_once(tmp_path: Path) -> None:
    """Stage 3 of a chain: the earlier run's verification.json already holds the sum of stages 1–2."""
    from ktgf.solver.sequencing import _earlier_cost

    first = {"run": {"step_count": 10, "wall_time_s": 1.0, "cpu_time_s": 0.5}}
    second = {"run": {"step_count": 20, "wall_time_s": 2.0, "cpu_time_s": 1.5,
                      "sequence": {"steps": 30, "wall_time_s": 3.0, "cpu_time_s": 2.0}}}
    for name, ver in (("a", first), ("b", second)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "verification.json").write_text(json.dumps(ver))
    assert _earlier_cost(tmp_path / "a", 10)["sequence"] == {"steps": 10, "wall_time_s": 1.0, "cpu_time_s": 0.5}
    assert _earlier_cost(tmp_path / "b", 20)["sequence"] == {"steps": 30, "wall_time_s": 3.0, "cpu_time_s": 2.0}
    assert _earlier_cost(tmp_path / "nothing", 7) == {"steps": 7}
