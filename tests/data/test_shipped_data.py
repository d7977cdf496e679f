"""The DEM reference files ship inside the package: every file parses with its reader, the copies match
``shared/data`` (their source) where that folder is present, and runs find them without any setting."""

from __future__ import annotations

from pathlib import Path

import pytest

from ktgf.data import (
    COUETTE, DEM_FILES, FRICTION_SHEAR, FRICTION_SHEAR_EXTRA, HCS_COOLING, UNIFORM_SHEAR, UNIFORM_SHEAR_EXTRA,
    locate_data_dir, read_cooling, read_couette, read_friction_shear, read_uniform_shear, shipped, shipped_data_dir,
)
from ktgf.errors import InputError

SHARED = Path(__file__).resolve().parents[3] / "shared" / "data"


@pytest.mark.regression
def test_every_shipped_file_is_read_by_its_reader() -> None:
    """Regression (format): each file of the shared formats parses, with the rows its README lists."""
    assert list(read_uniform_shear(shipped(UNIFORM_SHEAR)).phi) == [0.3, 0.5]
    assert sorted(read_uniform_shear(shipped(UNIFORM_SHEAR_EXTRA)).phi) == [0.4, 0.45, 0.55, 0.58, 0.6]
    base = read_friction_shear(shipped(FRICTION_SHEAR))
    assert sorted((r["mu"], r["phi"]) for r in base) == [(0.0, 0.5), (0.5, 0.4), (0.5, 0.5)]
    extra = read_friction_shear(shipped(FRICTION_SHEAR_EXTRA))
    assert sorted(r["phi"] for r in extra if r["mu"] == 0.5) == [0.3, 0.45, 0.52, 0.55, 0.57]
    assert read_couette(shipped(COUETTE)).case.mean_phi == pytest.approx(0.5)
    assert read_cooling(shipped(HCS_COOLING))["phi"].size >= 10
    readme = (shipped_data_dir() / "README.md").read_text()
    for name in DEM_FILES:
        assert name.split(".csv")[0].split("_extra")[0] in readme


@pytest.mark.contract
def test_shipped_copies_are_those_of_shared_data() -> None:
    """The package carries byte-identical copies of ``shared/data`` (copy them again when they change)."""
    if not SHARED.is_dir():  # a clone without shared/: nothing to compare the copies with
        return
    for name in (*DEM_FILES, "README.md"):
        assert shipped(name).read_bytes() == (SHARED / name).read_bytes(), f"{name}: copy shared/data/{name} into src/ktgf/data/dem/"
    assert {p.name for p in SHARED.glob("*.csv")} == set(DEM_FILES), "a new file in shared/data: ship it (ktgf.data.files)"


@pytest.mark.contract
def test_runs_find_the_shipped_files_unless_told_otherwise(tmp_path, monkeypatch) -> None:
    monkeypatch.delenv("KTGF_DATA", raising=False)
    found, why = locate_data_dir(None)
    assert found == shipped_data_dir() and "shipped" in why
    monkeypatch.setenv("KTGF_DATA", str(tmp_path))
    assert locate_data_dir(None)[0] == tmp_path.resolve()
    assert locate_data_dir(tmp_path / "absent")[0] is None  # an explicit folder that is not there: said, not raised


@pytest.mark.contract
def test_one_parser_gives_one_line_errors(tmp_path) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("# units d = m = 1, gdot = 1\nphi,e,T\n0.3,0.9\n")
    with pytest.raises(InputError, match=r"^data file bad.csv: 2 values per row but 3 column titles$"):
        read_uniform_shear(bad)
    with pytest.raises(InputError, match="does not exist"):
        read_couette(tmp_path / "none.csv")
    (tmp_path / "c.csv").write_text("# units d = m = 1; shear rate gdot = 1\nmu,phi,e,T\n0.5,0.4,0.7,0.1\n")
    with pytest.raises(InputError, match="missing column"):
        read_friction_shear(tmp_path / "c.csv")


@pytest.mark.contract
def test_a_shipped_file_is_read_by_its_bare_name(tmp_path, monkeypatch) -> None:
    """``--data dem_uniform_shear.csv`` works from any folder; a file of that name in the folder wins."""
    monkeypatch.chdir(tmp_path)
    assert read_uniform_shear(UNIFORM_SHEAR).path == shipped(UNIFORM_SHEAR)
    own = tmp_path / UNIFORM_SHEAR
    own.write_text(shipped(UNIFORM_SHEAR).read_text().replace("0.3,0.9,864", "0.35,0.9,864"))
    assert list(read_uniform_shear(UNIFORM_SHEAR).phi) == [0.35, 0.5]
    with pytest.raises(InputError, match="usable by name: dem_couette"):
        read_uniform_shear("dem_other.csv")
