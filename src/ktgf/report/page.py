"""The report page: one self-contained HTML file (figures as PNG beside it, tables as HTML).

Pictures first, numbers beside them: each section shows its figures with captions and a link to
the netCDF data behind each, then its tables.  The page ends with the discussion generated from
the numbers and everything needed to rerun it.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import html
import json
import math
import platform
import sys
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

from .._version import __version__
from .framework import _atomic_write, sections
from .results import GENERATOR, PAGE_NAME, SectionResult, TableData
from .settings import ReportSettings
from .summary import summary_html

#: The page is meant to be shared: readable by everyone, like the figures beside it.
PAGE_MODE = 0o644
#: Sections every page has besides the registered ones (generated at page time, never cached).
FIXED_SECTIONS = ("summary", "discussion", "rerun")
def closing_titles(n_sections: int) -> tuple[str, str]:
    """Titles of the two closing parts, numbered after the ``n_sections`` result sections."""
    return f"{n_sections + 1}. Discussion", f"{n_sections + 2}. How to rerun"
PACKAGES = ("numpy", "scipy", "xarray", "netCDF4", "h5netcdf", "matplotlib", "jax", "pydantic", "typer")

_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;max-width:1150px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{margin-bottom:.2em} h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:2em}
figure{margin:1.2em 0;padding:.5em;border:1px solid #e3e3e3;border-radius:4px}
figure img{max-width:100%;height:auto;display:block;margin:auto}
figcaption{font-size:.92em;color:#444;margin-top:.4em}
table{border-collapse:collapse;margin:.8em 0;font-size:.9em}
th,td{border:1px solid #ccc;padding:.25em .6em;text-align:right} th{background:#f3f3f3}
td.l,th.l{text-align:left} table.summary td b{color:#0a5} caption{font-weight:600;text-align:left;padding:.3em 0}
.note{background:#fff7d6;border-left:4px solid #e0b000;padding:.5em .8em;margin:.6em 0}
.na{background:#eef3fb;border-left:4px solid #5b8bd0;padding:.5em .8em;margin:.6em 0}
.fail{background:#fde8e8;border-left:4px solid #c33;padding:.5em .8em;margin:.6em 0}
.status{color:#777;font-size:.85em} code,pre{background:#f6f6f6;padding:.1em .3em;border-radius:3px}
pre{padding:.6em;overflow-x:auto}
nav ul{columns:2;list-style:none;padding-left:1em}
"""


def section_id(key: str) -> str:
    return f"sec-{key}"


def fmt(v: Any) -> str:
    """A table cell: numbers to 4 significant digits, the rest as text."""
    if isinstance(v, bool) or v is None:
        return "—" if v is None else str(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "—"
        if math.isinf(v):
            return "∞" if v > 0 else "−∞"
        return f"{v:.4g}"
    return str(v)


def _table(t: TableData) -> str:
    head = "".join(f'<th class="{"l" if i == 0 else ""}">{html.escape(c)}</th>' for i, c in enumerate(t.columns))
    body = "".join(
        "<tr>" + "".join(f'<td class="{"l" if i == 0 else ""}">{html.escape(fmt(v))}</td>' for i, v in enumerate(r)) + "</tr>"
        for r in t.rows
    )
    note = f'<p class="status">{html.escape(t.note)}</p>' if t.note else ""
    return f"<table><caption>{html.escape(t.title)}</caption><tr>{head}</tr>{body}</table>{note}"


def _section(r: SectionResult) -> str:
    parts = [f'<section id="{section_id(r.key)}"><h2>{html.escape(r.title)}</h2>']
    if r.status == "unavailable":
        parts.append(f'<p class="na"><b>Not available in this build.</b> {html.escape(r.reason)}</p>')
    elif r.status == "failed":
        parts.append(f'<p class="fail"><b>This section failed</b> and is not cached: <code>{html.escape(r.reason)}</code></p>')
    else:
        when = "computed in this run" if r.status == "computed" else "taken from the cache (inputs unchanged)"
        parts.append(f'<p class="status">Results {when}.</p>')
    parts += [f'<p class="note">{html.escape(n)}</p>' for n in r.notes]
    parts += [f"<p>{html.escape(p)}</p>" for p in r.paragraphs]
    figs = {f.file for f in r.figures}
    for f in r.figures:
        data = f' <a href="{html.escape(f.data)}">data (netCDF)</a>' if f.data else ""
        parts.append(
            f'<figure><img src="{html.escape(f.file)}" alt="{html.escape(f.caption)}" loading="lazy">'
            f"<figcaption>{html.escape(f.caption)}{data}</figcaption></figure>"
        )
        parts += [_table(t) for t in r.tables if t.figure == f.file]
    parts += [_table(t) for t in r.tables if t.figure not in figs]
    extra = [d for d in r.datasets if d not in {f.data for f in r.figures}]
    if extra:
        links = ", ".join(f'<a href="{html.escape(d)}">{html.escape(Path(d).name)}</a>' for d in extra)
        parts.append(f"<p>Further data behind this section's tables: {links}</p>")
    parts.append("</section>")
    return "\n".join(parts)


def _discussion(results: list[SectionResult]) -> str:
    by_key = {s.key: s for s in sections()}
    title = closing_titles(len(results))[0]
    parts = [f'<section id="{section_id("discussion")}"><h2>{title}</h2>',
             "<p class=\"status\">Generated from the numbers of the sections above.</p>"]
    sub = 0
    for r in results:
        sec = by_key.get(r.key)
        if r.status in ("computed", "cached") and sec is not None:
            sentences = sec.discuss(r.numbers)
            if sentences:
                sub += 1  # numbered within the discussion (6.1, 6.2, ...), not with the section numbers again
                parts.append(f"<h3>{title.split('.')[0]}.{sub} {html.escape(_unnumbered(r.title))}</h3>")
                parts += [f"<p>{html.escape(s)}</p>" for s in sentences]
        elif r.status == "unavailable":
            parts.append(f"<p><b>{html.escape(r.title)}</b>: not available in this build, so not discussed.</p>")
        elif r.status == "failed":
            parts.append(f"<p><b>{html.escape(r.title)}</b>: failed in this run, so not discussed.</p>")
    parts.append("</section>")
    return "\n".join(parts)


def _unnumbered(title: str) -> str:
    """'2. Homogeneous cooling state' -> 'Homogeneous cooling state'."""
    head, _, rest = title.partition(". ")
    return rest if head.isdigit() and rest else title


def _pkg_version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


def _rerun(results: list[SectionResult], settings: ReportSettings, data_dir: Path | None, data_note: str,
           argv: list[str] | None) -> str:
    from ..closures.models import get_model

    command = " ".join(argv) if argv else settings.rerun_options()
    parts = [f'<section id="{section_id("rerun")}"><h2>{closing_titles(len(results))[1]}</h2>',
             f"<p>Command: <code>{html.escape(command)}</code> (a rerun reuses cached sections whose inputs are unchanged; "
             "delete the <code>.cache</code> folder to recompute everything).</p>"]
    versions = [["ktgf", __version__], ["python", platform.python_version()], ["platform", platform.platform()]]
    versions += [[p, _pkg_version(p)] for p in PACKAGES]
    parts.append(_table(TableData("Versions", ["package", "version"], versions)))
    fields = type(settings).model_fields
    rows = [[k, json.dumps(v, default=str), fields[k].description or ""] for k, v in settings.model_dump(mode="json").items()]
    parts.append(_table(TableData("Settings", ["setting", "value", "meaning"], rows)))
    names = list(dict.fromkeys([*settings.models, *settings.cooling_models]))
    mrows = []
    for n in names:
        m = get_model(n)
        md = m.metadata()
        mrows.append([n, m.label, md["theory"], md["rdf"], md["viscosity_law"], md["model_options"], md["theory_reference"]])
    parts.append(_table(TableData("Models and their options", ["name", "label", "theory", "RDF", "viscosity law", "options", "reference"], mrows)))
    parts.append(f"<p>{html.escape(data_note)}.</p>")
    files = sorted({f for s in sections() for f in s.data_files})
    drows = []
    for f in files:
        p = data_dir / f if data_dir else None
        if p is not None and p.is_file():
            drows.append([f, "used", hashlib.sha256(p.read_bytes()).hexdigest()[:16]])
        else:
            drows.append([f, "absent", "—"])
    if drows:
        parts.append(_table(TableData("DEM reference files (LAMMPS; see the data folder's README)", ["file", "status", "sha256 (first 16)"], drows)))
    srows = [[r.key, r.status, r.reason] for r in results]
    parts.append(_table(TableData("Sections in this run", ["section", "status", "reason"], srows)))
    parts.append("</section>")
    return "\n".join(parts)


def write_page(out: Path, results: list[SectionResult], settings: ReportSettings, *, data_dir: Path | None,
               data_note: str, argv: list[str] | None = None) -> Path:
    """Write ``out/index.html`` for ``results`` and return its path."""
    now = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    data_empty = data_dir is not None and not any((data_dir / f).is_file() for s in sections() for f in s.data_files)
    kind = "quick (coarse) run" if settings.quick else "full run"
    toc = "".join(f'<li><a href="#{section_id(r.key)}">{html.escape(r.title)}</a></li>' for r in results)
    toc = f'<li><a href="#{section_id("summary")}">Summary</a></li>' + toc
    discussion, rerun = closing_titles(len(results))
    toc += f'<li><a href="#{section_id("discussion")}">{discussion}</a></li><li><a href="#{section_id("rerun")}">{rerun}</a></li>'
    body = "\n".join(_section(r) for r in results)
    doc = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="{GENERATOR}">
<title>ktgf model comparison report</title><style>{_CSS}</style></head>
<body>
<h1>Continuum models of dense inelastic granular flow: model comparison</h1>
<p class="status">ktgf {html.escape(__version__)} · {kind} · written {now} · python {html.escape(sys.version.split()[0])}</p>
{"" if data_dir is not None and not data_empty else f'<p class="note">{html.escape(data_note)}.</p>'}
{summary_html(results)}
<p>Four kinetic-theory closure models are compared: the classic Enskog/Lun et al. (1984) theory, the revised
Enskog theory of Garzó &amp; Dufty (1999, "RET"), Lun's theory with a viscosity that diverges faster at random
close packing ("Visc.div.", Bocquet et al. 2001) and RET with a radial distribution function derived from that
viscosity divergence ("Proposed"). Each figure links the netCDF file with the numbers behind it.</p>
<nav><ul>{toc}</ul></nav>
{body}
{_discussion(results)}
{_rerun(results, settings, data_dir, data_note, argv)}
</body></html>
"""
    page = out / PAGE_NAME
    _atomic_write(page, doc)
    page.chmod(PAGE_MODE)  # the temporary file behind the atomic write is private (0600); the page is for sharing
    return page
