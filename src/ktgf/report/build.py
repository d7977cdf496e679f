"""Run every section (or take it from the cache), write the page and check it is complete."""

from __future__ import annotations

import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from .check import check_report
from .framework import (
    SectionContext,
    SectionResult,
    cache_record,
    clear_section_outputs,
    load_cached,
    log_event,
    prepare_out_dir,
    record_hash,
    sections,
    store_cached,
)
from .page import PAGE_NAME, write_page
from .settings import ReportSettings, locate_data_dir

#: progress(section_key, text, event): event "start" (text = section title), "step" (text = what runs now, from
#: SectionContext.step), then one of "computed", "cached", "unavailable" or "failed" (text = title).
Progress = Callable[[str, str, str], None]


class ReportInterrupted(KeyboardInterrupt):
    """Ctrl-C during a report run; finished sections are kept in the cache.

    Subclasses KeyboardInterrupt so that code that does not handle it still stops as on Ctrl-C.
    """

    def __init__(self, section: str, finished: list[str], out: Path) -> None:
        self.section, self.finished, self.out = section, finished, out
        kept = ", ".join(finished) if finished else "none"
        super().__init__(
            f"interrupted during section {section!r}; finished sections kept in {out} ({kept}). "
            "Run the same command again to continue from there."
        )

    def __str__(self) -> str:
        return str(self.args[0])


@dataclass
class Report:
    """Outcome of :func:`build_report`: the page, the section results and completeness problems."""

    out: Path
    page: Path
    results: list[SectionResult]
    problems: list[str] = field(default_factory=list)
    data_note: str = ""

    @property
    def statuses(self) -> dict[str, str]:
        return {r.key: r.status for r in self.results}

    @property
    def failed(self) -> list[SectionResult]:
        return [r for r in self.results if r.status == "failed"]


def empty_data_note(data_dir: Path | None, note: str) -> str:
    """The data note, replaced by a warning when the folder holds none of the DEM files the sections read."""
    if data_dir is None:
        return note
    wanted = sorted({f for s in sections() for f in s.data_files})
    if wanted and not any((data_dir / f).is_file() for f in wanted):
        return (f"WARNING: the DEM data folder {data_dir} holds none of the reference files ({', '.join(wanted)}): "
                "comparisons with particle simulations are left out")
    return note


def build_report(settings: ReportSettings, *, progress: Progress | None = None, argv: list[str] | None = None) -> Report:
    """Build (or complete) the report described by ``settings`` in ``settings.out``.

    Sections whose cached result matches their inputs are not recomputed.  A section that
    raises is shown as failed on the page (with its error) and not cached; Ctrl-C raises
    :class:`ReportInterrupted` after removing the half-written outputs of the current section.
    ``argv`` is the command line shown in the page's rerun table.
    """
    out = prepare_out_dir(settings.out)
    data_dir, data_note = locate_data_dir(settings.data_dir)
    data_note = empty_data_note(data_dir, data_note)
    tell = progress or (lambda *a: None)
    results: list[SectionResult] = []
    finished: list[str] = []
    for sec in sections():
        tell(sec.key, sec.title, "start")
        reason = sec.available()
        if reason:
            clear_section_outputs(out, sec.key)  # outputs of an earlier build with that package would be orphans
            results.append(SectionResult(sec.key, sec.title, status="unavailable", reason=reason))
            log_event(out, sec.key, "unavailable")
            tell(sec.key, sec.title, "unavailable")
            continue
        record = cache_record(sec, settings, data_dir)
        digest = record_hash(record)
        cached = load_cached(out, sec.key, digest)
        if cached is not None:
            results.append(cached)
            finished.append(sec.key)
            log_event(out, sec.key, "cached", digest)
            tell(sec.key, sec.title, "cached")
            continue
        clear_section_outputs(out, sec.key)
        ctx = SectionContext(sec, settings, out, data_dir, record["inputs"], progress=tell)
        try:
            sec.run(ctx)
        except KeyboardInterrupt:
            clear_section_outputs(out, sec.key)
            log_event(out, sec.key, "interrupted", digest)
            raise ReportInterrupted(sec.key, finished, out) from None
        except Exception as exc:  # a failing section must not take the others down
            clear_section_outputs(out, sec.key)
            last = traceback.extract_tb(exc.__traceback__)[-1]
            results.append(SectionResult(
                sec.key, sec.title, status="failed",
                reason=f"{type(exc).__name__}: {exc} (at {Path(last.filename).name}:{last.lineno})",
            ))
            log_event(out, sec.key, "failed", digest)
            tell(sec.key, sec.title, "failed")
            continue
        store_cached(out, ctx.result, digest, record)
        results.append(ctx.result)
        finished.append(sec.key)
        log_event(out, sec.key, "computed", digest)
        tell(sec.key, sec.title, "computed")
    page = write_page(out, results, settings, data_dir=data_dir, data_note=data_note, argv=argv)
    problems = check_report(out, expected_sections=[s.key for s in sections()])
    return Report(out, page, results, problems, data_note)


__all__ = ["PAGE_NAME", "Report", "ReportInterrupted", "build_report"]
