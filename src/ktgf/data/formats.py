"""Typed readers of the shared DEM formats (``data/dem/README.md``), one per kind of flow.

uniform shear (``dem_uniform_shear*.csv``; the frictionless ``mu = 0`` rows of ``dem_uniform_shear_friction*.csv``)
    columns ``phi, e, T, dT, eta_over_eta0, deta_over_eta0, p_over_nT, dp_over_nT`` (``d*`` = standard
    error): ``T`` = θ/(γ̇d)², ``eta_over_eta0`` = η/η0, ``p_over_nT`` = p/(nT) (:func:`read_uniform_shear`).
frictional uniform shear (``dem_uniform_shear_friction*.csv``)
    columns ``mu, phi, e, T, Trot_over_T, p_star, tau_over_p, ...`` with standard errors (:func:`read_friction_shear`).
Couette profile (``dem_couette_e0.9_phi0.50.csv``)
    a header holding the case — restitution e, mean solid fraction, wall-centre distance H, wall
    speed U, wall shear stress τ and wall normal stress p_yy with their errors — then columns
    ``y, phi, ux, theta`` (and ``*_sem``).  The continuum cell is the slab between the planes
    tangent to the wall spheres: gap H − d (:func:`read_couette`).
homogeneous cooling (``dem_hcs_cooling.csv``)
    columns ``phi, e, A_main, A_early, ratio_main, ratio_early, p_over_nT`` (:func:`read_cooling`).

:func:`read_data` tells the format from the columns.  Every problem raises
:class:`~ktgf.errors.InputError` with one line naming the file and the field.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from .table import Table, check_units, read_table

#: DEM units (README): d = 1, m = 1, so ρ_s = 6/π.
RHO_S_DEM = 6.0 / math.pi
#: Uniform-shear observables fitted, with the column of their standard error.
SHEAR_OBSERVABLES = {"T": "dT", "eta_over_eta0": "deta_over_eta0", "p_over_nT": "dp_over_nT"}
#: Columns every uniform-shear record array has (:func:`uniform_shear_records`).
SHEAR_COLUMNS: tuple[str, ...] = ("phi", "e", "T", "eta_over_eta0", "p_over_nT")
#: Columns of the frictional uniform-shear format that are read.
FRICTION_COLUMNS: tuple[str, ...] = ("mu", "phi", "e", "T", "Trot_over_T", "p_star", "tau_over_p")
COUETTE_COLUMNS = ("y", "phi", "ux", "theta")
COOLING_COLUMNS: tuple[str, ...] = ("phi", "e", "A_main", "A_early", "ratio_main", "ratio_early", "p_over_nT")


@dataclass(frozen=True)
class UniformShearData:
    """Uniform-shear DEM states: φ, e and the observables with their standard errors."""

    path: Path
    phi: np.ndarray
    e: np.ndarray
    values: dict[str, np.ndarray]
    sigmas: dict[str, np.ndarray]
    notes: tuple[str, ...] = ()
    kind: str = field(default="uniform-shear", init=False)

    @property
    def labels(self) -> list[str]:
        """One label per residual, in the order of :func:`ktgf.calibration.residuals.observables`."""
        return [f"phi={p:g} e={e:g} {name}" for name in self.values for p, e in zip(self.phi, self.e)]

    def observed(self) -> tuple[np.ndarray, np.ndarray]:
        """Observations and their standard errors, flattened observable by observable."""
        return (np.concatenate([self.values[k] for k in self.values]), np.concatenate([self.sigmas[k] for k in self.values]))


def read_uniform_shear(path: str | Path) -> UniformShearData:
    """Read a uniform-shear DEM file (frictionless rows only: a ``mu`` column keeps ``mu = 0``)."""
    table = read_table(path)
    path = table.path
    check_units(table, shear_rate=True)
    rows = None
    notes: list[str] = []
    if table.has("mu"):
        mu = table.column("mu")
        rows = np.flatnonzero(mu == 0.0)
        if rows.size == 0:
            raise InputError(f"data file {path.name}: no frictionless (mu = 0) rows; the kinetic theories describe smooth spheres")
        if rows.size < mu.size:
            notes.append(f"{path.name}: {mu.size - rows.size} frictional row(s) (mu > 0) left out")
    needed = ("phi", "e", *[c for pair in SHEAR_OBSERVABLES.items() for c in pair])
    cols = table.columns(needed, rows)
    for k, s in SHEAR_OBSERVABLES.items():
        if np.any(cols[s] <= 0):
            raise InputError(f"data file {path.name}: column {s} (standard error of {k}) must be > 0")
    if np.any((cols["phi"] <= 0) | (cols["phi"] >= 1)):
        raise InputError(f"data file {path.name}: column phi must lie in (0, 1)")
    if np.any((cols["e"] <= 0) | (cols["e"] >= 1)):
        raise InputError(f"data file {path.name}: column e must lie in (0, 1) (uniform shear needs inelastic spheres)")
    return UniformShearData(path, cols["phi"], cols["e"], {k: cols[k] for k in SHEAR_OBSERVABLES},
                            {k: cols[s] for k, s in SHEAR_OBSERVABLES.items()}, tuple(notes))


@dataclass(frozen=True)
class CouetteCase:
    """The case a DEM Couette file describes, in DEM units (d = m = 1, ρ_s = 6/π).

    ``gap`` is the continuum cell, H − d (slab between the planes tangent to the wall spheres).
    ``wall_sphere_diameter`` and ``wall_sphere_gap`` (units of d) describe the walls' spheres when the
    header's geometry line does (``walls = ... layer of N touching spheres each (d = 1 ...``), else None.
    """

    e: float
    mean_phi: float
    gap: float
    wall_speed: float
    tau_wall: float
    tau_wall_sigma: float
    p_wall: float
    p_wall_sigma: float
    d: float = 1.0
    rho_s: float = RHO_S_DEM
    wall_sphere_diameter: float | None = None
    wall_sphere_gap: float | None = None


@dataclass(frozen=True)
class CouetteData:
    """A DEM Couette profile (bins holding flowing particles) and its case."""

    path: Path
    case: CouetteCase
    y: np.ndarray
    phi: np.ndarray
    u: np.ndarray
    theta: np.ndarray
    u_sem: np.ndarray | None = None
    kind: str = field(default="couette", init=False)

    @property
    def tau_wall(self) -> float:
        return self.case.tau_wall

    @property
    def p_wall(self) -> float:
        return self.case.p_wall

    @property
    def slip_y(self) -> float:
        """|y| of the outermost occupied bins (mean of both walls): where the slip velocity is read."""
        return 0.5 * (abs(float(self.y[0])) + abs(float(self.y[-1])))

    def slip_speed(self) -> float:
        """|u| at |y| = slip_y, averaged over both walls (the DEM slip the wall condition is fitted to)."""
        y0 = self.slip_y
        return 0.5 * (abs(float(np.interp(y0, self.y, self.u))) + abs(float(np.interp(-y0, self.y, self.u))))

    def slip_sigma(self) -> float:
        """Standard error of :meth:`slip_speed` from the ``ux_sem`` column (NaN without it)."""
        if self.u_sem is None:
            return math.nan
        y0 = self.slip_y
        return 0.5 * math.hypot(float(np.interp(-y0, self.y, self.u_sem)), float(np.interp(y0, self.y, self.u_sem)))


#: Header fields of the Couette format: name → (regular expression, example of the expected line).
_NUM = r"([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)"
COUETTE_HEADER = {
    "e": (rf"restitution\)?\s*:\s*{_NUM}", "# e (particle-particle = particle-wall normal restitution): 0.9"),
    "mean_phi": (rf"mean solid fraction\s+{_NUM}", "# ... mean solid fraction 0.5000 ..."),
    "H": (rf"(?<![/\w])H\s*=\s*{_NUM}", "# ... H = 20 (wall-centre to wall-centre)"),
    "U": (rf"(?<![/\w])U\s*=\s*{_NUM}", "# walls move rigidly at ... U = 10"),
    "tau": (rf"wall shear stress tau\s*=\s*{_NUM}\s*\+-\s*{_NUM}", "# wall shear stress tau = 0.65518 +- 0.0035"),
    "p_yy": (rf"wall normal stress p_yy\s*=\s*{_NUM}\s*\+-\s*{_NUM}", "# wall normal stress p_yy = 2.6588 +- 0.0091"),
}
#: The optional wall geometry: the walls' line, the wall-sphere diameter in it, and their gap unless they touch.
WALL_LINE = r"walls\s*=\s*[^\n]*"
WALL_SPHERE_DIAMETER = rf"spheres each\s*\(d\s*=\s*{_NUM}"
WALL_SPHERE_GAP = rf"gap\s*=\s*{_NUM}"


def _wall_spheres(text: str, name: str) -> tuple[float | None, float | None]:
    """(d_w/d, s/d) from the header's walls line, or None for what it does not state."""
    line = re.search(WALL_LINE, text)
    size = re.search(WALL_SPHERE_DIAMETER, line.group(0)) if line else None
    if line is None or size is None:
        return None, None
    d_w = float(size.group(1))
    if not d_w > 0.0:
        raise InputError(f"data file {name}: header field wall-sphere diameter = {d_w:g} is out of range: valid d > 0")
    if "touching" in line.group(0):
        return d_w, 0.0
    gap = re.search(WALL_SPHERE_GAP, line.group(0))
    if gap is not None and not float(gap.group(1)) >= 0.0:
        raise InputError(f"data file {name}: header field wall-sphere gap = {gap.group(1)} is out of range: valid gap >= 0")
    return d_w, None if gap is None else float(gap.group(1))


def read_couette_case(path: str | Path | Table) -> CouetteCase:
    """The case (e, mean φ, gap, wall speed, wall stresses) from a DEM Couette file's header."""
    table = path if isinstance(path, Table) else read_table(path)
    path = table.path
    check_units(table, shear_rate=False)
    text = "\n".join(table.header)
    found: dict[str, tuple[float, ...]] = {}
    for name, (pattern, example) in COUETTE_HEADER.items():
        m = re.search(pattern, text)
        if m is None:
            raise InputError(f"data file {path.name}: header field {name} not found (expected a line like {example!r})")
        found[name] = tuple(float(g) for g in m.groups())
    e, phi, H, U = found["e"][0], found["mean_phi"][0], found["H"][0], found["U"][0]
    for name, value, ok in (("e", e, 0 < e <= 1), ("mean_phi", phi, 0 < phi < 1), ("H", H, H > 2.0), ("U", U, U > 0)):
        if not ok:
            raise InputError(f"data file {path.name}: header field {name} = {value:g} is out of range")
    (tau, dtau), (p, dp) = found["tau"], found["p_yy"]
    d_w, s_w = _wall_spheres(text, path.name)
    return CouetteCase(e=e, mean_phi=phi, gap=H - 1.0, wall_speed=U, tau_wall=abs(tau), tau_wall_sigma=dtau,
                       p_wall=p, p_wall_sigma=dp, wall_sphere_diameter=d_w, wall_sphere_gap=s_w)


def read_couette(path: str | Path) -> CouetteData:
    """Read a DEM Couette file: its case from the header and the occupied bins (φ > 0.05, θ > 0)."""
    table = read_table(path)
    path = table.path
    case = read_couette_case(table)
    cols = table.columns(COUETTE_COLUMNS)
    keep = (cols["phi"] > 0.05) & (cols["theta"] > 0)
    if keep.sum() < 3:
        raise InputError(f"data file {path.name}: fewer than 3 occupied bins (phi > 0.05, theta > 0)")
    sem = table.column("ux_sem")[keep] if table.has("ux_sem") else None
    return CouetteData(path, case, cols["y"][keep], cols["phi"][keep], cols["ux"][keep], cols["theta"][keep], sem)


def uniform_shear_records(path: str | Path, *, where: dict[str, float] | None = None) -> np.ndarray:
    """Rows of a uniform-shear DEM file as a record array of every column (checked finite).

    ``where`` keeps only rows whose columns equal the given values (e.g. ``{"mu": 0.0}`` for the
    frictionless row of ``dem_uniform_shear_friction.csv``).
    """
    table = read_table(path)
    keep = np.ones(table.values.shape[0], dtype=bool)
    for key, value in (where or {}).items():
        keep &= table.column(key) == value
    cols = table.columns(tuple(dict.fromkeys((*SHEAR_COLUMNS, *table.names))), np.flatnonzero(keep))
    return np.rec.fromarrays(list(cols.values()), names=list(cols))


def read_friction_shear(path: str | Path) -> list[dict[str, float]]:
    """Rows of a frictional uniform-shear file (``dem_uniform_shear_friction*.csv``) as dicts of floats."""
    table = read_table(path)
    check_units(table, shear_rate=True)
    table.columns(FRICTION_COLUMNS)
    return table.records()


def read_cooling(path: str | Path) -> dict[str, np.ndarray]:
    """Columns of a homogeneous-cooling file (``dem_hcs_cooling.csv``) by title (the needed ones checked finite)."""
    table = read_table(path)
    table.columns(COOLING_COLUMNS)
    return table.as_dict()


def read_data(path: str | Path) -> UniformShearData | CouetteData:
    """Read a file of a calibration format, telling it from its columns (``y`` → Couette profile, else uniform shear)."""
    return read_couette(path) if read_table(path).has("y") else read_uniform_shear(path)
