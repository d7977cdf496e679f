"""Finite-volume JAX solver of the granular Navier–Stokes equations (model.md §1).

Boxes with per-axis boundaries — periodic, Lees–Edwards (uniform shear) or Johnson–Jackson walls —
and an optional body force; the case (cooling box, uniform shear, planar Couette, chute) is data
(:mod:`.cases`, one module each; :mod:`.boundaries`; docs/solver.md "Cases and boundaries").

Conservative variables (ρ, ρu, E = ρ(|u|²/2 + 3θ/2)) on a uniform grid in 1, 2 or 3 dimensions (one code
path; the velocity always has three components); the discretisation (MUSCL + HLL/Rusanov, central viscous and
heat fluxes, IMEX ARS(2,2,2) or SSP-RK3): docs/solver.md, "Equations and numerics".  The closures are evaluated
once per cell and stage through ``Model.reduced(φ, e, check=False)``: any registered closure model can be used,
and the solver never branches on its name.

Modules: :mod:`.grid` (grid and its boundaries, a pytree), :mod:`.boundaries` (ghost cells of
each boundary kind), :mod:`.cases` (the cases: checks, start, diagnostics, references), :mod:`.flows` (what they share), :mod:`.state` (variables), :mod:`.physics`
(EoS, sound speed, SI transport from the Model), :mod:`.fluxes`, :mod:`.sources`,
:mod:`.stepping` (RHS, Δt, IMEX/SSP-RK3, compiled ``advance`` with failure detection), :mod:`.imex`,
:mod:`.initial` (HCS states), :mod:`.diagnostics`, :mod:`.io` (netCDF, checkpoints, VTK .vti,
PNG), :mod:`.config` (pydantic/TOML), :mod:`.run` (:class:`Simulation`).

Precision
    Importing this package leaves JAX's global ``jax_enable_x64`` setting alone.  A run's precision
    is part of its config: :class:`Simulation` runs inside ``jax.enable_x64(True)`` (see
    :meth:`Simulation.precision`), with the state in ``numerics.precision`` (``"float64"``, ``"float32"``
    or ``"mixed"``; docs/solver.md "Mixed precision").  Calling the lower-level functions (:func:`advance`, ...)
    directly in float64 needs the same context, or ``jax.config.update("jax_enable_x64", True)`` by the caller.

Several devices, several hosts, GPUs: docs/solver.md (``parallel.devices`` shards the first grid axis).
"""

from __future__ import annotations

from .config import Config, load_config, parse_config
from .grid import Grid
from .physics import Physics
from .run import Simulation
from .stepping import Numerics, advance

__all__ = ["Config", "Grid", "Numerics", "Physics", "Simulation", "advance", "load_config", "parse_config"]
