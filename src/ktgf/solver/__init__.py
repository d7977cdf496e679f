"""Finite-volume JAX solver of the granular Navier–Stokes equations (model.md §1) in periodic boxes."""
from __future__ import annotations

import jax

# The verification against the linear theory needs float64; a float32 run casts its state.
jax.config.update("jax_enable_x64", True)
