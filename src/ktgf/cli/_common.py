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


#: Help of every ``--model`` option (comma-separated registry names; default: the paper's four models).
MODEL_HELP = ("Model name(s) from `ktgf models`, comma-separated (default: the paper's four models, "
              "or only the --model-file model when that is given).")
#: Help of every ``--dask`` option (the one name for running on a Dask cluster).
DASK_HELP = "Address of a Dask distributed scheduler to run on (e.g. tcp://host:8786)."


def deprecated_alias(value: Any, old_value: Any, old: str, new: str) -> Any:
    """The value of option ``new``, or of its hidden deprecated name ``old`` (with a warning on stderr)."""
    from ..errors import InputError

    if old_value is None:
        return value
    if value is not None:
        raise InputError(f"{old} is the deprecated name of {new}: give only {new}")
    typer.echo(f"Warning: {old} is deprecated, use {new}.", err=True)
    return old_value


#: How every list-valued option is written (one sentence for all help texts).
VALUES_HELP = "a value, a list a,b,c, a linear range start:stop:num or a log range log:start:stop:num"


def parse_values(text: str, name: str) -> np.ndarray:
    """Parse ``"0.3"``, ``"0.1,0.2,0.3"``, ``"start:stop:num"`` (linspace) or ``"log:start:stop:num"`` (geomspace).

    Both ranges include their ends; a log range needs start, stop > 0.  Anything else raises
    :class:`~ktgf.errors.InputError` naming the option.
    """
    from ..errors import InputError

    text = text.strip()
    try:
        if ":" in text:
            parts = [p.strip() for p in text.split(":")]
            log = parts[0].lower() == "log"
            if log:
                parts = parts[1:]
            if len(parts) != 3:
                raise ValueError
            start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
            if num < 1:
                raise ValueError
            values = None  # built below, once its size is checked
        else:
            values = np.array([float(v) for v in text.split(",") if v.strip()], dtype=float)
    except ValueError:
        raise InputError(f"--{name} {text!r} is not {VALUES_HELP}") from None
    if values is None:
        check_points(num, f"--{name} {text!r}")
        if log and (start <= 0 or stop <= 0):
            raise InputError(f"--{name} {text!r}: a log range needs start > 0 and stop > 0")
        values = np.geomspace(start, stop, num) if log else np.linspace(start, stop, num)
    if values.size == 0:
        raise InputError(f"--{name} {text!r} gives no value: give {VALUES_HELP}")
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
    from rich.text import Text

    # Text objects, not strings: Rich would read "[s]" or "[kg/(m s)]" in a header as markup and drop it.
    table = Table(title=Text(title) if title else None)
    for k in keys:
        numeric = all(isinstance(r[k], (int, float)) and not isinstance(r[k], bool) for r in rows)
        # wide enough for the longest word (a name such as "carnahan-starling()" is not split), fold beyond
        word = max((len(w) for r in rows for w in str(r[k]).split()), default=1) if not numeric else None
        table.add_column(Text(k), justify="right" if numeric else "left", overflow="fold", min_width=min(word, 40) if word else None)
    for r in rows:
        table.add_row(*(Text(f"{v:.6g}" if isinstance(v, float) else str(v)) for v in r.values()))
    need = sum(max(c.min_width or 0, 12) + 3 for c in table.columns) + 1  # never crop a column
    Console(width=max(120, need)).print(table)


MODEL_FILE_HELP = "Model file (TOML) written by `ktgf calibrate`: a registered model with changed options."


def model_file_option() -> Any:
    """The ``--model-file FILE`` option shared by every command that takes ``--model``."""
    return typer.Option(None, "--model-file", help=MODEL_FILE_HELP)


def resolve_models(names: str | None, model_file: Any = None, *, option: str = "--model") -> list[Any]:
    """Models named by ``--model`` (comma-separated) followed by the one of ``--model-file``.

    Neither given: the paper's four models.  Only ``--model-file``: just its model.
    """
    from ..closures import PAPER_MODELS, get_model
    from ..errors import InputError

    if names is None and model_file is None:
        names = ",".join(PAPER_MODELS)
    models = [get_model(n) for n in parse_names(names, option.lstrip("-"))] if names is not None else []
    if model_file is not None:
        from ..calibration.model_file import load_model_file

        models.append(load_model_file(model_file).model)
    if not models:
        raise InputError(f"give a model: {option} NAME (see `ktgf models`) or --model-file FILE")
    return models
