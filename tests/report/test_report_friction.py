"""The report's frictional section: curves, the DEM comparison table and the goal sentence.

Oracles: the DEM file's own values (read back into the table), the closed forms of the registered model
(`model_uniform_shear`), and the μ = 0 reduction (the frictional model's μ = 0 curve is ``dense``).
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from ktgf import get_model
from ktgf.data import FRICTION_SHEAR as DEM_FILE, read_friction_shear
from ktgf.shear.steady import steady_shear
from ktgf.report import ReportSettings, framework
from ktgf.report import friction as section


pytestmark = pytest.mark.dem


def _ctx(tmp_path, data_dir):
    s = ReportSettings.preset(quick=True, out=tmp_path / "r")
    sec = framework._SECTIONS["friction"]
    (tmp_path / "r").mkdir()
    return framework.SectionContext(sec, s, tmp_path / "r", data_dir, sec.inputs(s))


def test_friction_section_outputs_and_errors(tmp_path, data_dir):
    ctx = _ctx(tmp_path, data_dir)
    section.run(ctx)
    res = ctx.result
    (fig,) = res.figures
    assert (ctx.out / fig.file).is_file()
    with xr.open_dataset(ctx.out / fig.data) as ds:
        # μ = 0 curve of the frictional model = dense (one family for all μ, docs/friction.md §6.0)
        phi = ds.phi.values[:3]
        ref = steady_shear(get_model("dense"), phi, 0.7).T
        np.testing.assert_allclose(ds["T"].sel(model="frictional", mu=0.0).values[:3], ref, rtol=1e-12)
        assert np.isnan(ds["T"].sel(model="frictional", mu=0.5).values[-1])  # φ = 0.6 is beyond φ_J(0.5) = 0.594
    rows = read_friction_shear(data_dir / DEM_FILE)
    (table,) = res.tables
    assert [r[1] for r in table.rows] == [r["T"] for r in rows]  # the DEM column is the file's
    errs = res.numbers["friction_errors"]["frictional"]
    assert errs[1]["T_err"] == pytest.approx(0.017, abs=0.002)  # docs/friction.md §6.0: +1.7 % at μ = 0.5, φ = 0.4
    goal = res.numbers["friction_goal"]
    assert set(goal) == {"0.4", "0.5"} and max(goal.values()) < 0.15  # docs/friction.md §6: largest error 11.0 %
    (sentence,) = section.discuss(res.numbers)
    assert "is met" in sentence
