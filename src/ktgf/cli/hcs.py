"""``ktgf hcs haff|stability|map`` and ``ktgf plot stability-map|dispersion`` (model.md §8)."""

from __future__ import annotations

import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import typer

from ..closures import get_model
from ..errors import InputError
from ..validation import check_material, check_positive, check_range
from ._common import (DASK_HELP, MODEL_HELP, VALUES_HELP, OutputFormat, check_points, deprecated_alias, emit,
                      handle_errors, model_file_option, parse_values, resolve_models)

hcs_app = typer.Typer(help="Homogeneous cooling state: Haff's law, linear stability, critical box sizes.",
                      no_args_is_help=True)

#: Smallest solid fraction of the stability commands (L/d ~ 1/phi would overflow far below).
PHI_MIN = 1e-10
FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".eps", ".jpg", ".jpeg", ".tif", ".tiff")


def _models(text: str | None, model_file: Path | None = None) -> list[Any]:
    return resolve_models(text, model_file)


def _check_count(name: str, value: int, low: int) -> None:
    check_range(f"number of points {name}", value, low=low)
    check_points(value, name)


def _check_box(box: float) -> None:
    # below one particle diameter the box's lowest mode is no continuum wave (and 2 pi/L overflows)
    check_range("box side --box", box, low=1.0, why="L/d: at least one particle diameter")


def _kind_of_output(out: Path, allowed: tuple[str, ...]) -> str:
    suffix = out.suffix.lower()
    if suffix == ".nc" and ".nc" in allowed:
        return "netcdf"
    if suffix in FIGURE_SUFFIXES and "figure" in allowed:
        return "figure"
    valid = ", ".join(([".nc"] if ".nc" in allowed else []) + (list(FIGURE_SUFFIXES) if "figure" in allowed else []))
    raise InputError(f"--out {str(out)!r} has extension {suffix or '(none)'!r}: valid {valid}")


@handle_errors
def haff(
    model: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    phi: float = typer.Option(..., "--phi", help="Solid fraction, 0 < phi < packing limit."),
    e: float = typer.Option(..., "--e", help="Restitution coefficient, 0 < e <= 1."),
    theta0: float = typer.Option(..., "--theta0", help="Initial granular temperature theta0 [m^2/s^2] (> 0)."),
    d: float = typer.Option(..., "--d", help="Particle diameter [m] (> 0)."),
    t_end: float = typer.Option(None, "--t-end", help="End time [s] (default 10 x the longest Haff time)."),
    n: int = typer.Option(200, "--n", help="Number of output times."),
    out: Path = typer.Option(None, "--out", "-o", help="Write the histories: .nc (netCDF) or a figure (.png/.pdf/.svg)."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Haff's law theta(t) = theta0/(1 + t/t0)^2 against the integrated ODE; cooling time t0 per model."""
    from ..hcs.haff import haff_history

    kind = _kind_of_output(out, (".nc", "figure")) if out is not None else None
    _check_count("--n", n, 2)
    check_material(d=d, theta=theta0)
    check_range("solid fraction phi", phi, low=PHI_MIN, why="no collisions, no cooling at phi = 0")
    models = _models(model, model_file)
    for m in models:
        m.check(phi, e, theta0)
    if t_end is not None:
        check_positive("end time t_end", t_end, "s")
    ds = haff_history(models, phi, e, theta0, d=d, t_end=t_end, n=n)
    rows = []
    for i, name in enumerate(ds["model"].values):
        th, tn = ds["theta_haff"].values[i], ds["theta_numeric"].values[i]
        rows.append({
            "model": str(name),
            "zeta0 [1/s]": float(ds["zeta0"].values[i]),
            "t0 [s]": float(ds["t0"].values[i]),
            "t_end [s]": float(ds["t"].values[-1]),
            "theta(t_end) Haff": float(th[-1]),
            "theta(t_end) ODE": float(tn[-1]),
            "max rel. diff": float(np.max(np.abs(tn / th - 1.0))),
        })
    emit(rows, fmt, title=f"Haff's law: phi={phi:g}, e={e:g}, theta0={theta0:g} m^2/s^2, d={d:g} m")
    if kind == "netcdf":
        from ..io import write_netcdf

        typer.echo(f"wrote {write_netcdf(ds, out)}", err=True)
    elif kind == "figure":
        from ..plotting.hcs import plot_haff

        typer.echo(f"wrote {plot_haff(ds, out)}", err=True)


@handle_errors
def stability(
    model: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    phi: str = typer.Option(..., "--phi", help="Solid fraction(s): " + VALUES_HELP + "."),
    e: str = typer.Option(..., "--e", help="Restitution coefficient(s), 0 < e <= 1."),
    box: float = typer.Option(None, "--box", help="Side L/d of a periodic cube: growth rates at its lowest mode 2 pi/L."),
    method: str = typer.Option("closed", "--method", help="closed (closed form) or eig (root-finding on the eigenvalues)."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Critical wavenumbers k_perp*, k_par* and box sizes L_perp/d, L_par/d (and growth rates in a box)."""
    from ..hcs.critical import NoCrossingWarning, critical_wavenumbers_eig
    from ..hcs.dispersion import dispersion_relation
    from ..hcs.stability import box_wavenumber, critical_box_size, critical_wavenumbers

    if method not in ("closed", "eig"):
        raise InputError(f"--method {method!r} is not valid: choose closed or eig")
    if box is not None:
        _check_box(box)
    phi_values, e_values = parse_values(phi, "phi"), parse_values(e, "e")
    check_points(phi_values.size * e_values.size, "--phi x --e")
    phis, es = np.meshgrid(phi_values, e_values, indexing="ij")
    phis, es = phis.ravel(), es.ravel()
    check_range("solid fraction phi", phis, low=PHI_MIN, why="L/d grows like 1/phi: it overflows in the dilute limit")
    rows = []
    for m in _models(model, model_file):
        r = m.reduced(phis, es, hcs=True)
        if method == "closed":
            k_perp, k_par = critical_wavenumbers(r)
        else:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", NoCrossingWarning)
                k_perp, k_par = critical_wavenumbers_eig(r, on_no_crossing="inf")
            for w in caught:
                typer.echo(f"Note: {w.message}", err=True)
        k_perp, k_par = (np.broadcast_to(k, phis.shape) for k in (k_perp, k_par))
        l_perp, l_par = critical_box_size(phis, k_perp), critical_box_size(phis, k_par)
        if box is not None:
            kb = box_wavenumber(phis, box)
            # k* = k ell: the hydrodynamic equations hold for k ell below ~1; far above, rates overflow
            check_range("reduced wavenumber of the box's lowest mode k_box*", kb, high=1e3,
                        why="k* = 0.82/(phi L/d): give a larger --box or phi")
            disp = dispersion_relation(r, kb)
        for i in range(phis.size):
            row: dict[str, Any] = {
                "model": m.name, "phi": float(phis[i]), "e": float(es[i]),
                "k_perp*": float(k_perp[i]), "k_par*": float(k_par[i]),
                "L_perp/d": float(l_perp[i]), "L_par/d": float(l_par[i]),
            }
            if box is not None:
                s_long = disp.longitudinal[i]
                row.update({
                    "box L/d": box, "k_box*": float(kb[i]), "s_perp": float(disp.transverse[i]),
                    **{f"Re s_par{j + 1}": float(s_long[j].real) for j in range(3)},
                    "state": _verdict(float(disp.transverse[i]), float(s_long[0].real)),
                })
            rows.append(row)
    emit(rows, fmt, title="HCS stability (k* = k ell; growth rates in units of nu0)")


def _verdict(s_perp: float, s_par: float) -> str:
    if s_par > 0 and s_perp > 0:
        return "vortices+clusters"
    if s_perp > 0:
        return "vortices"
    if s_par > 0:
        return "clusters"
    return "homogeneous"


@handle_errors
def map_cmd(
    out: Path = typer.Option(..., "--out", "-o", help="Output netCDF file (.nc)."),
    model: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    n_phi: int = typer.Option(200, "--n-phi", help="Number of solid fractions."),
    n_e: int = typer.Option(100, "--n-e", help="Number of restitution coefficients."),
    phi_min: float = typer.Option(0.005, "--phi-min", help="Smallest solid fraction (> 0)."),
    phi_max: float = typer.Option(0.6, "--phi-max", help="Largest solid fraction (< 1; NaN beyond a model's packing limit)."),
    e_min: float = typer.Option(0.5, "--e-min", help="Smallest restitution coefficient (> 0)."),
    e_max: float = typer.Option(0.99, "--e-max", help="Largest restitution coefficient (<= 1)."),
    workers: int = typer.Option(0, "--workers", help="Run on a local process pool of this size (0: in-process)."),
    dask: str = typer.Option(None, "--dask", help=DASK_HELP),
    scheduler: str = typer.Option(None, "--scheduler", hidden=True, help="Deprecated name of --dask."),
) -> None:
    """Stability map L_perp/d, L_par/d over (model, phi, e), written to netCDF with full metadata."""
    from ..hcs.stability_map import stability_map
    from ..io import write_netcdf
    from ._progress import DelayedProgress

    _kind_of_output(out, (".nc",))
    _check_count("--n-phi", n_phi, 1)
    _check_count("--n-e", n_e, 1)
    check_points(n_phi * n_e, "--n-phi x --n-e")
    check_range("--workers", workers, low=0, high=256, why="local processes")
    check_range("smallest solid fraction phi-min", phi_min, low=PHI_MIN, high=1.0, high_open=True)
    check_range("largest solid fraction phi-max", phi_max, low=phi_min, high=1.0, high_open=True)
    check_range("smallest restitution coefficient e-min", e_min, low=0.0, high=1.0, low_open=True)
    check_range("largest restitution coefficient e-max", e_max, low=e_min, high=1.0)
    models = _models(model, model_file)
    phi = np.linspace(phi_min, phi_max, n_phi)
    e = np.linspace(e_min, e_max, n_e)
    start = time.perf_counter()
    from ..sweep import open_executor

    dask = deprecated_alias(dask, scheduler, "--scheduler", "--dask")
    with open_executor(workers, dask) as executor, DelayedProgress("stability map") as bar:
        ds = stability_map(models, phi, e, executor=executor, progress=bar)
    path = write_netcdf(ds, out)
    typer.echo(f"wrote {path}: {len(models)} models x {n_phi} phi x {n_e} e in {time.perf_counter() - start:.2f} s")


@handle_errors
def plot_stability_map_cmd(
    out: Path = typer.Option(Path("stability_map.png"), "--out", "-o", help="Output figure (.png/.pdf/.svg)."),
    e: str = typer.Option("0.9,0.7", "--e", help="Restitution coefficients, one panel each."),
    model: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    phi_min: float = typer.Option(0.01, "--phi-min", help="Smallest solid fraction (> 0)."),
    phi_max: float = typer.Option(0.6, "--phi-max", help="Largest solid fraction (< 1)."),
    n_phi: int = typer.Option(300, "--n-phi", help="Number of solid fractions."),
    source: Path = typer.Option(None, "--from", help="Plot a map written by `ktgf hcs map` instead of computing one."),
) -> None:
    """Critical box sizes L_perp/d and L_par/d against phi for several models (log y), one panel per e."""
    from ..hcs.stability_map import stability_map
    from ..plotting.hcs import plot_stability_map

    _kind_of_output(out, ("figure",))
    es = parse_values(e, "e")
    check_range("restitution coefficient e", es, low=0.0, high=1.0, low_open=True)
    if source is not None:
        from ..io import read_dataset

        ds = read_dataset(source, ("phi", "e", "L_perp", "L_par"), "stability map written by `ktgf hcs map`")
    else:
        _check_count("--n-phi", n_phi, 2)
        check_range("smallest solid fraction phi-min", phi_min, low=0.0, high=1.0, low_open=True, high_open=True)
        check_range("largest solid fraction phi-max", phi_max, low=phi_min, high=1.0, high_open=True)
        ds = stability_map(_models(model, model_file), np.linspace(phi_min, phi_max, n_phi), es)
    typer.echo(f"wrote {plot_stability_map(ds, es, out)}")


@handle_errors
def plot_dispersion_cmd(
    model: str = typer.Option("ret", "--model", "-m", help="Model name."),
    model_file: Path = model_file_option(),
    phi: float = typer.Option(..., "--phi", help="Solid fraction."),
    e: float = typer.Option(..., "--e", help="Restitution coefficient."),
    out: Path = typer.Option(Path("dispersion.png"), "--out", "-o", help="Output figure (.png/.pdf/.svg)."),
    k_max: float = typer.Option(None, "--k-max", help="Largest k* = k ell shown (default 2 x the larger threshold)."),
    box: float = typer.Option(None, "--box", help="Mark the lowest mode of a periodic cube of side L/d."),
) -> None:
    """Growth rates s(k*) of the shear and longitudinal modes, unstable bands shaded."""
    from ..calibration.model_file import load_model_file
    from ..plotting.hcs import plot_dispersion

    _kind_of_output(out, ("figure",))
    m = load_model_file(model_file).model if model_file is not None else get_model(model)
    m.check(phi, e)
    check_range("solid fraction phi", phi, low=PHI_MIN)
    if k_max is not None:
        # k* = k ell: hydrodynamics holds for k ell below ~1; far above, k*^2 overflows
        check_range("largest wavenumber k-max", k_max, low=0.0, high=1e3, low_open=True, why="k* = k ell")
    if box is not None:
        _check_box(box)
    typer.echo(f"wrote {plot_dispersion(m, phi, e, out, k_max=k_max, box=box)}")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    hcs_app.command("haff")(haff)
    hcs_app.command("stability")(stability)
    hcs_app.command("map")(map_cmd)
    app.add_typer(hcs_app, name="hcs")
    plot_app.command("stability-map")(plot_stability_map_cmd)
    plot_app.command("dispersion")(plot_dispersion_cmd)
