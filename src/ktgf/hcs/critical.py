"""Critical wavenumbers by root-finding on the eigenvalues of the HCS stability problem (model.md §8).

Independent of the closed forms in :mod:`ktgf.hcs.stability`: for each state the largest growth
rate of a mode family (the shear mode s⊥, or the largest real part of the three longitudinal
eigenvalues of −M) is scanned on a geometric k* grid; the *last* sign change from unstable to
stable is bracketed and refined with Brent's method.  That is the threshold a periodic box
sees: every wavenumber above it is stable.

A scan that finds no crossing says so: if the mode is still unstable at the end of the scan,
:class:`NoCrossingError` is raised (or, with ``on_no_crossing="inf"``, ``inf`` is returned with
a :class:`NoCrossingWarning`); if it is stable at every scanned wavenumber the answer is 0 (no
unstable band: every box is stable).
"""

from __future__ import annotations

import warnings
from typing import Any, Callable, Literal

import numpy as np
from scipy.optimize import brentq

from ..closures.coefficients import Reduced
from ..errors import ConvergenceError, InputError
from ..validation import check_positive
from .dispersion import dispersion_relation, expand_states

OnNoCrossing = Literal["raise", "inf"]

#: Default scan: k* = kℓ from 1e-5 (a box 10^5 mean free paths wide) to 1e3 (far below ℓ).
K_MIN, K_MAX, N_SCAN = 1e-5, 1e3, 241


class NoCrossingError(ConvergenceError):
    """The growth rate never changed sign from unstable to stable inside the scanned k* range."""


class NoCrossingWarning(UserWarning):
    """A mode was still unstable at the end of the scan and ``inf`` was returned for it."""


def last_crossing(
    growth: Callable[[np.ndarray], np.ndarray],
    *,
    k_min: float = K_MIN,
    k_max: float = K_MAX,
    n_scan: int = N_SCAN,
    on_no_crossing: OnNoCrossing = "raise",
    what: str = "mode",
    scanned: np.ndarray | None = None,
) -> float:
    """Largest k* at which ``growth`` (vectorised, real) changes sign from > 0 to ≤ 0.

    Parameters
    ----------
    growth : callable
        k* array -> growth rate array (same shape).
    k_min, k_max, n_scan : float, float, int
        Geometric scan grid used to bracket the root.
    on_no_crossing : {"raise", "inf"}
        What to do when the mode is still unstable at ``k_max``.
    what : str
        Name of the mode and state, for messages.
    scanned : ndarray, optional
        ``growth`` already evaluated on the scan grid (saves the scan when many states are batched).

    Returns
    -------
    float
        The critical wavenumber; 0.0 if the mode is stable on the whole grid.
    """
    grid = np.geomspace(k_min, k_max, n_scan)
    s = np.asarray(growth(grid) if scanned is None else scanned, dtype=float)
    if np.isnan(s).any():
        raise NoCrossingError(f"{what}: growth rate is NaN on the k* scan [{k_min:g}, {k_max:g}]")
    if s[-1] > 0:
        msg = (
            f"{what}: no crossing found, the growth rate is still positive (s = {s[-1]:.3g} ν0) at the end of "
            f"the scan k* = {k_max:g}; the mode is unstable at every scanned wavenumber (k_c > {k_max:g})"
        )
        if on_no_crossing == "inf":
            warnings.warn(msg, NoCrossingWarning, stacklevel=3)
            return float("inf")
        raise NoCrossingError(msg)
    unstable = np.flatnonzero(s > 0)
    if unstable.size == 0:
        return 0.0
    i = int(unstable[-1])
    if s[i + 1] == 0.0:
        return float(grid[i + 1])

    def f(k: float) -> float:
        return float(growth(np.array(k)))

    return float(brentq(f, grid[i], grid[i + 1], xtol=1e-15, rtol=4e-15, maxiter=200))


def critical_wavenumbers_eig(
    r: Reduced,
    *,
    k_min: float = K_MIN,
    k_max: float = K_MAX,
    n_scan: int = N_SCAN,
    on_no_crossing: OnNoCrossing = "raise",
) -> tuple[np.ndarray, np.ndarray]:
    """Critical (k⊥*, k∥*) of states ``r`` from the eigenvalues, by scan + Brent root-finding.

    The longitudinal threshold is where the largest real part of the eigenvalues of −M(k*)
    last crosses zero, whichever mode (real or complex pair) crosses; for the paper's models it
    agrees with the closed form of :func:`ktgf.hcs.stability.critical_wavenumbers`.

    Returns arrays with the broadcast shape of the coefficients in ``r``.
    """
    check_positive("k_min", k_min)
    if not k_max > k_min or n_scan < 3:
        raise InputError(f"k* scan needs 0 < k_min < k_max and n_scan >= 3, got k_min={k_min}, k_max={k_max}, n_scan={n_scan}")
    shape = np.broadcast_shapes(*(np.shape(v) for v in r))
    flat = Reduced(*(np.broadcast_to(np.asarray(v, dtype=float), shape).ravel() for v in r))
    grid = np.geomspace(k_min, k_max, n_scan)
    scan = dispersion_relation(expand_states(flat), grid)
    s_perp, s_par = scan.transverse, scan.largest_longitudinal
    k_perp = np.empty(flat.p.shape)
    k_par = np.empty(flat.p.shape)
    opts: dict[str, Any] = dict(k_min=k_min, k_max=k_max, n_scan=n_scan, on_no_crossing=on_no_crossing)
    for j in range(flat.p.size):
        rj = Reduced(*(v[j] for v in flat))
        label = f"state {j} (p*={rj.p:.4g}, zeta0*={rj.zeta0:.4g})"
        k_perp[j] = last_crossing(
            lambda k, rj=rj: dispersion_relation(rj, k).transverse,
            scanned=s_perp[j], what=f"transverse mode, {label}", **opts,
        )
        k_par[j] = last_crossing(
            lambda k, rj=rj: dispersion_relation(rj, k).largest_longitudinal,
            scanned=s_par[j], what=f"longitudinal modes, {label}", **opts,
        )
    return k_perp.reshape(shape), k_par.reshape(shape)
