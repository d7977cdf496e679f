"""``ktgf shear``: the Navier–Stokes uniform-shear steady state in the DEM file's columns."""

from __future__ import annotations

from typing import Any

import numpy as np
import typer

from ..closures import get_model
from ..errors import InputError
from ._common import OutputFormat, emit, handle_errors, parse_values


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
    model: str = typer.Option(..., "--model", "-m", help="Model name (see `ktgf models`)."),
    phi: str = typer.Option(..., "--phi", help="Solid fraction: value, list a,b,c or range start:stop:num."),
    e: str = typer.Option(..., "--e", help="Restitution coefficient(s), 0 < e < 1."),
    option: list[str] = typer.Option(
        None, "--option", "-O", help="Model option KEY=VALUE (repeatable), e.g. phi_f=0.46."
    ),
    fmt: OutputFormat = typer.Option(OutputFormat.table, "--format", help="table, json, csv or markdown."),
) -> None:
    """Steady uniform (Lees–Edwards) shear from the closed forms of model.md §9.

    Columns as in shared/data/dem_uniform_shear.csv (d = m = 1): T = θ/(γ̇d)², eta_star = η d²/√(mT),
    eta_over_eta0 = η/η0, p_over_nT = p/(nT), astar = γ̇/ν0; tau_over_p = |P_xy|/p and L_over_d
    (extended-kinetic-theory correlation length, 1 without that option).
    """
    m = get_model(model, **parse_options(option))
    rows = shear_rows(m, parse_values(phi, "phi"), parse_values(e, "e"))
    emit(rows, fmt, title=f"{m.label or m.name}: Navier–Stokes uniform shear (d = m = 1, shear rate 1)")


def register(app: typer.Typer, plot_app: typer.Typer) -> None:
    app.command("shear")(shear)
