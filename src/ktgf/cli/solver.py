"""``ktgf run case.toml`` (the JAX finite-volume solver: every case) and ``ktgf plot run <case>.nc``."""

from __future__ import annotations

from pathlib import Path

import typer

from ._common import handle_errors


@handle_errors
def run(
    case: Path = typer.Argument(..., help="TOML run configuration (examples/: hcs_3d, uniform_shear, "
                              "uniform_shear_dense, frictional_shear, couette_2d, couette_dense, couette_dense_3d, "
                              "couette_dense055, couette_dense055_3d, couette_dense_seq32, couette_dense_seq64, "
                              "couette_dense_seq128, chute_2d .toml)."),
    resume: Path = typer.Option(None, "--resume", help="Continue from this checkpoint (same config)."),
    output_dir: Path = typer.Option(None, "--output-dir", "-o", help="Override output.directory."),
    progress: bool = typer.Option(True, "--progress/--no-progress", help="Show the progress bar."),
    overwrite: bool = typer.Option(False, "--overwrite", help="Delete the files of an earlier run in the output folder first."),
) -> None:
    """Run a solver case (cooling box, uniform shear, Couette, chute); writes the time series <case>.nc
    (e.g. cooling.nc), checkpoint.npz, .vti, .png files and, for a case with a reference, verification.json.

    Examples: examples/hcs_3d.toml (cooling box), uniform_shear.toml, uniform_shear_dense.toml (64³,
    φ 0.55), frictional_shear.toml (μ 0.5), couette_2d.toml, couette_dense.toml (φ 0.5, 64 cells
    across the gap), couette_dense_3d.toml (64³ from couette_dense's result; runs couette_dense first),
    couette_dense055.toml → couette_dense055_3d.toml (the same at φ 0.55: ≈ 9 min from a uniform start),
    couette_dense_seq32.toml → _seq64 → _seq128 (φ 0.55, grid sequencing to 128 cells), chute_2d.toml; time.steady_tol stops a
    sheared run at its steady state; initial.from_run starts from an earlier run mapped onto the grid
    (from_run = "earlier.toml": that config is run first, or resumed, or reused if complete).

    Ctrl-C stops after the current chunk with a checkpoint that matches the files written
    (exit code 130); `--resume` continues bit for bit.
    """
    from ..solver.interrupt import STOP, Interrupted

    with STOP:  # from here on Ctrl-C is a flag, also during imports and the first compilation
        try:
            from ..solver.chain import run_chain

            sim, ds = run_chain(case, output_dir, resume, progress, overwrite)
        except Interrupted as exc:
            tail = f"\nResume with: ktgf run {case} --resume {exc.checkpoint}" if exc.checkpoint else ""
            typer.echo(f"{exc}{tail}", err=True)
            raise typer.Exit(exc.exit_code) from None
        except KeyboardInterrupt:  # before the handler was installed
            typer.echo("interrupted; nothing written", err=True)
            raise typer.Exit(130) from None
    last = ds.isel(time=-1)
    if sim.case.hcs:
        typer.echo(
            f"done: {sim.steps} steps, t = {float(last.time):.6g} s (tau = {float(last.tau):.4g}); "
            f"theta/theta_Haff = {float(last.theta_mean / last.theta_haff):.4f}, "
            f"density variance = {float(last.density_variance):.3g}, max phi = {float(last.phi_max):.4f}; "
            f"time series in {sim.timeseries}"
        )
        return
    check = ""
    if sim.verification is not None:
        errors = ", ".join(f"{k} {v:.2e}" for k, v in sim.verification["max_rel_error"].items())
        check = f"; relative error against the {sim.verification['reference'].split(' (')[0]}: {errors}"
    typer.echo(
        f"done ({sim.case.name}): {sim.steps} steps, t = {float(last.time):.6g} s; theta = {float(last.theta_mean):.4g} "
        f"m2/s2, max phi = {float(last.phi_max):.4f}{check}; time series in {sim.timeseries}"
    )


@handle_errors
def plot_run(
    timeseries: Path = typer.Argument(..., help="<case>.nc written by `ktgf run` (e.g. cooling.nc)."),
    out: Path = typer.Option(Path("run.png"), "--out", "-o", help="Figure file (png/pdf/svg)."),
) -> None:
    """Plot a run's time series: for the cooling box θ/θ_Haff, transverse and longitudinal kinetic energy / θ
    and density variance against τ; for a sheared case θ and its stresses against the strain γ̇t (and the
    profiles across the gap at the last output for the Couette cell and the chute)."""
    from ..errors import InputError
    from ..io import read_dataset, require
    from ..plotting.cooling_gas import plot_cooling_run
    from ..plotting.sheared import needs, plot_sheared_run
    from ..solver.cases import CASES

    what = "time series written by `ktgf run`"
    ds = read_dataset(timeseries, ("time",), what)
    case = ds.attrs.get("case")  # written by every case but the cooling box (Simulation.dataset)
    if case is not None:
        if str(case) not in CASES:
            raise InputError(f"{timeseries}: case {case!r} is not a case of this ktgf; valid: {', '.join(CASES)}")
        c = CASES[str(case)]
        typer.echo(f"wrote {plot_sheared_run(require(ds, timeseries, needs(c.panels, c.profiles), what), out, c.panels, c.profiles)}")
        return
    require(ds, timeseries, ("tau", "theta_mean", "theta_haff", "ke_transverse", "ke_longitudinal",
                             "density_variance"), what)
    typer.echo(f"wrote {plot_cooling_run(ds, out)}")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("run")(run)
    plot_app.command("run")(plot_run)
