"""``ktgf shear``: the Navier–Stokes uniform-shear steady state in the DEM file's columns."""

from __future__ import annotations

from typing import Any

import numpy as np
import typer

from pathlib import Path

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


def shear_rows(model: Any, phi: np.ndarray, e: np.ndarray) -> list[dict[str, float]]:
    """One row per (φ, e): φ, e, T, eta_star, eta_over_eta0, p_over_nT, astar, stress ratio, L/d."""
    from ..couette.uniform_shear import shear_state

    if phi.size == 0 or e.size == 0:
        raise InputError("--phi and --e need at least one value each")
    if np.any(e >= 1.0):
        raise InputError(f"restitution coefficient e = {float(e.max()):g} is out of range: valid 0 < e < 1 "
                         "(elastic spheres have no steady uniform shear)")
    phis, es = (a.ravel() for a in np.meshgrid(phi, e, indexing="ij"))
    s = shear_state(model, phis, es)
    cols = {"T": s.T, "eta_star": s.eta_star, "eta_over_eta0": s.eta_over_eta0, "p_over_nT": s.p_over_nT,
            "astar": s.astar, "tau_over_p": s.stress_ratio, "L_over_d": s.L_over_d}
    cols = {k: np.broadcast_to(v, phis.shape) for k, v in cols.items()}
    return [{"phi": float(phis[i]), "e": float(es[i]), **{k: float(v[i]) for k, v in cols.items()}} for i in range(phis.size)]


@handle_errors
def shear(
    model: str = typer.Option(None, "--model", "--models", "-m", help=MODEL_HELP),
    model_file: Path = model_file_option(),
    phi: str = typer.Option(..., "--phi", help="Solid fraction: " + VALUES_HELP + "."),
    e: str = typer.Option(..., "--e", help="Restitution coefficient(s), 0 < e < 1."),
    option: list[str] = typer.Option(
        None, "--option", "-O", help="Model option KEY=VALUE (repeatable, applied to every model), e.g. phi_f=0.46."
    ),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Steady uniform (Lees–Edwards) shear from the closed forms of docs/model.md §9.

    Columns as in the DEM file dem_uniform_shear.csv (d = m = 1): T = θ/(γ̇d)², eta_star = η d²/√(mT),
    eta_over_eta0 = η/η0, p_over_nT = p/(nT), astar = γ̇/ν0; tau_over_p = |P_xy|/p and L_over_d
    (extended-kinetic-theory correlation length, 1 without that option).
    """
    options = parse_options(option)
    ms = [m.with_options(**options) if options else m for m in resolve_models(model, model_file)]
    phis, es = parse_values(phi, "phi"), parse_values(e, "e")
    rows = [{"model": m.name, **row} for m in ms for row in shear_rows(m, phis, es)]
    emit(rows, fmt, title=f"{', '.join(m.label or m.name for m in ms)}: Navier–Stokes uniform shear (d = m = 1, shear rate 1)")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("shear")(shear)
