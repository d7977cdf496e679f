"""`ktgf plot run` on the time series of sheared cases (no solver run: a short synthetic history)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


pytestmark = pytest.mark.contract


def _timeseries(example: str, tmp_path: Path) -> tuple[Path, float]:
    """Write the history file a run of ``example`` would write, with made-up values on 3 outputs."""
    pytest.importorskip("jax")
    from ktgf.io import write_netcdf
    from ktgf.solver.config import load_config
    from ktgf.solver.flows import PROFILES
    from ktgf.solver.kinematics import gradient_axis, shear_rate
    from ktgf.solver.run import PER_AXIS, Simulation

    sim = Simulation(load_config(EXAMPLES / example), directory=tmp_path / "run")
    rng = np.random.default_rng(0)
    n = 3
    history: dict[str, list] = {}
    for name in sim.history_keys:
        if name in PER_AXIS:
            history[name] = [list(rng.random(sim.grid.ndim)) for _ in range(n)]
        elif name in PROFILES:
            history[name] = [list(rng.random(sim.grid.cells[gradient_axis(sim.grid)])) for _ in range(n)]
        else:
            history[name] = list(rng.random(n))
    history["time"] = [0.0, 0.01, 0.02]
    path = tmp_path / sim.case.timeseries
    write_netcdf(sim.dataset(history, steps=10), path)
    return path, shear_rate(sim.grid)


@pytest.mark.parametrize(("example", "panels"), [("uniform_shear.toml", 3), ("couette_2d.toml", 5), ("chute_2d.toml", 5)])
def test_plot_run_draws_a_sheared_history_against_strain(example: str, panels: int, tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """Strain γ̇t on the x axis where a shear rate is imposed, t [s] for the chute; units on the y axes."""
    import ktgf.plotting
    from ktgf.cli import app
    from typer.testing import CliRunner

    path, rate = _timeseries(example, tmp_path)
    assert (rate > 0) == (example != "chute_2d.toml")
    drawn = []
    real_save = ktgf.plotting.save
    monkeypatch.setattr(ktgf.plotting, "save", lambda fig, out: (drawn.append(fig), real_save(fig, out))[1])
    out = tmp_path / "p.png"
    res = CliRunner().invoke(app, ["plot", "run", str(path), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert out.stat().st_size > 1000
    axes = drawn[0].axes
    assert len(axes) == panels
    times = np.array([0.0, 0.01, 0.02])
    assert axes[0].get_xlabel() == ("strain γ̇t" if rate else "t [s]")
    np.testing.assert_allclose(axes[0].lines[0].get_xdata(), rate * times if rate else times)
    assert axes[0].get_ylabel() == "θ [m2 s-2]"
    assert axes[1].get_ylabel().endswith("[Pa]")
    if panels == 5:  # gap profiles: u_f, φ, θ against the wall-normal position
        assert axes[2].get_xlabel().startswith("u_f [m s-1]") and axes[2].get_ylabel().endswith("[m]")


def test_plot_run_names_a_missing_sheared_column(tmp_path: Path) -> None:
    import xarray as xr
    from ktgf.cli import app
    from ktgf.io import write_netcdf
    from typer.testing import CliRunner

    path, _ = _timeseries("uniform_shear.toml", tmp_path)
    ds = xr.load_dataset(path).drop_vars("viscosity")
    write_netcdf(ds, tmp_path / "cut.nc")
    res = CliRunner().invoke(app, ["plot", "run", str(tmp_path / "cut.nc"), "-o", str(tmp_path / "p.png")])
    assert res.exit_code == 2
    assert "lacks viscosity" in res.output
