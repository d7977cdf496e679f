"""``ktgf couette run | compare | sweep`` and ``ktgf plot couette``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from ._common import DASK_HELP, MODEL_HELP, VALUES_HELP, OutputFormat, emit, handle_errors, model_file_option, parse_values


def _default_dem() -> Path:
    """The DEM Couette file in the data folder of :func:`ktgf.data.locate_data_dir` (may not exist)."""
    from ..data import COUETTE, DATA_ENV, locate_data_dir

    folder, _ = locate_data_dir(None)
    return (folder or Path(f"${DATA_ENV}")) / COUETTE


DEFAULT_DEM = _default_dem()


def _summary(ds: Any) -> dict[str, Any]:
    return {
        "model": ds.attrs["model"],
        "converged": bool(ds.attrs["converged"]),
        "iterations": int(ds.attrs["solver_iterations"]),
        "wall_shear_stress_Pa": float(ds["wall_shear_stress"].values[0]),
        "slip_bottom_m/s": float(ds["wall_slip"].values[0]),
        "slip_top_m/s": float(ds["wall_slip"].values[1]),
        "max_phi": float(ds.attrs["max_phi"]),
        "valid": ds.attrs["validity"],
        "energy_budget_error": float(ds.attrs["energy_budget_relative_error"]),
    }


@handle_errors
def run_cmd(
    config: Path = typer.Argument(..., help="TOML config (see examples/couette_planar.toml)."),
    out: Path = typer.Option(None, "--out", "-o", help="Output netCDF (default: output.path of the config)."),
    model_file: Path = model_file_option(),
    mu: float = typer.Option(None, "--mu", help="Particle friction coefficient mu >= 0 (adds Walton friction to a "
                             "frictionless model; docs/friction.md)."),
    wall_friction_angle: float = typer.Option(
        None, "--wall-friction-angle", help="Wall friction angle delta_w [degrees], 0 <= delta_w < 90, on both walls "
        "(Johnson-Jackson frictional wall traction p_f tan delta_w; needs a model with a frictional stress)."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Solve one Couette cell described by a validated TOML config and write the profiles to netCDF.

    With ``--model-file`` the file's model replaces the config's ``model`` (the config's walls stay).
    ``--mu`` and ``--wall-friction-angle`` override the model's friction coefficient and both walls'
    ``friction_angle``.
    """
    from ..couette.config import check_output_path, load_config, run_config
    from ..io import write_netcdf
    from ..validation import check_range
    from .shear import with_friction

    if mu is not None:
        check_range("particle friction coefficient --mu", mu, low=0.0)
    if wall_friction_angle is not None:
        check_range("wall friction angle --wall-friction-angle", wall_friction_angle, low=0.0, high=90.0,
                    high_open=True, why="degrees")
    cfg = load_config(config)
    model = None
    if model_file is not None:
        from ..calibration.model_file import load_model_file

        model = load_model_file(model_file).model
    if mu is not None:
        model = with_friction(cfg.build_model() if model is None else model, mu)
    if wall_friction_angle is not None:
        cfg = _with_wall_friction(cfg, wall_friction_angle)
    path = check_output_path(out, "--out") if out is not None else Path(cfg.output.path)
    ds = run_config(cfg, model, failed_path=path.with_suffix(".failed.nc"))
    write_netcdf(ds, path)
    emit([_summary(ds)], fmt, title=f"Couette ({ds.attrs['geometry']}) -> {path}")
    if not ds.attrs["physically_valid"]:
        typer.echo(f"Warning: {ds.attrs['validity']}", err=True)


def _with_wall_friction(cfg: Any, angle: float) -> Any:
    """The config with friction_angle = ``angle`` on both walls (per-wall entries dropped)."""
    walls = cfg.walls
    sides = {s: getattr(walls, s).model_copy(update={"friction_angle": None}) for s in ("bottom", "top")
             if getattr(walls, s) is not None}
    return cfg.model_copy(update={"walls": walls.model_copy(update={"friction_angle": float(angle), **sides})})


@handle_errors
def compare_cmd(
    config: Path = typer.Argument(None, help="TOML config run for all models (default: the DEM file's case with calibrated walls)."),
    dem: Path = typer.Option(DEFAULT_DEM, "--dem", help="DEM Couette CSV; its header gives the case (e, mean phi, gap, wall speed)."),
    out: Path = typer.Option(Path("couette_compare.png"), "--out", "-o", help="Figure file."),
    models: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    n_cells: int = typer.Option(200, "--cells", help="Grid cells across the gap (DEM case)."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
    wall: str = typer.Option("johnson-jackson", "--wall", help="Walls of the DEM case: johnson-jackson (e_w = e, "
                             "specularity fitted per model to the DEM slip) or bumpy (the DEM's wall spheres from its "
                             "header, e_w = e, nothing fitted; the cell is then the layer the sphere centres reach)."),
) -> None:
    """Models on one figure (u/U, phi, sqrt(theta)/U vs y/d) with DEM points, profile errors and wall stresses against the DEM."""
    from ..couette.compare import compare_with_dem
    from ..data import read_couette
    from ..plotting.couette import plot_profiles
    from ._common import resolve_models

    chosen = resolve_models(models, model_file, option="--models")
    walls = {}
    if model_file is not None:
        from ..calibration.model_file import load_model_file

        mf = load_model_file(model_file)
        if mf.walls.get("specularity") is not None:
            walls[mf.model.name] = mf.walls
    if config is None:
        from ..data.table import resolve

        dem = resolve(dem)  # a missing file: one line naming it and the shipped files
        rows, extra = compare_with_dem(dem, chosen, n_cells=n_cells, walls=walls, wall=wall)
        c = extra["case"]
        bumpy = wall == "bumpy"
        if bumpy:
            band_note = "±1σ bands: computed for Johnson-Jackson walls only" if model_file is not None else ""
            cell = extra["cell"]
            walls_note = (f"bumpy walls (spheres d_w = {c.wall_sphere_diameter:g} d, gap {c.wall_sphere_gap:g} d, "
                          f"from the DEM header), e_w = e, nothing fitted; cell = the layer of the centres, gap "
                          f"{cell.gap:.4g} d, mean phi {cell.mean_phi:.4g}")
        else:
            band_note = _couette_bands(rows, chosen, model_file, extra["dem"], walls, n_cells)
            walls_note = f"JJ walls, e_w = e, specularity fitted per model to the DEM slip at |y| = {extra['dem'].slip_y:g} d"
        datasets = {m.label or m.name: extra["datasets"][m.name] for m in chosen if m.name in extra["datasets"]}
        emit(rows, fmt, title=(f"Models vs DEM ({dem.name}: e = {c.e:g}, mean phi = {c.mean_phi:g}, gap = {c.gap:g} d, U = {c.wall_speed:g}); "
                               f"{walls_note}"))
        if band_note:
            typer.echo(band_note, err=fmt == OutputFormat.json)
        path = plot_profiles(datasets, out, dem=extra["dem"],
                             title=f"DEM Couette e = {c.e:g}, mean phi = {c.mean_phi:g}; "
                                   + ("bumpy walls, nothing fitted" if bumpy else "specularity calibrated per model"))
    else:
        from ..couette.config import load_config, run_config

        cfg = load_config(config)
        from ..errors import ConvergenceError

        datasets, rows = {}, []
        for m in chosen:
            try:
                datasets[m.label or m.name] = ds = run_config(cfg, m)
                rows.append(_summary(ds))
            except ConvergenceError as exc:  # report it and go on with the other models
                rows.append({"model": m.name, "converged": False, "valid": str(exc)[:100]})
        rows = [{**{k: "" for k in rows[0] if k not in r}, **r} for r in rows] if rows else rows
        emit(rows, fmt, title=f"Couette comparison ({config})")
        dem_data = read_couette(dem) if dem.exists() and _is_dem_case(cfg, dem) else None
        path = plot_profiles(datasets, out, dem=dem_data)
    typer.echo(f"wrote {path}", err=fmt == OutputFormat.json)


def _couette_bands(rows: list[dict[str, Any]], chosen: list[Any], model_file: Path | None, dem: Any,
                   walls: dict[str, dict[str, float]], n_cells: int) -> str:
    """Adds tau_wall_sd and p_sd (±1σ from the model file's fitted covariance) to the rows; returns the note."""
    import math

    if model_file is None:
        return ""
    from ..calibration.model_file import load_model_file

    fit = load_model_file(model_file).covariance()
    if fit is None:
        return ""
    from ..calibration.bands import couette_bands

    m = chosen[-1]
    for r in rows:
        r["tau_wall_sd"], r["p_sd"] = math.nan, math.nan
    row = rows[-1]
    if not math.isfinite(row.get("tau_wall", math.nan)):
        return ""
    w = walls.get(m.name, {})
    sd = couette_bands(m, fit[0], fit[1], dem, specularity=row["specularity"], wall_restitution=w.get("wall_restitution"),
                       slip_fitted=m.name not in walls, n_cells=n_cells)
    row["tau_wall_sd"], row["p_sd"] = sd["tau_wall"], sd["p"]
    along = "; the specularity follows the parameters (refitted to the slip)" if m.name not in walls else ""
    return (f"tau_wall_sd, p_sd: ±1 standard deviation from the covariance of {', '.join(fit[0])} in {model_file.name} "
            f"(delta method, implicit-function Jacobian of the Couette solution{along})")


def _is_dem_case(cfg: Any, dem: Path) -> bool:
    """True if the config is the planar cell of the DEM file's header (gap in diameters and mean phi)."""
    from ..data import read_couette_case

    c = read_couette_case(dem)
    g = cfg.geometry
    return g.kind == "planar" and abs(g.gap / cfg.particle_diameter - c.gap) < 1e-9 and abs(cfg.mean_solid_fraction - c.mean_phi) < 1e-9


def _sweep_task(task: tuple[dict[str, Any], float, float]) -> dict[str, Any]:
    """One sweep point (module level so that process pools and Dask can pickle it)."""
    from ..couette.config import parse_config, run_config
    from ..errors import ConvergenceError

    data, spec, ew, model_file = task
    walls = dict(data.get("walls", {}))
    walls.update({"specularity": spec, "restitution": ew})
    for side in ("bottom", "top"):
        if isinstance(walls.get(side), dict):
            walls[side] = {k: v for k, v in walls[side].items() if k not in ("specularity", "restitution")}
    cfg = parse_config({**data, "walls": walls})
    row: dict[str, Any] = {"specularity": spec, "wall_restitution": ew}
    model = None
    if model_file is not None:
        from ..calibration.model_file import load_model_file

        model = load_model_file(model_file).model
    try:
        ds = run_config(cfg, model)
    except ConvergenceError as exc:
        return {**row, "converged": False, "slip_over_U": float("nan"), "wall_shear_stress_Pa": float("nan"),
                "max_phi": float("nan"), "valid": False, "message": str(exc)[:80]}
    U = float(ds.attrs["velocity_scale"])
    return {**row, "converged": True, "slip_over_U": float(abs(ds["wall_slip"].values[0]) / U),
            "wall_shear_stress_Pa": float(ds["wall_shear_stress"].values[0]),
            "max_phi": float(ds.attrs["max_phi"]), "valid": bool(ds.attrs["physically_valid"]), "message": ""}


@handle_errors
def sweep_cmd(
    config: Path = typer.Argument(..., help="TOML config of the base case."),
    specularity: str = typer.Option("0.001,0.01,0.1,1", "--specularity", help="Specularity coefficients phi': " + VALUES_HELP + "."),
    wall_restitution: str = typer.Option("0.9", "--wall-restitution", help="Wall restitution coefficients e_w: " + VALUES_HELP + "."),
    workers: int = typer.Option(0, "--workers", help="Processes (0: in-process)."),
    dask: str = typer.Option(None, "--dask", help=DASK_HELP),
    out: Path = typer.Option(None, "--out", "-o", help="Optional figure of the slip vs phi'."),
    model_file: Path = model_file_option(),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Sweep the specularity phi' and the wall restitution e_w (the calibration knobs) through an executor.

    With ``--model-file`` the file's model replaces the config's.
    """
    import tomllib

    from ..couette.config import load_config
    from ..sweep import map_tasks, open_executor
    from ..validation import check_range

    load_config(config)  # validate once, with field names, before dispatching
    data = tomllib.loads(config.read_text())
    specs = parse_values(specularity, "specularity")
    ews = parse_values(wall_restitution, "wall-restitution")
    check_range("specularity coefficient phi'", specs, low=0.0, high=1.0, low_open=True)
    check_range("wall restitution e_w", ews, low=0.0, high=1.0, low_open=True)
    if model_file is not None:
        from ..calibration.model_file import load_model_file

        load_model_file(model_file)  # check it once, with field names, before dispatching
        model_file = model_file.resolve()
    tasks = [(data, float(s), float(e), model_file) for e in ews for s in specs]
    with open_executor(workers, dask) as executor:
        rows = map_tasks(_sweep_task, tasks, executor=executor)
    emit(rows, fmt, title=f"Couette sweep ({config}): slip = |u_sl|/U at the bottom wall")
    if out is not None:
        from ..plotting.couette import plot_sweep

        typer.echo(f"wrote {plot_sweep(rows, out)}")


@handle_errors
def plot_cmd(
    files: list[Path] = typer.Argument(..., help="netCDF outputs of `ktgf couette run`."),
    out: Path = typer.Option(Path("couette.png"), "--out", "-o", help="Figure file."),
) -> None:
    """Plot u/U, phi and sqrt(theta)/U of saved Couette runs on one figure."""
    from ..io import read_dataset
    from ..plotting.couette import plot_profiles

    datasets = {}
    for f in files:
        ds = read_dataset(f, ("u", "phi", "theta"), "Couette profile written by `ktgf couette run`")
        datasets[f"{ds.attrs.get('model_label', f.stem)} ({f.name})"] = ds
    typer.echo(f"wrote {plot_profiles(datasets, out)}")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    couette_app = typer.Typer(help="Steady Couette shear cells (planar and annular).", no_args_is_help=True)
    couette_app.command("run")(run_cmd)
    couette_app.command("compare")(compare_cmd)
    couette_app.command("sweep")(sweep_cmd)
    app.add_typer(couette_app, name="couette")
    plot_app.command("couette")(plot_cmd)
