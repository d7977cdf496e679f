"""Browser-free completeness check of a written report.

A report is complete when every image and data file the page references exists in the output
folder and is whole (a PNG ends with its IEND chunk, a netCDF file starts with its signature,
and each file matches the size and SHA-256 its section's cache entry recorded), every figure and
netCDF file there is referenced, every figure links the data behind it, no reference leaves the
folder (the page is self-contained) and every expected section is on the page.
"""

from __future__ import annotations

import json
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlparse

from .framework import CACHE_DIR, DATA_DIR, FIGURE_DIR, damaged_files
from .page import FIXED_SECTIONS, PAGE_NAME, section_id


class _Refs(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.images: list[str] = []
        self.links: list[str] = []
        self.ids: set[str] = set()
        self.figures_without_data = 0
        self._in_figure = False
        self._figure_has_data = False
        self.external: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        if a.get("id"):
            self.ids.add(a["id"] or "")
        for name in ("src", "href"):
            ref = a.get(name)
            if ref and (urlparse(ref).scheme or ref.startswith("/")) and not ref.startswith("#"):
                self.external.append(ref)
        if tag == "img" and a.get("src"):
            self.images.append(unquote(a["src"] or ""))
        elif tag == "a" and a.get("href") and not (a["href"] or "").startswith("#"):
            self.links.append(unquote(a["href"] or ""))
            if self._in_figure and (a["href"] or "").endswith(".nc"):
                self._figure_has_data = True
        elif tag == "figure":
            self._in_figure, self._figure_has_data = True, False

    def handle_endtag(self, tag: str) -> None:
        if tag == "figure" and self._in_figure:
            self._in_figure = False
            if not self._figure_has_data:
                self.figures_without_data += 1


_PNG_START, _PNG_END = b"\x89PNG\r\n\x1a\n", b"IEND\xaeB`\x82"
_NC_STARTS = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")


def _broken(path: Path) -> str | None:
    """Why a figure or data file is not whole (None if it looks whole)."""
    try:
        size = path.stat().st_size
        with open(path, "rb") as fh:
            head = fh.read(8)
            fh.seek(max(0, size - 8))
            tail = fh.read(8)
    except OSError as exc:
        return f"unreadable ({exc.strerror or exc})"
    if path.suffix == ".png" and not (head == _PNG_START and tail == _PNG_END):
        return "not a complete PNG (truncated or damaged)"
    if path.suffix == ".nc" and not (size > 32 and head.startswith(_NC_STARTS)):
        return "not a complete netCDF file (empty, truncated or damaged)"
    return None


def _cache_manifests(out: Path) -> dict[str, dict]:
    """File manifests of the cache entries (file -> recorded size and hash)."""
    files: dict[str, dict] = {}
    for entry in sorted((out / CACHE_DIR).glob("*.json")):
        try:
            manifest = json.loads(entry.read_text(encoding="utf-8")).get("files", {})
        except (OSError, ValueError, AttributeError):
            continue
        if isinstance(manifest, dict):
            files.update({k: v for k, v in manifest.items() if isinstance(v, dict)})
    return files


def check_report(out: str | Path, expected_sections: list[str] | None = None) -> list[str]:
    """Problems that make the report at ``out`` incomplete (an empty list means complete).

    Parameters
    ----------
    out : path
        The report folder (holding ``index.html``).
    expected_sections : list of str, optional
        Section keys that must appear (default: the registered sections); the discussion and
        rerun sections are always required.
    """
    from .framework import sections

    out = Path(out)
    page = out / PAGE_NAME
    if not page.is_file():
        return [f"{page} does not exist"]
    parser = _Refs()
    parser.feed(page.read_text(encoding="utf-8"))
    problems: list[str] = []
    problems += [f"reference leaves the report folder: {ref}" for ref in parser.external]
    manifests = _cache_manifests(out)
    for ref in parser.images + parser.links:
        if not (out / ref).is_file():
            problems.append(f"referenced file is missing: {ref}")
            continue
        why = _broken(out / ref) or (damaged_files(out, {ref: manifests[ref]}) if ref in manifests else None)
        if why:
            problems.append(f"referenced file is damaged: {ref}: {why if isinstance(why, str) else why[0]}")
    referenced = {Path(r).as_posix() for r in parser.images + parser.links}
    for sub, pattern in ((FIGURE_DIR, "*.png"), (DATA_DIR, "*.nc")):
        for f in sorted((out / sub).rglob(pattern)):
            rel = f.relative_to(out).as_posix()
            if rel not in referenced:
                problems.append(f"file not referenced by the page: {rel}")
    if parser.figures_without_data:
        problems.append(f"{parser.figures_without_data} figure(s) without a link to their netCDF data")
    keys = expected_sections if expected_sections is not None else [s.key for s in sections()]
    for key in [*keys, *FIXED_SECTIONS]:
        if section_id(key) not in parser.ids:
            problems.append(f"section {key!r} is missing from the page")
    return problems
