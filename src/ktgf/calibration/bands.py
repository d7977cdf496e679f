"""Prediction bands: ±1σ of a predicted quantity from the fitted parameters' covariance (delta method).

σ_y² = J C Jᵀ (diagonal), J = ∂y/∂p at the fitted values, C the covariance written by ``ktgf
calibrate`` (:meth:`~ktgf.calibration.model_file.ModelFile.covariance`).  Linear in the parameters:
a band is honest where the prediction is close to linear over ±σ of the parameters, and it holds
only the parameters' uncertainty (not the model's own error, which cross-validation measures).

uniform shear
    J by ``jax.jacfwd`` of the closed forms (:func:`ktgf.shear.steady.steady_shear`,
    ``check=False``) with the fitted options as JAX values, compiled once per process and model; or
    (``method="differences"``) by central differences evaluated in one vectorised NumPy call, which
    spares a single command the JAX import and compilation (seconds, more than the prediction).
    Central differences point by point for a model whose closures cannot be traced or that carries a
    frictional stress (NumPy-only); the result says which.
Couette cell
    J by the implicit-function theorem of :class:`~ktgf.calibration.residuals.CouetteTerm` (the
    solver is NumPy).  When the specularity is fitted to the DEM slip for each prediction
    (``ktgf couette compare`` without walls in the model file) it follows the parameters: the
    derivative is taken along u_slip = const, dy/dp − (∂y/∂φ')(∂u/∂φ')⁻¹ ∂u/∂p.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..errors import InputError

#: Columns of ``ktgf shear`` that get a band (the others do not depend on fitted options).
SHEAR_BAND_COLUMNS = ("T", "eta_star", "eta_over_eta0", "p_over_nT", "astar", "tau_over_p", "L_over_d", "p_star")


def delta_sigma(J: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """√diag(J C Jᵀ) row by row (J: outputs × parameters)."""
    J = np.asarray(J, dtype=float)
    with np.errstate(invalid="ignore"):
        var = np.einsum("ij,jk,ik->i", J, np.asarray(cov, dtype=float), J)
    return np.sqrt(np.maximum(var, 0.0))


def _shear_columns(model: Any, phi: Any, e: Any, stress_scale: float | None = None) -> Any:
    """The banded columns of the uniform-shear state, stacked (NumPy or JAX, no range checks)."""
    from .._array import namespace
    from ..shear.steady import steady_shear

    s = steady_shear(model, phi, e, stress_scale=stress_scale, check=False)
    xp = namespace(s.T, s.eta_over_eta0)
    return xp.stack([xp.broadcast_to(getattr(s, k), xp.shape(phi)) * 1.0 for k in SHEAR_BAND_COLUMNS])


#: ``jit(jacfwd(...))`` of the banded columns by (model, names, shape of the points): op-by-op
#: ``jacfwd`` costs seconds per call, the compiled one ~1 ms after one trace and compilation (~2 s).
_JACOBIANS: dict[tuple, Any] = {}
_JACOBIANS_MAX = 16


def _compiled_jacobian(model: Any, names: tuple[str, ...], shape: tuple[int, ...], e_value: float | None = None) -> Any:
    """``fn(x, phi, e)``; with ``e_value`` the restitution is that constant (``e`` is ignored) and part of the key."""
    import jax

    from .residuals import traced_model

    key = (model, names, shape, e_value)
    try:
        fn = _JACOBIANS.get(key)
    except TypeError:  # an unhashable option: no caching
        key, fn = None, None
    if fn is None:
        def f(x, phi, e):
            return _shear_columns(traced_model(model, dict(zip(names, x))), phi, e if e_value is None else e_value)

        fn = jax.jit(jax.jacfwd(f))
        if key is not None:
            if len(_JACOBIANS) >= _JACOBIANS_MAX:
                _JACOBIANS.pop(next(iter(_JACOBIANS)))
            _JACOBIANS[key] = fn
    return fn


JACOBIANS = ("jax", "differences")


def _vectorised_jacobian(model: Any, names: Sequence[str], x: np.ndarray, h: np.ndarray, phi: np.ndarray, e: Any,
                         method: str) -> np.ndarray:
    """(columns, points, parameters) by JAX or by vectorised central differences (see :func:`shear_jacobian`)."""
    from .residuals import enable_x64, traced_model

    if method == "jax":
        import jax.numpy as jnp

        enable_x64()
        scalar = np.ndim(e) == 0
        fn = _compiled_jacobian(model, tuple(names), phi.shape, float(e) if scalar else None)
        return np.asarray(fn(jnp.asarray(x, dtype=jnp.float64), jnp.asarray(phi), jnp.asarray(e)))
    X = np.repeat(x[None, :], 2 * x.size, axis=0)
    for j in range(x.size):
        X[2 * j, j] += h[j]
        X[2 * j + 1, j] -= h[j]
    shape = (2 * x.size, phi.size)
    with np.errstate(all="ignore"):
        cols = _shear_columns(traced_model(model, {n: X[:, j:j + 1] for j, n in enumerate(names)}),
                              np.broadcast_to(phi, shape), e if np.ndim(e) == 0 else np.broadcast_to(e, shape))
    return np.stack([(cols[:, 2 * j] - cols[:, 2 * j + 1]) / (2 * h[j]) for j in range(x.size)], axis=-1)


def shear_jacobian(model: Any, names: Sequence[str], phi: np.ndarray, e: np.ndarray, *,
                   stress_scale: float | None = None, method: str = "jax") -> tuple[np.ndarray, str]:
    """∂(banded columns)/∂(options ``names``) at the points (φ_i, e_i): array (columns, points, parameters), method used.

    ``method="jax"``: ``jax.jit(jax.jacfwd(...))`` (exact; the first call in a process imports JAX and
    compiles, ~1–3 s); ``"differences"``: central differences, all 2n parameter sets in one vectorised
    NumPy evaluation (options set as column arrays; relative error ~1e-8, no JAX).  A model with a friction
    part is evaluated one restitution at a time (its rotational balance is solved for a scalar e).  A model
    that cannot be traced, or with a frictional stress, falls back to central differences of
    :func:`~ktgf.shear.steady.steady_shear` one restitution at a time (checked, as ``ktgf shear``).
    """
    from .residuals import model_at

    if method not in JACOBIANS:
        raise InputError(f"band Jacobian {method!r} is not valid; choose one of {', '.join(JACOBIANS)}")
    values = {n: float(model.options()[n]) for n in names}
    phi, e = np.asarray(phi, dtype=float), np.asarray(e, dtype=float)
    x = np.array([values[n] for n in names])
    h = 1e-6 * np.maximum(np.abs(x), 1e-2)
    by_e = [(np.flatnonzero(e == v), float(v)) for v in np.unique(e)]
    J = np.empty((len(SHEAR_BAND_COLUMNS), phi.size, x.size))
    if not model.friction.has_stress:
        try:
            groups = by_e if model.friction.key != "none" else [(np.arange(phi.size), e)]
            for idx, ev in groups:
                J[:, idx, :] = _vectorised_jacobian(model, names, x, h, phi[idx], ev, method)
            with np.errstate(all="ignore"):
                if np.all(np.isfinite(J)) or not all(np.all(np.isfinite(_shear_columns(model, phi[i], v))) for i, v in by_e):
                    return J, method
        except Exception:  # noqa: BLE001, S110  (a part that is not JAX or array code: central differences below, and say so)
            pass
    from ..shear.steady import steady_shear

    for idx, ev in by_e:  # one restitution at a time, as ktgf shear (a friction part needs a scalar e)
        def g(v: dict[str, float], idx=idx, ev=ev) -> np.ndarray:
            s = steady_shear(model_at(model, v), phi[idx], ev, stress_scale=stress_scale)
            return np.array([np.broadcast_to(getattr(s, k), idx.shape) for k in SHEAR_BAND_COLUMNS])

        for j, n in enumerate(names):
            J[:, idx, j] = (g({**values, n: values[n] + h[j]}) - g({**values, n: values[n] - h[j]})) / (2 * h[j])
    return J, "central differences, point by point"


def shear_bands(model: Any, names: Sequence[str], cov: np.ndarray, phi: np.ndarray, e: np.ndarray, *,
                stress_scale: float | None = None, method: str = "jax") -> tuple[dict[str, np.ndarray], str]:
    """±1σ of every banded column at every (φ, e) of the grid (φ outer, e inner, as ``ktgf shear``), and the method."""
    phis, es = (a.ravel() for a in np.meshgrid(np.asarray(phi, float), np.asarray(e, float), indexing="ij"))
    J, method = shear_jacobian(model, names, phis, es, stress_scale=stress_scale, method=method)
    return {k: delta_sigma(J[i], cov) for i, k in enumerate(SHEAR_BAND_COLUMNS)}, method


def couette_bands(model: Any, names: Sequence[str], cov: np.ndarray, dem: Any, *, specularity: float,
                  wall_restitution: float | None = None, slip_fitted: bool, n_cells: int = 200) -> dict[str, float]:
    """±1σ of the wall shear stress and wall pressure of a DEM Couette cell (module notes).

    ``names`` may hold model options and the wall parameters; ``slip_fitted``: the specularity is
    re-fitted to the DEM slip for every prediction (then it must not be among ``names``).
    """
    from .residuals import CouetteTerm

    walls = {"specularity": specularity, "wall_restitution": dem.case.e if wall_restitution is None else wall_restitution}
    if slip_fitted and "specularity" in names:
        raise InputError("the specularity is both fitted in the model file and fitted to the DEM slip")
    wrt = list(names) + (["specularity"] if slip_fitted else [])
    term = CouetteTerm(dem, model, wrt, "relative", n_cells=n_cells, fixed={k: v for k, v in walls.items() if k not in wrt})
    values = {n: float(walls[n]) if n in walls else float(model.options()[n]) for n in wrt}
    J = term.jacobian(values) * term.scale[:, None]  # d(tau, p, slip)/d(parameters), unweighted
    if slip_fitted:
        du_ds = J[2, -1]
        J = J[:, :-1] - np.outer(J[:, -1], J[2, :-1] / du_ds)
    sig = delta_sigma(J[:2], cov)
    return {"tau_wall": float(sig[0]), "p": float(sig[1])}


__all__ = ["JACOBIANS", "SHEAR_BAND_COLUMNS", "couette_bands", "delta_sigma", "shear_bands", "shear_jacobian"]
