"""The planar Couette config of the 3D solver's tests (RET, JJ walls) and the check that a run started from the
1D solver's profile stays within 1 % of it."""

from __future__ import annotations

import tomllib

import jax.numpy as jnp
import numpy as np

from ktgf.solver.config import parse_config
from ktgf.solver.state import conservative


def parse(text: str):
    """A solver config from TOML text."""
    return parse_config(tomllib.loads(text))


def couette_case(cells: list[int], end: float, extra: str = "", lengths: str = "10.0", axis: str = "x",
                 flow: str = "y") -> str:
    """TOML text of a RET Couette cell (φ 0.3, JJ walls φ' 0.1, e_w 0.9, wall speed 1 m/s) from rest, IMEX."""
    return f"""
[case]
kind = "couette"
[model]
name = "ret"
restitution = 0.9
[initial]
solid_fraction = 0.3
temperature = 1e-3
perturbation = "none"
[grid]
cells = {cells}
length_d = {lengths}
[boundaries]
{axis} = {{ kind = "wall", flow = "{flow}", wall_speed = 1.0, walls = {{ type = "johnson-jackson", specularity = 0.1, restitution = 0.9 }} }}
[time]
end = {end}
unit = "strain"
outputs = 2
scheme = "imex"
{extra}
[output]
png = false
vtk = false
"""


def run_from_profile_within_one_percent(sim, ref, phi_mean: float, theta_tol: float = 0.01):
    """Start ``sim`` (cells across the gap on axis 0) from the 1D profile ``ref``, run it, and check that
    u, φ and both wall shear stresses stay within 1 % of the reference and θ within ``theta_tol`` (1 % unless a
    caller measured that θ's discretisation error at its grid is larger); returns the initial state."""
    n = sim.grid.cells[0]
    y = sim.grid.centres(0) - 0.5 * sim.grid.lengths[0]
    yr = ref["y"].values
    u = np.zeros((3, n))
    u[1] = np.interp(y, yr, ref["u"].values)
    with sim.precision():
        U0 = conservative(jnp.asarray(sim.phys.material_density * np.interp(y, yr, ref["phi"].values)),
                          jnp.asarray(u), jnp.asarray(np.interp(y, yr, ref["theta"].values)))
        # the exact inventory (interpolation moved it)
        U0 = U0 * (phi_mean * sim.phys.material_density * n / float(U0[0].sum()))
    sim.initial_state = lambda: sim.place(U0)
    sim.run(progress=False, write_files=False)
    ver = sim.verification
    err = ver["max_rel_error"]
    assert err["u"] < 0.01 and err["phi"] < 0.01 and err["theta"] < theta_tol, err
    assert set(err) == {"u", "phi", "theta"}, err
    tau_run, tau_ref = ver["wall_shear_stress_Pa"]["run"], ver["wall_shear_stress_Pa"]["reference"]
    assert abs(tau_run[0] / tau_ref[0] - 1) < 0.01 and abs(tau_run[1] / tau_ref[1] - 1) < 0.01
    return U0
