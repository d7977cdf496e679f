"""Section 7: the fitted models against every shipped DEM file, fitted and predicted points apart.

Models: the registered models with a fit on record (:data:`ktgf.calibration.registry_fits.REGISTERED_FITS`:
``dense``, ``frictional``).  Each is run through :func:`ktgf.calibration.validate.validate` — the table
``ktgf validate --model NAME`` prints — on every DEM file the report has; a row is *fitted* when its state was
in the model's fit, else *predicted*.  The predicted rows are the number to quote: they are what a user gets
where no particle data exist.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from ..calibration.validate import Validation, fit_sources, validate
from ..closures.models import get_model, list_models
from ..data import DEM_FILES
from ..io import run_metadata
from .framework import Section, SectionContext, model_inputs, register_section
from .settings import ReportSettings

#: The models of the section, where registered: the ones whose constants were fitted to DEM.
MODELS = ("dense", "frictional")
ROLES = ("fitted", "predicted")


def section_models() -> tuple[str, ...]:
    registered = {m.name for m in list_models()}
    return tuple(n for n in MODELS if n in registered)


def inputs(s: ReportSettings) -> dict[str, Any]:
    return {"models": model_inputs(section_models()), "couette_cells": s.couette_cells}


def role_errors(v: Validation) -> dict[str, dict[str, float]]:
    """Per role, the mean |model/DEM − 1| over every answered row of each case (``case|role`` → mean), and the
    pooled mean over all cases (``all|role``)."""
    out: dict[str, dict[str, float]] = {}
    pooled: dict[str, list[float]] = {r: [] for r in ROLES}
    for r in v.rows:
        if math.isfinite(r["error"]):
            out.setdefault(r["case"], {}).setdefault(r["role"], []).append(abs(r["error"]))  # type: ignore[arg-type]
            pooled[r["role"]].append(abs(r["error"]))
    means = {case: {role: float(np.mean(e)) for role, e in roles.items()} for case, roles in out.items()}
    means["all"] = {role: float(np.mean(e)) for role, e in pooled.items() if e}
    return means


def run(ctx: SectionContext) -> None:
    names = section_models()
    files = [p for p in (ctx.data_file(n) for n in DEM_FILES) if p is not None]
    ctx.paragraph(
        "A fitted model is only as good as its error on data it was not fitted to. Each model whose constants were fitted "
        "to particle data (" + ", ".join(get_model(n).label or n for n in names) + ") is compared here with every DEM "
        "file, each row marked fitted (its state was in the fit) or predicted (it was not); the same table as "
        "`ktgf validate --model NAME`.")
    if not names or not files:
        return
    numbers: dict[str, Any] = {}
    rows: list[dict[str, Any]] = []
    fitted_on: dict[str, list[str]] = {}
    for name in names:
        ctx.step(f"{name} against {len(files)} DEM files")
        v = validate(get_model(name), files, sources=fit_sources(name), n_cells=ctx.settings.couette_cells)
        for note in v.notes:
            ctx.note(f"{name}: {note}")
        fitted_on[name] = sorted({s.file for s in v.sources})
        ctx.table(f"{get_model(name).label or name}: |model/DEM − 1| per case, quantity and role",
                  ["case", "quantity", "role", "rows", "mean |error| %", "max |error| %"],
                  [[s["case"], s["quantity"], s["role"], s["answered"], 100 * s["mean_abs_error"], 100 * s["max_abs_error"]]
                   for s in v.summary()],
                  note="fitted: " + (", ".join(fitted_on[name]) or "nothing") + f". Every row: `ktgf validate --model {name}`.",
                  with_figure=False)
        rows += [{"model_name": name, **r} for r in v.rows]
        numbers[name] = role_errors(v)
    ctx.dataset(xr.Dataset(
        {k: (("row",), np.array([r[src] for r in rows], dtype=float), {"long_name": what, "units": "1"})
         for k, src, what in (("value", "model", "model value (DEM units d = m = 1)"), ("dem", "dem", "DEM value"),
                              ("dem_sigma", "dem_sigma", "DEM standard error"), ("error", "error", "model/DEM - 1"))},
        coords={k: (("row",), np.array([str(r[src]) for r in rows]))
                for k, src in (("model", "model_name"), ("file", "file"), ("case", "case"), ("state", "state"),
                               ("quantity", "quantity"), ("role", "role"))},
        attrs=run_metadata(None, models=list(names), quantity="relative error model/DEM - 1", fitted_on=fitted_on)),
        "validation")
    ctx.number("validation", numbers)


def discuss(nb: dict[str, Any]) -> list[str]:
    out = []
    for name, cases in (nb.get("validation") or {}).items():
        pooled = cases.get("all", {})
        parts = [f"{role} {100 * pooled[role]:.1f} %" for role in ROLES if role in pooled]
        if parts:
            out.append(f"{get_model(name).label or name} against all DEM files, mean |error|: " + ", ".join(parts)
                       + " (fitted rows were in its fit; predicted rows were not).")
    return out


SECTION = register_section(Section(
    "validation", "7. Fitted models against all DEM data: fitted and predicted points", run, inputs, order=70,
    data_files=DEM_FILES, modules=("ktgf.calibration", "ktgf.shear", "ktgf.couette", "ktgf.hcs", "ktgf.data"),
    discuss=discuss,
))
