"""Haff's law for the homogeneous cooling state (model.md §8).

A uniform gas at rest cools as dθ/dt = −ζ0(θ)θ.  Every closure here has ζ0 ∝ √θ, so

    θ(t) = θ0/(1 + t/t0)²,     t0 = 2/ζ0(θ0)

(Haff, J. Fluid Mech. 134, 401 (1983)).
"""

from __future__ import annotations

from typing import Any

from .._array import asarray
from ..closures.coefficients import nu0
from ..closures.models import Model, get_model
from ..validation import check_positive


def cooling_rate(model: Model | str, phi: Any, e: Any, theta0: Any, *, d: float) -> Any:
    """ζ0(θ0) = ν0(φ, θ0) ζ0*(φ, e) [1/s] for particles of diameter ``d`` [m]."""
    model = get_model(model)
    phi, e, theta0 = asarray(phi), asarray(e), asarray(theta0)
    model.check(phi, e, theta0)
    check_positive("particle diameter d", d, "m")
    return nu0(phi, theta0, d) * model.reduced(phi, e, check=False).zeta0


def cooling_time(model: Model | str, phi: Any, e: Any, theta0: Any, *, d: float) -> Any:
    """Haff time t0 = 2/ζ0(θ0) [s]; θ halves its square root after t0."""
    return 2.0 / cooling_rate(model, phi, e, theta0, d=d)


def haff_temperature(t: Any, theta0: Any, t0: Any) -> Any:
    """θ(t) = θ0/(1 + t/t0)² (Haff's law)."""
    return theta0 / (1.0 + asarray(t) / t0) ** 2
