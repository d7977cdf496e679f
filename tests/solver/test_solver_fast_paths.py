"""The periodic padding of the JAX path copies the same values as NumPy's wrap padding."""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np
import pytest

from ktgf.solver import fluxes

pytestmark = pytest.mark.contract


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("shape", [(5,), (6, 4), (4, 7, 5)])
def test_periodic_padding_is_numpy_wrap_padding(dtype: type, shape: tuple) -> None:
    f = np.random.default_rng(1).random(shape).astype(dtype)
    (P,) = fluxes.pad_periodic((jnp.asarray(f),), len(shape))
    assert P.dtype == dtype
    np.testing.assert_array_equal(np.asarray(P), np.pad(f, fluxes.GHOST, mode="wrap"))
