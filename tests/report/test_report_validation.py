"""The report's validation section: every fitted model against every DEM file, fitted and predicted rows apart.

Oracles: the DEM files themselves (row counts per case), the fit sources on record (which rows are fitted),
and the errors of the same rows recomputed by ``ktgf validate``'s function on one file.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from ktgf import get_model
from ktgf.calibration.validate import fit_sources, validate
from ktgf.data import DEM_FILES, UNIFORM_SHEAR, read_table
from ktgf.report import ReportSettings, framework
from ktgf.report import validation as section
from ktgf.report.summary import summarise

pytestmark = pytest.mark.dem


def _run(tmp_path, data_dir):
    s = ReportSettings.preset(quick=True, out=tmp_path / "r")
    sec = framework._SECTIONS["validation"]
    (tmp_path / "r").mkdir()
    ctx = framework.SectionContext(sec, s, tmp_path / "r", data_dir, sec.inputs(s))
    section.run(ctx)
    return ctx


def test_validation_section_marks_fitted_and_predicted_rows(tmp_path, data_dir):
    ctx = _run(tmp_path, data_dir)
    res = ctx.result
    assert [t.title.split(":")[0] for t in res.tables] == [get_model(n).label or n for n in ("dense", "frictional")]
    (nc,) = res.datasets
    with xr.open_dataset(ctx.out / nc) as all_models:
        ds = all_models.where(all_models.model == "dense", drop=True)
        assert set(ds.case.values) == {"uniform-shear", "frictional-shear", "couette", "homogeneous-cooling"}
        us = ds.where(ds.case == "uniform-shear", drop=True)
        n_us = sum(read_table(data_dir / f).values.shape[0] for f in DEM_FILES if f.startswith("dem_uniform_shear")
                   and "friction" not in f)
        assert us.sizes["row"] == 3 * n_us and set(us.role.values) == {"fitted"}  # dense was fitted to all of them
        rest = ds.where(ds.case != "uniform-shear", drop=True)
        fitted = rest.where(rest.role == "fitted", drop=True)  # and p/(nT) of the cooling states: χ without shear
        assert set(fitted.case.values) == {"homogeneous-cooling"} and set(fitted.quantity.values) == {"p_over_nT"}
        assert fitted.sizes["row"] == read_table(data_dir / "dem_hcs_cooling.csv").values.shape[0]
        assert set(rest.where(rest.quantity != "p_over_nT", drop=True).role.values) == {"predicted"}
        # the same rows as `ktgf validate` on one file
        one = validate(get_model("dense"), [data_dir / UNIFORM_SHEAR], sources=fit_sources("dense"))
        mine = ds.where(ds.file == UNIFORM_SHEAR, drop=True)
        np.testing.assert_allclose(mine.error.values, [r["error"] for r in one.rows], rtol=1e-12)
    means = res.numbers["validation"]["dense"]
    assert means["all"]["fitted"] < means["all"]["predicted"]  # the fit set is where the model is best
    (line_dense, line_fric) = section.discuss(res.numbers)
    assert "predicted" in line_dense and "fitted" in line_fric


def test_summary_shows_fitted_and_predicted_rows_apart(tmp_path, data_dir):
    ctx = _run(tmp_path, data_dir)
    ctx.result.status = "computed"
    s = summarise([ctx.result])
    rows = [r for r in s.rows if r.regime == "validation"]
    assert {r.case.rsplit(": ", 1)[1] for r in rows} == {"fitted rows", "predicted rows"}
    assert rows[0].case.startswith("Fitted models, all DEM files")
    assert any("quote the predicted rows" in c for c in s.caveats)
    assert not any("validation" in t for t in s.recommendations)
    assert not any("Dense and Frictional" in c for c in s.caveats)  # equal at μ = 0 in the fit rows: not a ranking tie
    from ktgf.report.summary import summary_html

    page = summary_html([ctx.result])
    assert "Fitted models" in page and "<b>" not in page.split("Fitted models", 1)[1].split("</table>")[0]
