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
#: Most points one option or sweep may ask for (a float64 array of them is 80 MB).
MAX_POINTS = 10_000_000


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
        except MemoryError as exc:  # a request the checks below did not foresee: refuse, do not crash
            typer.echo(f"Error: not enough memory for this request ({exc or 'MemoryError'}); ask for fewer points",
                       err=True)
            raise typer.Exit(EXIT_USAGE) from None

    return wrapper


def check_points(n: int, what: str) -> None:
    """Refuse a request of more than :data:`MAX_POINTS` points, with its memory estimate."""
    from ..errors import InputError

    if n > MAX_POINTS:
        raise InputError(f"{what} asks for {n:.3g} points (one float64 array of them is {8 * n / 1e9:.3g} GB): "
                         f"valid at most {MAX_POINTS:.0e} points")


def parse_values(text: str, name: str) -> np.ndarray:
    """Parse ``"0.3"``, ``"0.1,0.2,0.3"`` or a range ``"start:stop:num"`` (inclusive, like linspace).

    Empty lists, non-finite values and ranges of more than :data:`MAX_POINTS` points are refused.
    """
    from ..errors import InputError

    try:
        if ":" in text:
            parts = text.split(":")
            if len(parts) != 3:
                raise ValueError
            start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
            if num < 1:
                raise ValueError
            values = None  # built below, once its size is checked
        else:
            values = np.array([float(v) for v in text.split(",") if v.strip()], dtype=float)
    except ValueError:
        raise InputError(
            f"--{name} {text!r} is not a number, a comma-separated list or a range start:stop:num"
        ) from None
    if values is None:
        check_points(num, f"--{name} {text!r}")
        values = np.linspace(start, stop, num)
    if values.size == 0:
        raise InputError(f"--{name} {text!r} gives no value: give a number, a list a,b,c or a range start:stop:num")
    if not np.isfinite(values).all():
        raise InputError(f"--{name} {text!r} holds a non-finite value ({values[~np.isfinite(values)][0]:g})")
    return values


def parse_names(text: str, name: str) -> list[str]:
    """Comma-separated names (blanks dropped); an empty list is refused."""
    from ..errors import InputError

    names = [n for n in (s.strip() for s in text.split(",")) if n]
    if not names:
        raise InputError(f"--{name} {text!r} names nothing: give one or more comma-separated names")
    return names


def _strict_json(x: Any) -> Any:
    """JSON has no infinities or NaN: NaN becomes null, ±inf the strings "inf" / "-inf"."""
    if isinstance(x, dict):
        return {k: _strict_json(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_strict_json(v) for v in x]
    if isinstance(x, (np.generic, np.ndarray)):
        return _strict_json(x.tolist())
    if isinstance(x, float) and not np.isfinite(x):
        return None if np.isnan(x) else ("inf" if x > 0 else "-inf")
    return x


def emit(rows: Sequence[dict[str, Any]], fmt: OutputFormat, title: str = "") -> None:
    """Print rows (dicts with the same keys) as a rich table, JSON, CSV or Markdown on stdout.

    JSON is strict (RFC 8259): NaN is written as ``null`` and ±infinity as the strings
    ``"inf"`` / ``"-inf"`` (e.g. the critical size of a stable state).
    """
    if fmt == OutputFormat.json:
        typer.echo(json.dumps(_strict_json(list(rows)), indent=2, allow_nan=False, default=str))
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
