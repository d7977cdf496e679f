"""Stability maps: critical wavenumbers and box sizes over (model, φ, e) as an xarray Dataset.

The closed forms of :mod:`ktgf.hcs.stability` are vectorised over the whole (φ, e) grid, so a
4 × 200 × 100 map is a few array operations.  Larger sweeps can be split into (model, φ-block)
tasks and run through :func:`ktgf.sweep.map_tasks` on any ``concurrent.futures`` executor or a
Dask ``distributed.Client``; the result is identical.  States at or beyond a model's packing
limit are NaN.
"""

from __future__ import annotations

import json
from typing import Any, Callable, Sequence

import numpy as np

from ..closures.models import Model, get_model
from ..errors import InputError
from ..sweep import map_tasks
from ..validation import check_range
from .stability import critical_box_size, critical_wavenumbers

VARIABLES = {
    "k_perp": {"long_name": "critical reduced wavenumber of the transverse (vortex) mode, k_perp* = k ell", "units": "1"},
    "k_par": {"long_name": "critical reduced wavenumber of the longitudinal (cluster) mode, k_par* = k ell", "units": "1"},
    "L_perp": {"long_name": "critical side of a periodic cube for vortices, L_perp/d, in particle diameters", "units": "1"},
    "L_par": {"long_name": "critical side of a periodic cube for clusters, L_par/d, in particle diameters", "units": "1"},
}


def map_block(task: tuple[Model, np.ndarray, np.ndarray]) -> dict[str, np.ndarray]:
    """Critical wavenumbers and box sizes of one model on a (φ, e) block (a picklable sweep task).

    Returns arrays of shape (len(φ), len(e)); NaN where φ ≥ the model's packing limit.
    """
    model, phi, e = task
    phi2, e2 = np.meshgrid(np.asarray(phi, dtype=float), np.asarray(e, dtype=float), indexing="ij")
    valid = phi2 < model.phi_max
    # Evaluate beyond the packing limit at a harmless stand-in state, then blank it out.
    r = model.reduced(np.where(valid, phi2, 0.5 * model.phi_max), e2, check=False, hcs=True)
    k_perp, k_par = (np.broadcast_to(k, phi2.shape) for k in critical_wavenumbers(r))
    out = {
        "k_perp": k_perp,
        "k_par": k_par,
        "L_perp": critical_box_size(phi2, k_perp),
        "L_par": critical_box_size(phi2, k_par),
    }
    return {name: np.where(valid, v, np.nan) for name, v in out.items()}


def stability_map(
    models: Sequence[Model | str],
    phi: Any,
    e: Any,
    executor: Any = None,
    progress: Callable[[int, int], None] | None = None,
    *,
    phi_chunks: int | None = None,
) -> Any:
    """Critical wavenumbers k⊥*, k∥* and box sizes L⊥/d, L∥/d over (model, φ, e) (model.md §8).

    Parameters
    ----------
    models : sequence of Model or str
        Models (registered names or Model objects; user models work if picklable for the executor).
    phi, e : array_like (1-D)
        Solid fractions 0 < φ < 1 and restitution coefficients 0 < e ≤ 1.  Each model is NaN where
        φ ≥ its packing limit.
    executor : concurrent.futures.Executor or dask Client, optional
        Where to run the (model, φ-block) tasks; ``None`` computes in-process.
    progress : callable(done, total), optional
        Called as blocks finish (e.g. a progress bar).
    phi_chunks : int, optional
        φ blocks per model; default 1 in-process without progress, else 8 (capped at len(φ)).

    Returns
    -------
    xarray.Dataset
        ``k_perp``, ``k_par`` (reduced, k* = kℓ), ``L_perp``, ``L_par`` (in particle diameters) with
        dims (model, phi, e); attrs from :func:`ktgf.io.run_metadata` plus every model's metadata
        (JSON, attribute ``models``).  k∥* = inf (L∥ = 0) marks states whose heat mode is unstable at
        every wavenumber; k* = 0 (L = inf) marks stability at every size (e = 1).
    """
    import xarray as xr

    from ..io import run_metadata

    models = [get_model(m) for m in models]
    if not models:
        raise InputError("stability_map needs at least one model")
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    e = np.atleast_1d(np.asarray(e, dtype=float))
    if phi.ndim != 1 or e.ndim != 1 or phi.size == 0 or e.size == 0:
        raise InputError("phi and e must be non-empty 1-D arrays")
    check_range("solid fraction phi", phi, low=0.0, high=1.0, low_open=True, high_open=True)
    check_range("restitution coefficient e", e, low=0.0, high=1.0, low_open=True)
    if phi_chunks is None:
        phi_chunks = 1 if (executor is None and progress is None) else 8
    if phi_chunks < 1:
        raise InputError(f"phi_chunks = {phi_chunks} is out of range: valid phi_chunks >= 1")
    blocks = np.array_split(phi, min(phi_chunks, phi.size))
    tasks = [(m, block, e) for m in models for block in blocks]
    results = map_tasks(map_block, tasks, executor=executor, progress=progress)
    per_model = len(blocks)
    data = {
        name: np.stack(
            [np.concatenate([res[name] for res in results[i * per_model:(i + 1) * per_model]], axis=0) for i in range(len(models))]
        )
        for name in VARIABLES
    }
    ds = xr.Dataset(
        {name: (("model", "phi", "e"), data[name], attrs) for name, attrs in VARIABLES.items()},
        coords={
            "model": [m.name for m in models],
            "model_label": ("model", [m.label or m.name for m in models]),
            "phi": ("phi", phi, {"long_name": "solid fraction", "units": "1"}),
            "e": ("e", e, {"long_name": "normal restitution coefficient", "units": "1"}),
        },
    )
    ds.attrs.update(
        run_metadata(
            None,
            models=[m.name for m in models],
            phi={"min": float(phi.min()), "max": float(phi.max()), "n": int(phi.size)},
            e={"min": float(e.min()), "max": float(e.max()), "n": int(e.size)},
            method="closed form, model.md section 8",
        )
    )
    ds.attrs["models"] = json.dumps({m.name: m.metadata() for m in models})
    ds.attrs["box_size_formula"] = "L/d = 2 pi ell/(d k*) = 0.8202922/(phi k*)"
    return ds
