"""``ktgf validate``: one table of a model against every DEM file given, rows marked fitted or predicted."""

from __future__ import annotations

from pathlib import Path

import typer

from ._common import OutputFormat, emit, handle_errors, model_file_option


@handle_errors
def validate_cmd(
    model: str = typer.Option(None, "--model", "-m", help="Registered model (see `ktgf models`)."),
    model_file: Path = model_file_option(),
    data: list[Path] = typer.Option(None, "--data", help="DEM file or folder of them (uniform shear, frictional shear, Couette, "
                                    "homogeneous cooling; the case from the columns); repeat for several. Default: the DEM "
                                    "files shipped with ktgf."),
    n_cells: int = typer.Option(200, "--cells", help="Grid cells of Couette cells."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Model against DEM: per state and quantity the model, DEM +- sigma, model/DEM - 1, and whether that state was fitted.

    Fitted states come from the model file's provenance (the data files it was calibrated on) or, for a
    registered model, from what it was fitted to (docs/calibration.md).  Couette cells use Johnson-Jackson walls
    with the specularity fitted to the DEM slip, unless the model file holds walls.
    """
    from ..calibration.validate import fit_sources, validate
    from ..errors import InputError

    if (model is None) == (model_file is None):
        raise InputError("give exactly one of --model NAME or --model-file FILE")
    if model_file is not None:
        from ..calibration.model_file import load_model_file

        mf = load_model_file(model_file)
        m, sources, walls = mf.model, fit_sources(model_file=mf), mf.walls or None
    else:
        from ..closures import get_model

        m = get_model(model)
        sources, walls = fit_sources(model_name=m.name), None
    if not data:
        from ..data import shipped_data_dir

        data = [shipped_data_dir()]
    result = validate(m, data, sources=sources, walls=walls, n_cells=n_cells)
    if fmt == OutputFormat.json:
        import json

        from ._common import _strict_json

        typer.echo(json.dumps(_strict_json({"model": result.model, "rows": result.rows, "summary": result.summary(),
                                            "fitted_on": [s.file for s in result.sources], "notes": result.notes}), indent=2))
        return
    emit(result.rows, fmt, title=f"{m.label or m.name} against DEM: error = model/DEM - 1; role = fitted (state in the "
                                 "calibration data) or predicted")
    emit(result.summary(), fmt, title="|error| per case, quantity and role")
    if fmt == OutputFormat.table:
        fitted = ", ".join(s.file for s in result.sources) or "nothing in these files"
        typer.echo(f"fitted on: {fitted}")
        for n in result.notes:
            typer.echo(f"note: {n}")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("validate")(validate_cmd)
