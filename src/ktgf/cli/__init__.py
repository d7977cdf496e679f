"""The ``ktgf`` command line: a thin layer that parses, validates, calls the library and prints.

Each topic lives in its own module exposing ``register(app, plot_app)``; the modules listed in
:data:`COMMAND_MODULES` are loaded if present.
"""

from __future__ import annotations

import importlib
import logging
import sys

import typer

app = typer.Typer(
    name="ktgf",
    help="Continuum models of dense inelastic granular flows (kinetic theory of granular flow).",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    rich_markup_mode=None,  # help texts are plain: "[m]", "[s]" are units, not Rich markup tags
)
plot_app = typer.Typer(help="Figures (PNG/PDF/SVG by file extension).", no_args_is_help=True, rich_markup_mode=None)
app.add_typer(plot_app, name="plot")

COMMAND_MODULES = ("closures", "shear", "hcs", "couette", "chute", "solver", "report", "calibrate", "validate", "dem")


def _print_version(value: bool) -> None:
    if value:
        from .. import __version__

        typer.echo(f"ktgf {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", help="Print the version and exit.", is_eager=True, callback=_print_version
    ),
) -> None:
    """Continuum models of dense inelastic granular flows (kinetic theory of granular flow)."""


for _name in COMMAND_MODULES:
    try:
        _mod = importlib.import_module(f"{__name__}.{_name}")
    except ModuleNotFoundError as _exc:  # that topic is not part of this build
        if _exc.name != f"{__name__}.{_name}":
            raise
        continue
    _mod.register(app, plot_app)


def show_info() -> None:
    """Shows the INFO records of the ``ktgf`` logger (e.g. that the C++ flux kernel is being compiled, which
    takes seconds the first time) on stderr, unless the ``ktgf`` logger already has a handler.

    Library use stays silent: without a handler only warnings and errors reach stderr (Python's last resort).
    """
    logger = logging.getLogger("ktgf")
    if not logger.handlers:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("ktgf: %(message)s"))
        logger.addHandler(handler)
        if logger.level == logging.NOTSET:
            logger.setLevel(logging.INFO)


def main() -> None:
    """Entry point of the ``ktgf`` console script."""
    show_info()
    app()
