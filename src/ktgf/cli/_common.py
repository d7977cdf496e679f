"""Shared CLI helpers: error reporting, list/range parsing and table/JSON/CSV output."""

from __future__ import annotations

import functools
import json
import sys
from enum import Enum
from typing import Any, Callable, Sequence

import numpy as np
import typer

from ..errors import KtgfError

EXIT_USAGE = 2


class OutputFormat(str, Enum):
    table = "table"
    json = "json"
    csv = "csv"
    markdown = "markdown"


def markdown_table(rows: Sequence[dict[str, Any]]) -> str:
    """Rows as a GitHub-flavoured Markdown table (used for the generated docs)."""
    keys = list(rows[0])
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(f"{v:.6g}" if isinstance(v, float) else str(v) for v in r.values()) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def handle_errors(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Turn user mistakes (:class:`~ktgf.errors.KtgfError`) into a one-line message and exit code 2."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except KtgfError as exc:
            typer.echo(f"Error: {exc}", err=True)
            raise typer.Exit(EXIT_USAGE) from None

    return wrapper


def parse_values(text: str, name: str) -> np.ndarray:
    """Parse ``"0.3"``, ``"0.1,0.2,0.3"`` or a range ``"start:stop:num"`` (inclusive, like linspace)."""
    from ..errors import InputError

    try:
        if ":" in text:
            parts = text.split(":")
            if len(parts) != 3:
                raise ValueError
            start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
            if num < 1:
                raise ValueError
            return np.linspace(start, stop, num)
        return np.array([float(v) for v in text.split(",") if v.strip()], dtype=float)
    except ValueError:
        raise InputError(
            f"--{name} {text!r} is not a number, a comma-separated list or a range start:stop:num"
        ) from None


def emit(rows: Sequence[dict[str, Any]], fmt: OutputFormat, title: str = "") -> None:
    """Print rows (dicts with the same keys) as a rich table, JSON, CSV or Markdown on stdout."""
    if fmt == OutputFormat.json:
        typer.echo(json.dumps(list(rows), indent=2, default=float))
        return
    if not rows:
        return
    keys = list(rows[0])
    if fmt == OutputFormat.markdown:
        typer.echo(markdown_table(rows), nl=False)
        return
    if fmt == OutputFormat.csv:
        import csv

        w = csv.DictWriter(sys.stdout, fieldnames=keys, lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow(r)
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(title=title or None)
    for k in keys:
        table.add_column(k, justify="right")
    for r in rows:
        table.add_row(*(f"{v:.6g}" if isinstance(v, float) else str(v) for v in r.values()))
    Console(width=max(120, 14 * len(keys))).print(table)


MODEL_FILE_HELP = "Model file (TOML) written by `ktgf calibrate`: a registered model with changed options."


def model_file_option() -> Any:
    """The ``--model-file FILE`` option shared by every command that takes ``--model``."""
    return typer.Option(None, "--model-file", help=MODEL_FILE_HELP)


def resolve_models(names: str | None, model_file: Any = None, *, option: str = "--model") -> list[Any]:
    """Models named by ``--model`` (comma-separated) followed by the one of ``--model-file``; at least one."""
    from ..closures import get_model
    from ..errors import InputError

    models = [get_model(n.strip()) for n in (names or "").split(",") if n.strip()]
    if model_file is not None:
        from ..calibration.model_file import load_model_file

        models.append(load_model_file(model_file).model)
    if not models:
        raise InputError(f"give a model: {option} NAME (see `ktgf models`) or --model-file FILE")
    return models
