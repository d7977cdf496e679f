"""``ktgf shear``: the Navier–Stokes uniform-shear steady state in the DEM file's columns."""

from __future__ import annotations

from typing import Any

import numpy as np
import typer

from pathlib import Path

from ..closures.friction.model_slot import with_friction  # ``--mu`` (cli/couette.py imports it from here)
from ..errors import InputError
from ._common import MODEL_HELP, VALUES_HELP, OutputFormat, emit, handle_errors, model_file_option, parse_values, resolve_models


def parse_options(items: list[str] | None) -> dict[str, Any]:
    """``KEY=VALUE`` strings as model options: numbers as floats, true/false as booleans, else text."""
    out: dict[str, Any] = {}
    for item in items or []:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"--option {item!r} is not KEY=VALUE")
        low = text.strip().lower()
        if low in ("true", "false"):
            value: Any = low == "true"
        else:
            try:
                value = float(text)
            except ValueError:
                value = text.strip()
        out[key.strip()] = value
    return out


def shear_rows(model: Any, phi: np.ndarray, e: np.ndarray, stress_scale: float | None = None) -> list[dict[str, float]]:
    """One row per (φ, e): φ, e, T, eta_star, eta_over_eta0, p_over_nT, astar, τ/p, L/d, T_rot/T, p_star, μ."""
    from ..shear.steady import steady_shear

    if phi.size == 0 or e.size == 0:
        raise InputError("--phi and --e need at least one value each")
    if np.any(e >= 1.0):
        raise InputError(f"restitution coefficient e = {float(e.max()):g} is out of range: valid 0 < e < 1 "
                         "(elastic spheres have no steady uniform shear)")
    # the frictionless columns first, in their original order; the frictional DEM file's columns after them
    order = ("T", "eta_star", "eta_over_eta0", "p_over_nT", "astar", "tau_over_p", "L_over_d", "Trot_over_T", "p_star")
    mu = float(model.friction.mu)
    states = [steady_shear(model, phi, float(q), stress_scale=stress_scale) for q in e]
    return [{"phi": float(p), "e": float(q), **{k: float(np.broadcast_to(getattr(s, k), phi.shape)[i]) for k in order},
             "mu": mu} for i, p in enumerate(phi) for q, s in zip(e, states)]


@handle_errors
def shear(
    model: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    phi: str = typer.Option(..., "--phi", help="Solid fraction: " + VALUES_HELP + "."),
    e: str = typer.Option(..., "--e", help="Restitution coefficient(s), 0 < e < 1."),
    mu: float = typer.Option(None, "--mu", help="Particle friction coefficient mu >= 0 (adds Walton friction to a "
                             "frictionless model; docs/friction.md)."),
    stress_scale: float = typer.Option(None, "--stress-scale", help="rho_s d^2 gdot^2 [Pa]: needed only by a model "
                                       "with a frictional stress (option stress)."),
    option: list[str] = typer.Option(
        None, "--option", "-O", help="Model option KEY=VALUE (repeatable, applied to every model), e.g. phi_f=0.46."
    ),
    band_jacobian: str = typer.Option("differences", "--band-jacobian", help="How the +-1 sigma bands of a --model-file "
                                      "fit differentiate the prediction: differences (vectorised central differences, "
                                      "relative error ~1e-8; default: a band costs about one prediction) or jax (exact "
                                      "JAX Jacobian; importing and compiling JAX costs seconds per command)."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Steady uniform (Lees–Edwards) shear from the closed forms of docs/model.md §9 (frictional: docs/friction.md).

    Columns as in the DEM files dem_uniform_shear.csv and dem_uniform_shear_friction.csv (d = m = 1, shear
    rate 1, rho_s = 6/pi): T = θ/(γ̇d)², Trot_over_T (NaN/null where the model has no rotation), p_star =
    p/(rho_s d² γ̇²), tau_over_p = |P_xy|/p, p_over_nT = p/(nT), eta_star = η d²/√(mT), eta_over_eta0 = η/η0,
    astar = γ̇/ν0 and L_over_d (extended-kinetic-theory correlation length, 1 without that option).
    With a --model-file holding a fit, *_sd columns give +-1 standard deviation of the --model-file model's values
    from the fitted covariance (delta method; docs/calibration.md).
    """
    options = parse_options(option)
    ms = [m.with_options(**options) if options else m for m in resolve_models(model, model_file)]
    ms = [with_friction(m, mu) for m in ms]
    phis, es = parse_values(phi, "phi"), parse_values(e, "e")
    rows = [{"model": m.name, **row} for m in ms for row in shear_rows(m, phis, es, stress_scale)]
    note = ""
    fit = _fit_covariance(model_file)
    if fit is not None:  # ±1σ from the model file's fitted covariance, on its model's rows (delta method)
        from ..calibration.bands import SHEAR_BAND_COLUMNS, shear_bands

        bands, method = shear_bands(ms[-1], fit[0], fit[1], phis, es, stress_scale=stress_scale, method=band_jacobian)
        own = [r for r in rows if r["model"] == ms[-1].name][-phis.size * es.size:]
        for r in rows:
            r.update({f"{k}_sd": float("nan") for k in SHEAR_BAND_COLUMNS})
        for i, r in enumerate(own):
            r.update({f"{k}_sd": float(bands[k][i]) for k in SHEAR_BAND_COLUMNS})
        note = (f"*_sd: ±1 standard deviation from the covariance of {', '.join(fit[0])} in {model_file.name} "
                f"(delta method, Jacobian by {method}); NaN for models without a fit")
    emit(rows, fmt, title=f"{', '.join(m.label or m.name for m in ms)}: Navier–Stokes uniform shear (d = m = 1, shear rate 1)")
    if note:
        typer.echo(note, err=fmt == OutputFormat.json)
    for line in extrapolation_notes(ms if model_file is None else ms[:-1], es):
        typer.echo(line, err=True)


def extrapolation_notes(models: list[Any], e: np.ndarray) -> list[str]:
    """One line per registered fitted model asked at a restitution it was not fitted at (docs/friction.md §6.2)."""
    from ..calibration.registry_fits import fitted_restitutions

    lines = []
    for m in models:
        fitted = fitted_restitutions(m.name, float(m.friction.mu))
        if fitted is None:
            continue
        outside = [float(q) for q in e if min(abs(float(q) - f) for f in fitted) > 0.025]
        if outside:
            lines.append(f"note: {m.name} (mu = {float(m.friction.mu):g}) was fitted at e = "
                         f"{', '.join(f'{f:g}' for f in fitted)} only; e = {', '.join(f'{q:g}' for q in outside)} is a "
                         "prediction (docs/friction.md §6.2: ktgf's own DEM runs put T, p/(nT) or tau/p up to 29 % off at mu = 0, "
                         "e = 0.7 and up to 89 % off at mu = 0.5, e = 0.9)")
    return lines


def _fit_covariance(model_file: Path | None) -> tuple[list[str], Any] | None:
    """(names, covariance) of a model file's fit (None without a file or a fit)."""
    if model_file is None:
        return None
    from ..calibration.model_file import load_model_file

    return load_model_file(model_file).covariance()


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("shear")(shear)
