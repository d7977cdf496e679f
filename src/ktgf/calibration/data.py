"""Readers of the shared particle-data formats (``shared/data/README.md``), with checked inputs.

Two formats are read:

uniform shear (``dem_uniform_shear.csv``; the frictionless ``mu = 0`` rows of ``dem_uniform_shear_friction.csv``)
    '#' header lines stating the units (``d = m = 1``, ``gdot = 1``), then CSV with columns
    ``phi, e, T, dT, eta_over_eta0, deta_over_eta0, p_over_nT, dp_over_nT`` (``d*`` = standard
    error).  Observables: ``T`` = θ/(γ̇d)², ``eta_over_eta0`` = η/η0 and ``p_over_nT`` = p/(nT).
Couette profile (``dem_couette_e0.9_phi0.50.csv``)
    '#' header holding the case — restitution e, mean solid fraction, wall-centre distance H,
    wall speed U, wall shear stress τ and wall normal stress p_yy with their errors — then CSV
    with columns ``y, phi, ux, theta`` (and ``*_sem``).  The continuum cell is the slab between
    the planes tangent to the wall spheres: gap H − d (README).

Every problem with a file (missing, no units statement or other units, a missing column or
header field, NaN) raises :class:`~ktgf.errors.InputError` with one line naming the file and
the field.
"""

from __future__ import annotations

import hashlib
import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError

#: DEM units (README): d = 1, m = 1, so ρ_s = 6/π.
RHO_S_DEM = 6.0 / math.pi
#: Uniform-shear observables fitted, with the column of their standard error.
SHEAR_OBSERVABLES = {"T": "dT", "eta_over_eta0": "deta_over_eta0", "p_over_nT": "dp_over_nT"}
COUETTE_COLUMNS = ("y", "phi", "ux", "theta")


def file_hash(path: Path) -> str:
    """SHA-256 of a file's bytes (the provenance of a calibration)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _split(path: Path) -> tuple[list[str], list[str], np.ndarray]:
    """Header lines (without '#'), column names and the float table of a DEM CSV file."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"data file {str(path)!r} does not exist")
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    header = [ln[1:].strip() for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if ln.strip() and not ln.startswith("#")]
    if len(body) < 2:
        raise InputError(f"data file {path.name}: no data rows after the column-title row")
    names = [n.strip() for n in body[0].split(",")]
    try:
        table = np.genfromtxt(io.StringIO("\n".join(body[1:])), delimiter=",", dtype=float, ndmin=2)
    except ValueError as exc:
        raise InputError(f"data file {path.name}: rows are not a numeric table ({exc})") from None
    if table.shape[1] != len(names):
        raise InputError(f"data file {path.name}: {table.shape[1]} values per row but {len(names)} column titles")
    return header, names, table


def _columns(path: Path, names: list[str], table: np.ndarray, needed: tuple[str, ...], rows: np.ndarray | None = None) -> dict[str, np.ndarray]:
    missing = [c for c in needed if c not in names]
    if missing:
        raise InputError(f"data file {Path(path).name}: missing column(s) {', '.join(missing)} (columns present: {', '.join(names)})")
    out = {}
    for c in needed:
        v = table[:, names.index(c)] if rows is None else table[rows, names.index(c)]
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise InputError(f"data file {Path(path).name}: column {c} holds NaN or a non-number in data row {int(bad[0]) + 1}")
        out[c] = v
    return out


_UNIT = r"\s*=\s*(?:m\s*=\s*)?([-+\d.eE]+)\s*([A-Za-z]*)"


def _unit_is_one(text: str, symbol: str) -> bool:
    """``symbol = 1`` (or ``d = m = 1``) stated without a unit word after the number."""
    m = re.search(rf"(?<![A-Za-z_]){symbol}{_UNIT}", text)
    if m is None:
        return False
    try:
        return float(m.group(1)) == 1.0 and not m.group(2)
    except ValueError:
        return False


def _check_units(path: Path, header: list[str], *, shear_rate: bool) -> None:
    """The header must state d = m = 1 (and γ̇ = 1 for uniform shear): the units the model's reduced values are compared in."""
    units = [ln for ln in header if ln.lower().lstrip().startswith("units")]
    if not units:
        raise InputError(f"data file {Path(path).name}: header states no units (expected a line 'units d = m = 1 ...')")
    text = " ".join(units)
    m_ok = _unit_is_one(text, "m") or re.search(r"(?<![A-Za-z_])d\s*=\s*m\s*=\s*1(?![\d.])", text) is not None
    if not (_unit_is_one(text, "d") and m_ok):
        raise InputError(f"data file {Path(path).name}: units {units[0]!r} do not match the shared format (d = m = 1)")
    if shear_rate and not _unit_is_one(" ".join(header), "gdot"):
        raise InputError(f"data file {Path(path).name}: header does not state the shear rate gdot = 1 the columns are scaled with")


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
    path = Path(path)
    header, names, table = _split(path)
    _check_units(path, header, shear_rate=True)
    rows = None
    notes: list[str] = []
    if "mu" in names:
        mu = table[:, names.index("mu")]
        rows = np.flatnonzero(mu == 0.0)
        if rows.size == 0:
            raise InputError(f"data file {path.name}: no frictionless (mu = 0) rows; the kinetic theories describe smooth spheres")
        if rows.size < mu.size:
            notes.append(f"{path.name}: {mu.size - rows.size} frictional row(s) (mu > 0) left out")
    needed = ("phi", "e", *[c for pair in SHEAR_OBSERVABLES.items() for c in pair])
    cols = _columns(path, names, table, needed, rows)
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


def read_couette_case(path: str | Path, header: list[str] | None = None) -> CouetteCase:
    """The case (e, mean φ, gap, wall speed, wall stresses) from a DEM Couette file's header."""
    path = Path(path)
    if header is None:
        header, _, _ = _split(path)
    _check_units(path, header, shear_rate=False)
    text = "\n".join(header)
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
    return CouetteCase(e=e, mean_phi=phi, gap=H - 1.0, wall_speed=U, tau_wall=abs(tau), tau_wall_sigma=dtau,
                       p_wall=p, p_wall_sigma=dp)


def read_couette(path: str | Path) -> CouetteData:
    """Read a DEM Couette file: its case from the header and the occupied bins (φ > 0.05, θ > 0)."""
    path = Path(path)
    header, names, table = _split(path)
    case = read_couette_case(path, header)
    cols = _columns(path, names, table, COUETTE_COLUMNS)
    keep = (cols["phi"] > 0.05) & (cols["theta"] > 0)
    if keep.sum() < 3:
        raise InputError(f"data file {path.name}: fewer than 3 occupied bins (phi > 0.05, theta > 0)")
    sem = _columns(path, names, table, ("ux_sem",))["ux_sem"][keep] if "ux_sem" in names else None
    return CouetteData(path, case, cols["y"][keep], cols["phi"][keep], cols["ux"][keep], cols["theta"][keep], sem)


def read_data(path: str | Path) -> UniformShearData | CouetteData:
    """Read a shared-format file, telling the format from its columns (``y`` → Couette profile)."""
    _, names, _ = _split(Path(path))
    return read_couette(path) if "y" in names else read_uniform_shear(path)
