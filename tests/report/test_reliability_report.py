"""The report cache verifies its files: a damaged figure or data file behind a cached section is
detected by the completeness check and recomputed by the next build (issue 11)."""

from __future__ import annotations

import dataclasses
import functools
import json
import shutil
from pathlib import Path

import pytest

from ktgf.report import ReportSettings, build_report, check_report, framework

pytestmark = pytest.mark.contract


def _counting(monkeypatch: pytest.MonkeyPatch, key: str) -> list[int]:
    sec = framework._SECTIONS[key]
    calls: list[int] = []

    @functools.wraps(sec.run)  # keeps __module__, so the cache key is the real section's
    def run(ctx):
        calls.append(1)
        return sec.run(ctx)

    monkeypatch.setitem(framework._SECTIONS, key, dataclasses.replace(sec, run=run))
    return calls


def _truncate(p: Path) -> None:
    p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])


def _empty(p: Path) -> None:
    p.write_bytes(b"")


def _flip_middle(p: Path) -> None:  # same size, other content: only the recorded hash sees it
    raw = bytearray(p.read_bytes())
    raw[len(raw) // 2] ^= 0x01
    p.write_bytes(bytes(raw))


@pytest.mark.parametrize("suffix, damage", [(".png", _truncate), (".nc", _empty), (".png", _flip_middle),
                                            (".nc", _flip_middle)])
def test_damaged_file_behind_a_cached_section_is_found_and_recomputed(
        suffix: str, damage, quick_report, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "r"
    shutil.copytree(quick_report.out, out)
    entry = json.loads((out / ".cache" / "hcs.json").read_text())
    victim = next(f for f in entry["files"] if f.endswith(suffix))
    before = entry["files"][victim]
    damage(out / victim)
    problems = check_report(out)
    assert any(victim in p and "damaged" in p for p in problems), problems
    calls = {k: _counting(monkeypatch, k) for k in ("coefficients", "hcs")}
    again = build_report(ReportSettings.preset(quick=True, out=out))
    assert (len(calls["coefficients"]), len(calls["hcs"])) == (0, 1)
    assert again.statuses["hcs"] == "computed" and again.problems == [] and check_report(out) == []
    assert framework.file_digest(out / victim)["size"] == before["size"]


def test_cache_entries_record_size_and_hash_of_every_file(quick_report) -> None:
    for key in ("coefficients", "hcs"):
        entry = json.loads((quick_report.out / ".cache" / f"{key}.json").read_text())
        result = framework.SectionResult.from_json(entry["result"])
        assert set(entry["files"]) == set(result.files()) and result.files()
        for rel, rec in entry["files"].items():
            assert rec == framework.file_digest(quick_report.out / rel)
