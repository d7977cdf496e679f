"""``ktgf chute``: the steady gravity-driven inclined layer (docs/chute.md)."""

from __future__ import annotations

from pathlib import Path

import typer

from ._common import MODEL_HELP, OutputFormat, emit, handle_errors, model_file_option, resolve_models


@handle_errors
def chute(
    model: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    depth: float = typer.Option(..., "--depth", help="Column height H [m] (base at y = 0, free surface at H)."),
    angle: float = typer.Option(..., "--angle", help="Inclination of the base [degrees], 0 < angle < 90."),
    mean_phi: float = typer.Option(..., "--mean-phi", help="Mean solid fraction of the column (fixed inventory)."),
    d: float = typer.Option(1e-3, "--d", help="Particle diameter [m]."),
    rho_s: float = typer.Option(2500.0, "--rho-s", help="Material density [kg/m^3]."),
    e: float = typer.Option(0.9, "--e", help="Particle restitution coefficient, 0 < e <= 1."),
    specularity: float = typer.Option(1.0, "--specularity", help="Johnson-Jackson specularity of the base (bumpy: 1)."),
    wall_restitution: float = typer.Option(0.9, "--wall-restitution", help="Particle-base restitution e_w."),
    gravity: float = typer.Option(9.81, "--gravity", help="g [m/s^2]."),
    n_cells: int = typer.Option(64, "--cells", help="Grid cells across the column (>= 8)."),
    out: Path = typer.Option(None, "--out", "-o", help="Output netCDF (optional; with several models one file each, NAME_model.nc)."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Steady fully developed layer on a bumpy inclined base: zero stress and energy flux at the top.

    Prints the surface and slip velocities, the base traction against the weight and p(H)/p(0)
    (the share of the weight the top boundary carries; docs/chute.md).
    """
    from ..couette.chute import solve_chute
    from ..couette.run import Material
    from ..couette.walls import Wall
    from ..io import write_netcdf

    models = resolve_models(model, model_file)
    base = Wall(specularity=specularity, restitution=wall_restitution)
    rows, written, warnings = [], [], []
    for m in models:
        ds = solve_chute(m, depth=depth, angle_deg=angle, mean_phi=mean_phi, material=Material(d, rho_s, e),
                         base=base, gravity=gravity, n_cells=n_cells)
        a = ds.attrs
        rows.append({
            "model": a["model"], "iterations": int(a["solver_iterations"]), "surface_velocity_m/s": a["surface_velocity"],
            "base_slip_m/s": a["base_slip_velocity"], "base_traction_Pa": float(ds["wall_shear_stress"].values[0]),
            "weight_tangential_Pa": a["weight_tangential"], "top_pressure_fraction": a["top_pressure_fraction"],
            "max_phi": a["max_phi"], "valid": a["validity"],
        })
        if out is not None:
            path = out if len(models) == 1 else out.with_name(f"{out.stem}_{m.name}{out.suffix or '.nc'}")
            written.append(str(write_netcdf(ds, path)))
        if not a["physically_valid"]:
            warnings.append(f"Warning ({m.name}): {a['validity']}")
    title = f"chute: {angle:g} deg, H = {depth:g} m, mean phi {mean_phi:g}"
    if written:
        title += " -> " + ", ".join(written)
    emit(rows, fmt, title=title)
    for w in warnings:
        typer.echo(w, err=True)


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("chute")(chute)
