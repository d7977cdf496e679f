"""``ktgf calibrate``: fit model parameters to particle-data files and write a model file."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import typer

from ._common import OutputFormat, emit, handle_errors, model_file_option


def _pairs(text: str, what: str) -> dict[str, str]:
    from ..errors import InputError

    out = {}
    for item in (t.strip() for t in text.split(",") if t.strip()):
        if "=" not in item:
            raise InputError(f"--{what} {item!r} is not NAME=VALUE")
        k, v = item.split("=", 1)
        out[k.strip()] = v.strip()
    return out


def _floats(text: str, what: str) -> dict[str, float]:
    from ..errors import InputError

    out = {}
    for k, v in _pairs(text, what).items():
        try:
            out[k] = float(v)
        except ValueError:
            raise InputError(f"--{what} {k}={v!r}: not a number") from None
    return out


def _bounds(text: str) -> dict[str, tuple[float, float]]:
    from ..errors import InputError

    out = {}
    for k, v in _pairs(text, "bounds").items():
        try:
            lo, hi = (float(x) for x in v.split(":"))
        except ValueError:
            raise InputError(f"--bounds {k}={v!r}: expected LOW:HIGH") from None
        out[k] = (lo, hi)
    return out


@handle_errors
def calibrate_cmd(
    model: str = typer.Option(None, "--model", "-m", help="Registered model whose parameters are fitted (see `ktgf models`)."),
    model_file: Path = model_file_option(),
    data: list[Path] = typer.Option(..., "--data", help="Data file (uniform-shear or Couette CSV of the shared format); repeat for several."),
    fit: str = typer.Option(..., "--fit", help="Parameters to fit, comma-separated: float options of the model (phi_c, beta, ...) "
                                                "and, with Couette data, specularity, wall_restitution."),
    out: Path = typer.Option(None, "--out", "-o", help="Model file (TOML) to write; every command reads it with --model-file "
                             "(needed unless --cross-validate)."),
    cross_validate: bool = typer.Option(False, "--cross-validate", help="Also refit leaving out one state at a time (a row of a "
                                        "uniform-shear file, a Couette file) and print each left-out state's error and their "
                                        "mean: the error to quote (docs/calibration.md)."),
    start: str = typer.Option("", "--start", help="Start values NAME=VALUE,... (default: the model's values)."),
    bounds: str = typer.Option("", "--bounds", help="Bounds NAME=LOW:HIGH,... (default: see docs/calibration.md)."),
    wall: str = typer.Option("", "--wall", help="Fixed wall parameters of Couette cells: specularity=...,wall_restitution=..."),
    weights: str = typer.Option("sigma", "--weights", help="sigma (residuals over the files' standard errors) or relative."),
    errors: str = typer.Option(None, "--errors", help="scaled (by the residual variance; default) or stated (the data's errors)."),
    n_cells: int = typer.Option(100, "--cells", help="Grid cells of Couette cells."),
    max_evaluations: int = typer.Option(100, "--max-evaluations", help="Limit on residual evaluations."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Fit chosen parameters of a model to DEM data (least squares, exact gradients) and write a model file.

    Prints the fitted values, their correlations, the data points per parameter and a warning for any
    pair correlated beyond 0.95 or a rank-deficient Jacobian; --cross-validate adds the leave-one-state-out errors.
    """
    from ..data import read_data
    from ..calibration.fit import calibrate
    from ..calibration.model_file import fit_text, load_model_file, write_model_file
    from ..closures import get_model
    from ..errors import InputError

    if (model is None) == (model_file is None):
        raise InputError("give exactly one of --model NAME or --model-file FILE (the model to start from)")
    if out is None and not cross_validate:
        raise InputError("--out FILE is needed: the model file to write (only --cross-validate may go without it)")
    start_file = load_model_file(model_file) if model_file is not None else None
    m = start_file.model if start_file is not None else get_model(model)
    datasets = [read_data(p) for p in data]
    walls = {**(start_file.walls if start_file else {}), **_floats(wall, "wall")}
    result = calibrate(m, datasets, [n.strip() for n in fit.split(",") if n.strip()], start=_floats(start, "start"),
                       bounds=_bounds(bounds), weights=weights, errors=errors, walls=walls, n_cells=n_cells,
                       max_evaluations=max_evaluations)
    if start_file is not None:
        result.base = start_file.base
    command = " ".join(["ktgf", *map(shlex.quote, sys.argv[1:])]) if sys.argv else "ktgf calibrate"
    path = write_model_file(out, fit_text(result, command=command, start_file=start_file)) if out is not None else None
    cv = None
    if cross_validate:
        from ..calibration.crossval import cross_validate as run_cv
        from ._progress import DelayedProgress

        with DelayedProgress("leave-one-out refits") as bar:
            cv = run_cv(m, datasets, result.names, full=result, progress=bar, bounds=_bounds(bounds), weights=weights,
                        walls=walls, n_cells=n_cells, max_evaluations=max_evaluations)
    notes = [n for d in datasets for n in getattr(d, "notes", ())]
    se_kind = ("scaled by the residual variance s^2 = sum(r^2)/(m - n)" if result.errors == "scaled"
               else "from the data's stated uncertainties (not rescaled)")
    params = [{"parameter": p.name, "start": p.start, "value": float(v), "std_error": float(s),
               "lower": p.lower, "upper": p.upper, "at_bound": p.name in result.at_bound}
              for p, v, s in zip(result.parameters, result.values, result.stderr)]
    corr = [{"parameter": a, **{b: float(result.correlation[i, j]) for j, b in enumerate(result.names)}}
            for i, a in enumerate(result.names)]
    points = [{"observation": lab, "data": float(o), "model": float(p), "residual": float(r)}
              for lab, o, p, r in zip(result.labels, result.observed, result.predicted, result.residuals)]
    summary = {"model": result.base, "success": result.success, "message": result.message, "cost": result.cost,
               "weights": result.weights, "standard_errors": se_kind, "evaluations": result.evaluations,
               "seconds": result.seconds, "walls": result.walls, "out": str(path) if path else None, "notes": notes}
    ident = result.identifiability
    identity = {"observations": ident.observations, "parameters": ident.parameters,
                "points_per_parameter": ident.points_per_parameter, "rank": ident.rank, "warnings": list(ident.warnings)}
    if fmt == OutputFormat.json:
        import json

        from ._common import _strict_json

        doc = {**summary, "parameters": params, "correlation": corr, "identifiability": identity, "points": points}
        if cv is not None:
            doc["cross_validation"] = {**cv.summary(), "per_quantity": cv.per_quantity(), "rows": cv.rows, "refits": cv.refits}
        typer.echo(json.dumps(_strict_json(doc), indent=2, default=float))
    else:
        emit(params, fmt, title=f"{result.base}: fitted parameters (standard errors {se_kind})")
        emit(corr, fmt, title="correlations")
        emit(points, fmt, title=f"residuals ({'(model - data)/sigma' if result.weights == 'sigma' else 'model/data - 1'}) per data point")
        if fmt == OutputFormat.table:
            for n in notes:
                typer.echo(f"note: {n}")
            if result.walls:
                typer.echo("walls: " + ", ".join(f"{k} = {v:.6g}" for k, v in result.walls.items()))
            typer.echo(f"cost = {result.cost:.6g} (1/2 sum r^2 over {len(result.labels)} points), {result.evaluations} evaluations, "
                       f"{result.seconds:.2f} s; {result.message}")
            typer.echo(f"identifiability: {ident.observations} data points for {ident.parameters} parameter(s) "
                       f"({ident.points_per_parameter:.3g} per parameter), Jacobian rank {ident.rank}")
            if path is not None:
                typer.echo(f"wrote {path}")
        if cv is not None:
            _emit_cross_validation(cv, fmt)
    for w in ident.warnings:
        typer.echo(f"Warning: {w}", err=True)
    if cv is not None:
        for n in cv.notes:
            typer.echo(f"Warning: cross-validation: {n}", err=True)
        for r in cv.refits:
            if not r["success"]:
                typer.echo(f"Warning: refit without {r['state']} did not converge: {r['message']}", err=True)
    if not result.success:
        where = f" (best point written to {path})" if path is not None else ""
        typer.echo(f"Warning: {result.message}{where}", err=True)
        raise typer.Exit(1)


def _emit_cross_validation(cv, fmt: OutputFormat) -> None:
    """The left-out errors per state and quantity, per quantity, and the mean (table, csv, markdown)."""
    cols = ("state", "quantity", "data", "sigma", "model", "error", "in_sample_error", "refit_converged")
    names = [f"refit_{n}" for n in cv.full.names]
    rows = [{k: r[k] for k in (*cols, *names)} for r in cv.rows]
    emit(rows, fmt, title=f"leave-one-state-out cross-validation of {', '.join(cv.full.names)}: error = model/data - 1 "
                          "of the state left out (in_sample_error: the fit on all states)")
    emit(cv.per_quantity(), fmt, title="cross-validated |error| per quantity")
    emit([{"states": len(cv.refits), "values": len(cv.rows), "mean_abs_error": cv.mean_abs_error,
           "mean_abs_in_sample_error": cv.mean_abs_in_sample_error, "seconds": cv.seconds}], fmt,
         title="cross-validated mean |model/data - 1| (the number to quote)")
    if fmt == OutputFormat.table:
        typer.echo(f"cross-validated mean |model/data - 1| over {len(cv.refits)} states and {len(cv.rows)} values: "
                   f"{100 * cv.mean_abs_error:.2f} % (in sample: {100 * cv.mean_abs_in_sample_error:.2f} %); "
                   f"{cv.seconds:.1f} s")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("calibrate")(calibrate_cmd)
