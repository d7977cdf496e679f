"""The one parser of the shared DEM file format: '#' header lines, a row of column titles, then CSV numbers.

Every problem with a file (missing, not a numeric table, a missing column, NaN, units other than
d = m = 1) raises :class:`~ktgf.errors.InputError` with one line naming the file and the field.
The typed readers of :mod:`ktgf.data.formats` are built on :func:`read_table`.
"""

from __future__ import annotations

import hashlib
import io
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError


def file_hash(path: str | Path) -> str:
    """SHA-256 of a data file's bytes (the provenance of a calibration or a report section)."""
    return hashlib.sha256(resolve(path).read_bytes()).hexdigest()


@dataclass(frozen=True)
class Table:
    """A DEM file: its header lines (without '#'), column titles and the float table (rows × columns)."""

    path: Path
    header: tuple[str, ...]
    names: tuple[str, ...]
    values: np.ndarray

    @property
    def name(self) -> str:
        return self.path.name

    def has(self, *columns: str) -> bool:
        return all(c in self.names for c in columns)

    def columns(self, needed: tuple[str, ...] | list[str], rows: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """The named columns (restricted to ``rows``), checked to exist and to hold finite numbers."""
        missing = [c for c in needed if c not in self.names]
        if missing:
            raise InputError(f"data file {self.name}: missing column(s) {', '.join(missing)} "
                             f"(columns present: {', '.join(self.names)})")
        out = {}
        for c in needed:
            v = self.values[:, self.names.index(c)]
            v = v if rows is None else v[rows]
            bad = np.flatnonzero(~np.isfinite(v))
            if bad.size:
                raise InputError(f"data file {self.name}: column {c} holds NaN or a non-number in data row {int(bad[0]) + 1}")
            out[c] = v
        return out

    def column(self, name: str, rows: np.ndarray | None = None) -> np.ndarray:
        return self.columns((name,), rows)[name]

    def as_dict(self) -> dict[str, np.ndarray]:
        """Every column by title (values as read, NaN allowed)."""
        return {n: self.values[:, i] for i, n in enumerate(self.names)}

    def records(self) -> list[dict[str, float]]:
        """The rows as dicts of floats keyed by column title."""
        return [dict(zip(self.names, map(float, row))) for row in self.values]


def resolve(path: str | Path) -> Path:
    """A data file's path: the path itself, or, for the bare name of a file shipped with ktgf that is not a file
    in the working folder (``dem_uniform_shear.csv``), the shipped copy."""
    from .files import shipped, shipped_data_dir

    path = Path(path)
    if not path.is_file() and path.name == str(path) and shipped(path.name).is_file():
        return shipped(path.name)
    if not path.is_file():
        names = ", ".join(sorted(p.name for p in shipped_data_dir().glob("*.csv")))
        raise InputError(f"data file {str(path)!r} does not exist (files shipped with ktgf, usable by name: {names})")
    return path


def read_table(path: str | Path) -> Table:
    """Read a DEM CSV file (``data/dem/README.md`` format) into a :class:`Table`; a bare shipped name reads
    the shipped copy (:func:`resolve`)."""
    path = resolve(path)
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    header = tuple(ln[1:].strip() for ln in lines if ln.startswith("#"))
    body = [ln for ln in lines if ln.strip() and not ln.startswith("#")]
    if len(body) < 2:
        raise InputError(f"data file {path.name}: no data rows after the column-title row")
    names = tuple(n.strip() for n in body[0].split(","))
    try:
        values = np.genfromtxt(io.StringIO("\n".join(body[1:])), delimiter=",", dtype=float, ndmin=2)
    except ValueError as exc:
        raise InputError(f"data file {path.name}: rows are not a numeric table ({exc})") from None
    if values.shape[1] != len(names):
        raise InputError(f"data file {path.name}: {values.shape[1]} values per row but {len(names)} column titles")
    return Table(path, header, names, values)


_UNIT = r"\s*=\s*(?:m\s*=\s*)?([-+\d.eE]+)\s*([A-Za-z]*)"


def _unit_is_one(text: str, symbol: str) -> bool:
    """``symbol = 1`` (or ``d = m = 1``) stated without a unit word after the number."""
    m = re.search(rf"(?<![A-Za-z_]){symbol}{_UNIT}", text)
    if m is None:
        return False
    try:
        return float(m.group(1)) == 1.0 and not m.group(2)
    except ValueError:
        return False


def check_units(table: Table, *, shear_rate: bool) -> None:
    """The header must state d = m = 1 (and γ̇ = 1 for uniform shear): the units reduced values are compared in."""
    units = [ln for ln in table.header if ln.lower().lstrip().startswith("units")]
    if not units:
        raise InputError(f"data file {table.name}: header states no units (expected a line 'units d = m = 1 ...')")
    text = " ".join(units)
    m_ok = _unit_is_one(text, "m") or re.search(r"(?<![A-Za-z_])d\s*=\s*m\s*=\s*1(?![\d.])", text) is not None
    if not (_unit_is_one(text, "d") and m_ok):
        raise InputError(f"data file {table.name}: units {units[0]!r} do not match the shared format (d = m = 1)")
    if shear_rate and not _unit_is_one(" ".join(table.header), "gdot"):
        raise InputError(f"data file {table.name}: header does not state the shear rate gdot = 1 the columns are scaled with")
