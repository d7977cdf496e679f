"""Dispersion relations s(k*) of the linearised hydrodynamics about the HCS (model.md §8).

For every wavenumber the perturbation modes are the two (degenerate) transverse shear modes and
the three longitudinal modes (heat, longitudinal velocity, density — sound at large k*).  Growth
rates are in units of ν0 (time τ = ∫ν0 dt), wavenumbers reduced as k* = kℓ.  The physics (the
growth rate of the shear mode and the longitudinal matrix) lives in :mod:`ktgf.hcs.stability`;
this module only evaluates it on (state × wavenumber) grids.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..closures.coefficients import Reduced
from .stability import longitudinal_growth_rates, transverse_growth_rate


class Dispersion(NamedTuple):
    """Growth rates of all modes at wavenumbers ``kstar`` (broadcast with the state shape).

    Attributes
    ----------
    kstar : reduced wavenumbers k* = kℓ.
    transverse : s⊥(k*), real, the rate of each of the two shear (vortex) modes.
    longitudinal : (..., 3) complex eigenvalues of −M(k*), sorted by decreasing real part.
    """

    kstar: Any
    transverse: Any
    longitudinal: Any

    @property
    def largest_longitudinal(self) -> Any:
        """Largest real part of the three longitudinal growth rates (the cluster criterion)."""
        return self.longitudinal[..., 0].real


def expand_states(r: Reduced, ndim: int = 1) -> Reduced:
    """Append ``ndim`` unit axes to every coefficient so that states broadcast against a k* grid."""
    index = (...,) + (None,) * ndim
    return Reduced(*(np.asarray(v, dtype=float)[index] for v in r))


def dispersion_relation(r: Reduced, kstar: Any) -> Dispersion:
    """All growth rates s(k*) for states ``r`` at wavenumbers ``kstar`` (NumPy broadcasting).

    To tabulate many states against one k* grid, pass ``expand_states(r)`` and a 1-D ``kstar``:
    the result then has shape ``state_shape + kstar.shape``.

    Examples
    --------
    >>> import numpy as np
    >>> from ktgf import get_model
    >>> r = get_model("ret").reduced(0.1, 0.9)
    >>> d = dispersion_relation(r, np.geomspace(1e-3, 1.0, 50))
    >>> d.longitudinal.shape
    (50, 3)
    """
    kstar = np.asarray(kstar, dtype=float)
    s_perp = np.broadcast_to(transverse_growth_rate(r, kstar), np.broadcast_shapes(np.shape(r.p), kstar.shape))
    return Dispersion(kstar=kstar, transverse=s_perp, longitudinal=longitudinal_growth_rates(r, kstar))
