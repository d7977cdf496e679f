"""Shared by the growth-rate tests of the solver: the rate of a complex mode amplitude."""

from __future__ import annotations

import numpy as np


def fit_rate(times: np.ndarray, amplitudes: np.ndarray) -> complex:
    """Least-squares slope of log(a(t)/a(0)): the complex rate σ of a ∝ exp(σt) (imaginary part unwrapped)."""
    logp = np.log(np.asarray(amplitudes) / amplitudes[0])
    return complex(np.polyfit(times, logp.real, 1)[0] + 1j * np.polyfit(times, np.unwrap(logp.imag), 1)[0])
