"""Haff's law for the homogeneous cooling state (model.md §8).

A uniform gas at rest cools as dθ/dt = −ζ0(θ)θ.  Every closure here has ζ0 ∝ √θ, so

    θ(t) = θ0/(1 + t/t0)²,     t0 = 2/ζ0(θ0)

(Haff, J. Fluid Mech. 134, 401 (1983)).

Frictional models cool with the homogeneous-cooling dissipation of their friction part (``Model.reduced(...,
hcs=True)``): rotation at its HCS ratio T_rot/T, which the translational temperature θ here drags along
(Luding, Huthmann, McNamara & Zippelius, Phys. Rev. E 58, 3416 (1998); ``docs/friction.md`` §7).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .._array import asarray, namespace
from ..closures.coefficients import nu0
from ..closures.models import Model, get_model
from ..errors import ConvergenceError, InputError
from ..validation import check_positive, check_range


def cooling_rate(model: Model | str, phi: Any, e: Any, theta0: Any, *, d: float) -> Any:
    """ζ0(θ0) = ν0(φ, θ0) ζ0*(φ, e) [1/s] for particles of diameter ``d`` [m]."""
    model = get_model(model)
    check_positive("granular temperature theta0", theta0, "m^2/s^2")  # required here (None is not "no theta")
    model.check(phi, e, theta0)  # on the values as given, so that the error names them
    check_positive("particle diameter d", d, "m")
    phi, e, theta0 = asarray(phi), asarray(e), asarray(theta0)
    return nu0(phi, theta0, d) * model.reduced(phi, e, check=False, hcs=True).zeta0


def cooling_time(model: Model | str, phi: Any, e: Any, theta0: Any, *, d: float) -> Any:
    """Haff time t0 = 2/ζ0(θ0) [s]; θ halves its square root after t0 (``inf`` for an elastic gas, e = 1)."""
    zeta = cooling_rate(model, phi, e, theta0, d=d)
    xp = namespace(zeta)
    return xp.where(zeta > 0, 2.0 / xp.where(zeta > 0, zeta, 1.0), xp.inf)


def haff_temperature(t: Any, theta0: Any, t0: Any) -> Any:
    """θ(t) = θ0/(1 + t/t0)² (Haff's law)."""
    return theta0 / (1.0 + asarray(t) / t0) ** 2


def integrate_cooling(
    model: Model | str,
    phi: float,
    e: float,
    theta0: float,
    t: Any,
    *,
    d: float,
    rho_s: float = 2500.0,
    rtol: float = 1e-10,
) -> np.ndarray:
    """θ(t) by integrating dθ/dt = −ζ0(θ)θ numerically (``scipy.integrate.solve_ivp``, DOP853).

    Independent of Haff's closed form: ζ0(θ) is the model's own SI cooling rate
    (:meth:`Model.coefficients`) evaluated at the current θ, so no θ-scaling is assumed.
    The unknown is ln θ (d ln θ/dt = −ζ0(θ)), which keeps θ positive.

    Parameters
    ----------
    model : Model or str
        Closure model.
    phi, e, theta0 : float
        Solid fraction, restitution coefficient and initial temperature θ0 [m²/s²].
    t : array_like
        Output times [s], non-decreasing, t ≥ 0.
    d : float
        Particle diameter [m].
    rho_s : float
        Material density [kg/m³] (ζ0 does not depend on it).
    rtol : float
        Relative tolerance of the integrator (absolute tolerance on ln θ is ``rtol`` too).
    """
    from scipy.integrate import solve_ivp

    model = get_model(model)
    model.check(phi, e, theta0)
    check_positive("particle diameter d", d, "m")
    t = np.asarray(t, dtype=float)
    check_range("time t", t, low=0.0, why="s")
    if np.any(np.diff(t) < 0):
        raise InputError("times t must be non-decreasing")

    def rhs(_: float, y: np.ndarray) -> np.ndarray:
        theta = np.exp(y[0])
        return np.array([-float(model.coefficients(phi, e, theta, d=d, rho_s=rho_s, check=False, hcs=True).zeta0)])

    t_end = float(t.max()) if t.size else 0.0
    if t_end == 0.0:
        return np.full(t.shape, float(theta0))
    sol = solve_ivp(rhs, (0.0, t_end), [np.log(theta0)], method="DOP853", t_eval=t.ravel(), rtol=rtol, atol=rtol)
    if not sol.success:  # pragma: no cover - DOP853 does not fail on this smooth scalar ODE
        raise ConvergenceError(f"Haff integration failed: {sol.message}")
    return np.exp(sol.y[0]).reshape(t.shape)


def haff_history(
    models: Sequence[Model | str],
    phi: float,
    e: float,
    theta0: float,
    *,
    d: float,
    t_end: float | None = None,
    n: int = 200,
) -> Any:
    """Cooling histories of several models as an xarray Dataset (dims ``model``, ``t``).

    Variables: ``theta_haff`` (closed form), ``theta_numeric`` (:func:`integrate_cooling`), and per
    model ``zeta0`` [1/s] and ``t0`` [s].  The time axis is t = 0 followed by ``n − 1`` points
    spaced geometrically from 10⁻³ t_end to ``t_end`` (default: 10 × the longest t0), which suits the
    log–log plot of the t⁻² tail; attrs from :func:`ktgf.io.run_metadata`.
    """
    import json

    import xarray as xr

    from ..io import run_metadata

    models = [get_model(m) for m in models]
    if not models:
        raise InputError("at least one model is needed")
    zeta = np.array([float(cooling_rate(m, phi, e, theta0, d=d)) for m in models])
    t0 = np.array([float(cooling_time(m, phi, e, theta0, d=d)) for m in models])
    if t_end is None:
        finite = t0[np.isfinite(t0)]
        t_end = 10.0 * float(np.max(finite)) if finite.size else 10.0  # 10 × the longest Haff time
    check_positive("end time t_end", t_end, "s")
    check_range("number of output times n", n, low=2)
    t = np.concatenate([[0.0], np.geomspace(1e-3 * t_end, t_end, n - 1)])
    theta_haff = np.stack([haff_temperature(t, theta0, t0_m) for t0_m in t0])
    theta_num = np.stack([integrate_cooling(m, phi, e, theta0, t, d=d) for m in models])
    ds = xr.Dataset(
        {
            "theta_haff": (("model", "t"), theta_haff, {"long_name": "granular temperature, Haff's law", "units": "m2 s-2"}),
            "theta_numeric": (("model", "t"), theta_num, {"long_name": "granular temperature, integrated", "units": "m2 s-2"}),
            "zeta0": ("model", zeta, {"long_name": "cooling rate at theta0", "units": "s-1"}),
            "t0": ("model", t0, {"long_name": "Haff time 2/zeta0(theta0)", "units": "s"}),
        },
        coords={
            "model": [m.name for m in models],
            "model_label": ("model", [m.label or m.name for m in models]),
            "t": ("t", t, {"units": "s"}),
        },
    )
    ds.attrs.update(run_metadata(None, phi=phi, e=e, theta0=theta0, d=d, t_end=t_end, n=n))
    ds.attrs["models"] = json.dumps({m.name: m.metadata() for m in models})
    return ds
