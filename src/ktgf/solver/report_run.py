"""The solver run the reproduction report calls (a ready-made cooling box: :mod:`ktgf.report.cooling_gas`)."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..closures.coefficients import nu0
from .config import parse_config
from .run import Simulation
from .state import primitive


def report_cooling_run(model: Any, *, phi: float, e: float, box: float, n_cells: int, t_end: float, seed: int,
                       d: float, rho_s: float, theta0: float, outputs: int = 60) -> xr.Dataset:
    """A 3D homogeneous cooling gas in a periodic cube, summarised for the report (:mod:`ktgf.report.cooling_gas`).

    Parameters
    ----------
    model : Model
        Registered model (rebuilt from its name and options inside the run config).
    phi, e, theta0 : float
        Uniform solid fraction, restitution and initial temperature [m²/s²].
    box : float
        Side of the cube in particle diameters.
    n_cells : int
        Cells per side.
    t_end : float
        End time in units of the initial collision time 1/ν0(θ0).
    seed : int
        Seed of the small random initial velocity field.

    Returns
    -------
    xarray.Dataset
        ``time`` (units 1/ν0(θ0)) with ``theta_mean``, ``flow_energy`` (mean-flow kinetic energy over
        the thermal energy (3/2)θ), ``phi_std`` (std of φ over mean φ); ``x``, ``y`` (units of d) with
        the mid-plane fields ``phi_slice``, ``ux_slice``, ``uy_slice`` at the final time.
    """
    collision_time = 1.0 / float(nu0(phi, theta0, d))
    cfg = parse_config({
        "model": {"name": model.name, "restitution": e, "options": model.options()},
        "particles": {"diameter": d, "density": rho_s},
        "initial": {"solid_fraction": phi, "temperature": theta0, "perturbation": "random", "seed": seed},
        "grid": {"cells": [n_cells] * 3, "length_d": box},
        "time": {"end": t_end * collision_time, "unit": "s", "outputs": outputs},
        "output": {"vtk": False, "png": False},
    })
    sim = Simulation(cfg)
    hist = sim.run(progress=False, write_files=False)
    with sim.precision():
        W = np.asarray(primitive(sim.state))
    mid = n_cells // 2
    centres = (np.arange(n_cells) + 0.5) * box / n_cells
    ds = xr.Dataset(
        {
            "theta_mean": ("time", hist["theta_mean"].values),
            "flow_energy": ("time", hist["kinetic_energy"].values / (1.5 * hist["theta_mean"].values)),
            "phi_std": ("time", np.sqrt(hist["density_variance"].values)),
            "phi_slice": (("x", "y"), W[0][:, :, mid] / rho_s),
            "ux_slice": (("x", "y"), W[1][:, :, mid]),
            "uy_slice": (("x", "y"), W[2][:, :, mid]),
        },
        coords={"time": hist["time"].values / collision_time, "x": centres, "y": centres},
        attrs=hist.attrs,
    )
    return ds
