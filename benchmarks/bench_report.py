"""Run time of ``ktgf reproduce``: quick and full report from scratch, and a rerun served from the cache.

Run as ``python benchmarks/bench_report.py``.  The target is the
issue's: ``--quick`` under 5 minutes on 2 cores (Couette and 3D sections included once available).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from ktgf.report import ReportSettings, build_report


def timed(settings: ReportSettings) -> tuple[float, dict[str, str]]:
    t0 = time.perf_counter()
    rep = build_report(settings)
    assert not rep.problems, rep.problems
    return time.perf_counter() - t0, rep.statuses


def main() -> None:
    target = 300.0
    with tempfile.TemporaryDirectory() as tmp:
        for quick in (True, False):
            out = Path(tmp) / ("quick" if quick else "full")
            fresh, statuses = timed(ReportSettings.preset(quick=quick, out=out))
            again, _ = timed(ReportSettings.preset(quick=quick, out=out))
            kind = "--quick" if quick else "full   "
            ran = ", ".join(f"{k}={v}" for k, v in statuses.items())
            print(f"{kind}: fresh {fresh:6.1f} s   cached rerun {again:5.2f} s   (rerun/fresh {again / fresh:.2f})   [{ran}]")
            if quick:
                print(f"         --quick target {target:.0f} s: {fresh / target:.1%} of the budget used")


if __name__ == "__main__":
    main()
