"""``ktgf reproduce``: run the paper's model comparisons and write the report page."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Optional

import typer

from ._common import handle_errors

EXIT_INTERRUPTED = 130
DEFAULT_OUT = Path("ktgf-report")


@handle_errors
def reproduce(
    out: Path = typer.Option(DEFAULT_OUT, "--out", "-o", help="Output folder (index.html, figures/, data/)."),
    quick: bool = typer.Option(False, "--quick", help="Coarse grids and fewer points (< 5 min on 2 cores; what CI runs)."),
    data: Optional[Path] = typer.Option(None, "--data", help="DEM reference data folder (default: $KTGF_DATA, else ../shared/data)."),
    config: Optional[Path] = typer.Option(None, "--config", "-c", help="TOML file of report settings (setting = value; see the page's Settings table)."),
    set_: list[str] = typer.Option([], "--set", metavar="KEY=VALUE", help="Override one setting, key=value (repeatable), e.g. --set cooling_phi=0.5 --set models=ret,proposed."),
) -> None:
    """Run the model comparisons of the paper and write a self-contained HTML report.

    Finished sections are cached in OUT/.cache under a hash of their inputs: after Ctrl-C or a
    change of settings, the same command continues from what was already computed.
    """
    from rich.console import Console
    from rich.markup import escape
    from rich.text import Text
    from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    from ..report import ReportInterrupted, ReportSettings, build_report, sections
    from ..report.framework import prepare_out_dir

    from ..report.build import empty_data_note
    from ..report.settings import locate_data_dir

    settings = ReportSettings.from_sources(quick=quick, config=config, sets=set_, out=out if out != DEFAULT_OUT or config is None else None,
                                           data_dir=data)
    prepare_out_dir(settings.out)  # an unwritable folder fails here, in one line, before any work
    console = Console(stderr=True)
    note = empty_data_note(*locate_data_dir(settings.data_dir))
    if note.startswith("WARNING"):
        console.print(Text(note), style="yellow")
    secs = sections()
    words = {"computed": "[green]computed", "cached": "[cyan]cached (inputs unchanged)",
             "unavailable": "[yellow]not available in this build", "failed": "[red]FAILED"}
    t0 = time.perf_counter()
    with Progress(SpinnerColumn(), TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                  TimeElapsedColumn(), console=console, transient=False) as bar:
        task = bar.add_task("sections", total=len(secs))
        started: dict[str, float] = {}
        titles: dict[str, str] = {}

        def progress(key: str, title: str, event: str) -> None:
            if event == "start":
                started[key] = time.perf_counter()
                titles[key] = title
                bar.update(task, description=f"{title} …")
                return
            if event == "step":
                bar.update(task, description=f"{titles.get(key, key)}: {title} …")
                return
            dt = time.perf_counter() - started.get(key, time.perf_counter())
            bar.console.print(f"  {escape(title)}: {words.get(event, event)}[/] ({dt:.1f} s)")
            bar.advance(task)

        try:
            report = build_report(settings, progress=progress, argv=["ktgf", *sys.argv[1:]] if sys.argv[1:2] == ["reproduce"] else None)
        except ReportInterrupted as exc:
            bar.stop()
            console.print(f"[bold red]Interrupted[/]: {escape(str(exc))}")
            raise typer.Exit(EXIT_INTERRUPTED) from None
    console.print(Text(f"Report written to {report.page} in {time.perf_counter() - t0:.1f} s; {report.data_note}."))
    if report.problems:
        console.print("[red]The report is incomplete:[/] " + escape("; ".join(report.problems)))
        raise typer.Exit(1)
    if report.failed:
        console.print("[red]Failed sections:[/] " + escape("; ".join(f"{r.key}: {r.reason}" for r in report.failed)))
        raise typer.Exit(1)
    console.print("Completeness check passed: every figure file exists and is referenced, every section is present.")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("reproduce")(reproduce)
