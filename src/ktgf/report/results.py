"""What a report section produces (figures, tables, numbers), in a JSON-serialisable form the cache stores.

The bottom of :mod:`ktgf.report`: the framework, the page and the summary all read these types.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

#: File name of the report page in its output folder.
PAGE_NAME = "index.html"
#: The page's ``<meta name="generator">``: a folder holding an index.html without it is not ktgf's.
GENERATOR = "ktgf reproduce"


@dataclass
class FigureRef:
    """A figure file (path relative to the output folder), its caption and its data file."""

    file: str
    caption: str
    data: str | None = None


@dataclass
class TableData:
    """A small table: column titles and rows of plain values (numbers are formatted on the page)."""

    title: str
    columns: list[str]
    rows: list[list[Any]]
    note: str = ""
    figure: str | None = None  # file of the figure it is shown beside (None: end of the section)


@dataclass
class SectionResult:
    """Everything a section produced, in a JSON-serialisable form (what the cache stores).

    ``status`` is ``computed`` (this run), ``cached`` (read back), ``unavailable`` (its package
    is not part of this build; ``reason`` says why) or ``failed`` (``reason`` holds the error).
    """

    key: str
    title: str
    status: str = "computed"
    reason: str = ""
    paragraphs: list[str] = field(default_factory=list)
    figures: list[FigureRef] = field(default_factory=list)
    tables: list[TableData] = field(default_factory=list)
    numbers: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    datasets: list[str] = field(default_factory=list)
    inputs: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> SectionResult:
        d = dict(d)
        d["figures"] = [FigureRef(**f) for f in d.get("figures", [])]
        d["tables"] = [TableData(**t) for t in d.get("tables", [])]
        return cls(**d)

    def files(self) -> list[str]:
        """Every file the section wrote (relative paths)."""
        return [f.file for f in self.figures] + list(self.datasets)
