"""``ktgf models``, ``ktgf coefficients`` and ``ktgf plot coefficients``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer

from ..closures import list_models
from ._common import MODEL_HELP, VALUES_HELP, OutputFormat, emit, handle_errors, model_file_option, parse_values, resolve_models

REDUCED_NAMES = {
    "p": "p*", "eta": "eta*", "lambda_b": "lambda_b*", "kappa": "kappa*", "mu": "mu*",
    "zeta0": "zeta0*", "zeta_u": "zeta_U",
}
SI_NAMES = {
    "p": "p [Pa]", "eta": "eta [Pa s]", "lambda_b": "lambda_b [Pa s]", "kappa": "kappa [kg/(m s)]",
    "omega": "omega [W/m]", "zeta0": "zeta0 [1/s]",
}


def model_rows(models: list | None = None) -> list[dict[str, str]]:
    """One row per model (default: the registered ones): parts, options and references (feeds the CLI and docs/models.md)."""
    return [
        {
            "name": m.name,
            "label": m.label,
            "theory": m.theory.label,
            "rdf": m.rdf.describe(),
            "viscosity": m.viscosity.label,
            "dissipation": m.dissipation.label,
            "friction": m.friction.describe(),
            "options": ", ".join(f"{k}={v}" for k, v in m.options().items()),
            "reference": m.theory.reference,
            "description": m.description,
        }
        for m in (list_models() if models is None else models)
    ]


@handle_errors
def models(
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
    model_file: Path = model_file_option(),
) -> None:
    """List the registered closure models with their parts, references and options (or describe a model file)."""
    if model_file is None:
        emit(model_rows(), fmt, title="ktgf closure models")
        return
    from ..calibration.model_file import load_model_file

    mf = load_model_file(model_file)
    row = {**model_rows([mf.model])[0], "base": mf.base, "walls": ", ".join(f"{k}={v:g}" for k, v in mf.walls.items()),
           "fit": ", ".join(f"{n}={v:.6g}+-{s:.2g}" for n, v, s in zip(mf.fit.get("parameters", []), mf.fit.get("values", []),
                                                                        mf.fit.get("standard_errors", []))),
           "cost": mf.fit.get("cost", ""),
           "data": ", ".join(f"{d.get('file')} (sha256 {str(d.get('sha256', ''))[:12]})" for d in mf.provenance.get("data", [])),
           "created": mf.provenance.get("created", ""), "ktgf_version": mf.provenance.get("ktgf_version", "")}
    if fmt == OutputFormat.table:
        emit([{"field": k, "value": str(v)} for k, v in row.items()], fmt, title=f"model file {model_file}")
    else:
        emit([row], fmt)


@handle_errors
def coefficients(
    model: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    phi: str = typer.Option(..., "--phi", help="Solid fraction: " + VALUES_HELP + "."),
    e: str = typer.Option(..., "--e", help="Restitution coefficient(s), 0 < e <= 1."),
    theta: float = typer.Option(1e-2, "--theta", help="Granular temperature theta [m^2/s^2] for SI values."),
    d: float = typer.Option(1e-3, "--d", help="Particle diameter [m]."),
    rho_s: float = typer.Option(1500.0, "--rho-s", help="Material density [kg/m^3]."),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Reduced and SI transport coefficients of the models at states (phi, e)."""
    from ..errors import InputError
    from ..validation import check_material

    ms = resolve_models(model, model_file)
    check_material(d=d, theta=theta, rho_s=rho_s)
    phis, es = np.meshgrid(parse_values(phi, "phi"), parse_values(e, "e"), indexing="ij")
    phis, es = phis.ravel(), es.ravel()
    tiny = (phis > 0) & (phis < 1e-10)
    if tiny.any():  # the SI coefficients scale with 1/phi: they overflow between 0 and 1e-10
        raise InputError(f"solid fraction phi = {phis[tiny][0]:g} is out of range: valid phi = 0 or phi >= 1e-10")
    rows = []
    for m in ms:
        red = m.reduced(phis, es)
        si = m.coefficients(phis, es, theta, d=d, rho_s=rho_s)
        for i in range(phis.size):
            row: dict[str, float | str] = {"model": m.name, "phi": float(phis[i]), "e": float(es[i])}
            row.update({label: float(np.broadcast_to(getattr(red, k), phis.shape)[i]) for k, label in REDUCED_NAMES.items()})
            row.update({label: float(np.broadcast_to(getattr(si, k), phis.shape)[i]) for k, label in SI_NAMES.items()})
            rows.append(row)
    emit(rows, fmt, title=f"{', '.join(m.label for m in ms)}: theta={theta:g} m^2/s^2, d={d:g} m, rho_s={rho_s:g} kg/m^3")


@handle_errors
def plot_coefficients(
    e: float = typer.Option(0.9, "--e", help="Restitution coefficient."),
    out: Path = typer.Option(Path("coefficients.png"), "--out", "-o", help="Output figure file."),
    phi_max: float = typer.Option(0.6, "--phi-max", help="Largest solid fraction plotted."),
    models: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
) -> None:
    """Reduced p*, eta*, kappa*, mu*, zeta0* vs phi for several models on one figure."""
    from ..plotting.coefficients import plot_reduced_coefficients

    path = plot_reduced_coefficients(resolve_models(models, model_file, option="--models"), e=e, phi_max=phi_max, out=out)
    typer.echo(f"wrote {path}")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("models")(models)
    app.command("coefficients")(coefficients)
    plot_app.command("coefficients")(plot_coefficients)
