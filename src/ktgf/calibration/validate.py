"""One table of a model against every DEM file given, each row marked *fitted* or *predicted*.

Cases, recognised from a file's columns (the header must state the units d = m = 1):

uniform shear (``phi, e, T, eta_over_eta0, p_over_nT``; no ``mu``)
    T = θ/(γ̇d)², η/η0 and p/(nT) of the Navier–Stokes closed forms (the calibration's observables,
    :func:`~ktgf.calibration.residuals.shear_prediction`), the model at μ = 0.
frictional shear (``mu, phi, e, T, p_star, tau_over_p, Trot_over_T``)
    T, p*, τ/p and T_rot/T of :func:`ktgf.shear.steady.steady_shear` with the
    model at the row's μ (a frictionless model gets Walton friction, as ``ktgf shear --mu``).
Couette (``y, phi, ux, theta``; case from the header)
    wall shear stress and wall pressure of :func:`ktgf.couette.compare.compare_with_dem`: the
    DEM's bumpy walls where the header states the wall spheres (nothing fitted, on the layer of the
    centres), else Johnson–Jackson walls, e_w = e, the specularity fitted to the DEM slip (one wall
    number; the stresses are predictions); the model file's walls if it holds walls.
homogeneous cooling (``phi, e, A_main, A_early``)
    the cooling rate A = ζ0/√T (:func:`ktgf.hcs.cooling_rate`, d = 1, T = 1) against both Haff fits,
    and p/(nT) of the cooling state; the model at μ = 0.

A row is *fitted* when its state (a row of a shear or cooling file, a Couette file) and its quantity
were in the data the model's parameters were fitted to: for a model file, the files of its
``[[provenance.data]]`` (by SHA-256, or by name for a file without hash) with every state
:func:`ktgf.data.read_data` takes from them (``ktgf calibrate`` fits them all); for a registered model,
:data:`ktgf.calibration.registry_fits.REGISTERED_FITS` (e.g. p/(nT) of the cooling states, not their
cooling rates).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..data import RHO_S_DEM, file_hash
from ..data.table import Table, check_units, read_table, resolve
from ..errors import ConvergenceError, InputError
from .registry_fits import REGISTERED_FITS, FitSource

CASES = ("uniform-shear", "frictional-shear", "couette", "homogeneous-cooling")
_CASE_COLUMNS = {
    "uniform-shear": ("phi", "e", "T", "eta_over_eta0", "p_over_nT"),
    "frictional-shear": ("mu", "phi", "e", "T", "p_star", "tau_over_p", "Trot_over_T"),
    "couette": ("y", "phi", "ux", "theta"),
    "homogeneous-cooling": ("phi", "e", "A_main", "A_early"),
}
FRICTION_QUANTITIES = {"T": "dT", "p_star": "dp_star", "tau_over_p": "dtau_over_p", "Trot_over_T": "dTrot_over_T"}


def detect_case(path: str | Path) -> str:
    """The case of a DEM file from its columns (one-line error naming the file and its columns if none fits)."""
    names = read_table(path).names
    if "y" in names:
        return "couette"
    if "A_main" in names or "A_early" in names:
        return "homogeneous-cooling"
    if "mu" in names:
        return "frictional-shear"
    if "eta_over_eta0" in names or "p_over_nT" in names:
        return "uniform-shear"
    expected = "; ".join(f"{k}: {', '.join(v)}" for k, v in _CASE_COLUMNS.items())
    raise InputError(f"data file {Path(path).name}: columns {', '.join(names)} match no DEM case (expected {expected})")


def data_files(paths: Sequence[str | Path]) -> list[Path]:
    """Files given, folders expanded to their ``*.csv`` (sorted); a missing path is a one-line error."""
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            found = sorted(p.glob("*.csv"))
            if not found:
                raise InputError(f"--data {str(p)!r}: folder holds no .csv file")
            out += found
        else:
            out.append(resolve(p))  # a file, or the bare name of a file shipped with ktgf
    if not out:
        raise InputError("no data file given (--data FILE or folder)")
    return out


def _at_mu(model: Any, mu: float) -> Any:
    from ..closures.friction.model_slot import with_friction

    return with_friction(model, mu)


def _row(case: str, path: Path, state: str, key: tuple, quantity: str, model: float, dem: float, sigma: float,
         note: str = "") -> dict[str, Any]:
    err = model / dem - 1.0 if dem != 0 and math.isfinite(model) else math.nan
    return {"file": path.name, "case": case, "state": state, "quantity": quantity, "model": float(model), "dem": float(dem),
            "dem_sigma": float(sigma), "error": float(err), "_key": key, "note": note}


def _uniform_shear(model: Any, path: Path) -> list[dict[str, Any]]:
    from ..data import UniformShearData, read_uniform_shear
    from .residuals import shear_prediction

    d = read_uniform_shear(path)
    m0 = _at_mu(model, 0.0)
    obs, sig = d.observed()
    n = len(d.phi)
    rows = []
    for i in range(n):  # state by state: a state the model refuses keeps its rows, with the refusal
        one = UniformShearData(d.path, d.phi[i:i + 1], d.e[i:i + 1], {}, {})
        try:
            m0.check(one.phi, one.e)  # refuse before evaluating (shear_prediction evaluates χ unchecked first)
            pred, note = np.asarray(shear_prediction(m0, one), dtype=float), ""
        except InputError as exc:
            pred, note = np.full(len(d.values), np.nan), str(exc)
        for q, name in enumerate(d.values):
            k = q * n + i
            rows.append(_row("uniform-shear", path, f"phi={d.phi[i]:g} e={d.e[i]:g}", (0.0, float(d.phi[i]), float(d.e[i])),
                             name, pred[q], obs[k], sig[k], note))
    return rows


def _frictional_shear(model: Any, path: Path, table: Table) -> list[dict[str, Any]]:
    from ..shear.steady import steady_shear

    check_units(table, shear_rate=True)
    cols = table.columns(("mu", "phi", "e", *[c for pair in FRICTION_QUANTITIES.items() for c in pair]))
    rows = []
    for i in range(table.values.shape[0]):
        mu, phi, e = (float(cols[c][i]) for c in ("mu", "phi", "e"))
        state, key = f"mu={mu:g} phi={phi:g} e={e:g}", (mu, phi, e)
        m = _at_mu(model, mu)
        # a frictional stress is in Pa: in DEM units (d = m = gdot = 1) its scale rho_s d^2 gdot^2 is 6/pi
        note = "frictional stress with stress scale rho_s d^2 gdot^2 = 6/pi (DEM units)" if m.friction.has_stress else ""
        try:
            s = steady_shear(m, np.array([phi]), e, stress_scale=RHO_S_DEM if m.friction.has_stress else None)
        except InputError as exc:  # e.g. φ beyond the model's packing limit: the model gives no answer there
            rows += [_row("frictional-shear", path, state, key, q, math.nan, cols[q][i], cols[s_][i], str(exc))
                     for q, s_ in FRICTION_QUANTITIES.items()]
            continue
        for q, s_ in FRICTION_QUANTITIES.items():
            v = float(np.asarray(getattr(s, q))[0])
            if math.isnan(v):  # T_rot/T of a model without rotation: nothing to compare
                continue
            rows.append(_row("frictional-shear", path, state, key, q, v, cols[q][i], cols[s_][i], note))
    return rows


def _couette(model: Any, path: Path, walls: dict[str, float] | None, n_cells: int) -> list[dict[str, Any]]:
    from ..couette.compare import compare_with_dem
    from ..data import read_couette

    d = read_couette(path)  # a file error is bad input (exit 2); a model that gives no answer is a note
    m0 = _at_mu(model, 0.0)
    # the DEM's own walls where its header states them: nothing fitted; else JJ walls fitted to the slip
    bumpy = not walls and d.case.wall_sphere_diameter is not None and d.case.wall_sphere_gap is not None
    try:
        (r,), _ = compare_with_dem(path, [m0], n_cells=n_cells, walls={m0.name: walls} if walls else None,
                                   wall="bumpy" if bumpy else "johnson-jackson")
    except (ConvergenceError, InputError) as exc:
        raise _NoAnswer(f"{path.name}: no Couette prediction: {exc}") from None
    how = (f"walls from the model file (specularity {r['specularity']:.4g})" if walls else
           "bumpy walls of the DEM's header, nothing fitted" if bumpy else
           f"JJ walls, specularity {r['specularity']:.4g} fitted to the DEM slip")
    note = how + ("" if r["valid"] else f"; profile INVALID (max phi {r['max_phi']:.3g}) {r['message']}".rstrip())
    state = f"mean phi={d.case.mean_phi:g} e={d.case.e:g}"
    key = ("couette",)
    return [_row("couette", path, state, key, "tau_wall", r["tau_wall"], d.case.tau_wall, d.case.tau_wall_sigma, note),
            _row("couette", path, state, key, "p_wall", r["p"], d.case.p_wall, d.case.p_wall_sigma, note)]


class _NoAnswer(Exception):
    """The model gives no answer for a file's case (solver failure, a state it refuses): a note, not an error."""


def _hcs(model: Any, path: Path, table: Table) -> list[dict[str, Any]]:
    from ..hcs.haff import cooling_rate

    if not re.search(r"(?<![A-Za-z_])d\s*=\s*m\s*=\s*1(?![\d.])", " ".join(table.header)):
        raise InputError(f"data file {path.name}: header does not state the units d = m = 1 the cooling rates are in")
    cols = table.columns(("phi", "e", "A_main", "A_main_sem", "A_early"))
    names = table.names
    m0 = _at_mu(model, 0.0)
    rows = []
    for i in range(table.values.shape[0]):
        phi, e = float(cols["phi"][i]), float(cols["e"][i])
        state, key = f"phi={phi:g} e={e:g}", (0.0, phi, e)
        try:
            a = float(cooling_rate(m0, phi, e, 1.0, d=1.0))
            p = float(m0.reduced(phi, e, hcs=True).p)
        except InputError as exc:
            a = p = math.nan
            note = str(exc)
        else:
            note = ""
        rows.append(_row("homogeneous-cooling", path, state, key, "A_early", a, cols["A_early"][i], math.nan, note))
        rows.append(_row("homogeneous-cooling", path, state, key, "A_main", a, cols["A_main"][i], cols["A_main_sem"][i], note))
        if "p_over_nT" in names:
            rows.append(_row("homogeneous-cooling", path, state, key, "p_over_nT", p, table.values[i, names.index("p_over_nT")],
                             math.nan, note))
    return rows


def fit_sources(model_name: str | None = None, model_file: Any = None) -> tuple[FitSource, ...]:
    """The data a model was fitted to: a model file's provenance, or :data:`REGISTERED_FITS` of a registered name."""
    if model_file is not None:
        out = []
        for d in model_file.provenance.get("data", []) or []:
            if isinstance(d, dict) and "file" in d:
                out.append(FitSource(str(d["file"]), None, str(d.get("sha256", ""))))
        return tuple(out)
    return REGISTERED_FITS.get(str(model_name), ())


def _fitted_keys(path: Path, case: str,
                 sources: Sequence[FitSource]) -> tuple[set[tuple], tuple[str, ...] | None] | None:
    """States of ``path`` in the fit and the quantities fitted there (None: every one); None: the file was not used."""
    for s in sources:
        same = file_hash(path) == s.sha256 if s.sha256 else path.name == Path(s.file).name
        if not same:
            continue
        if case == "couette":
            return {("couette",)}, s.quantities
        if s.states is not None:
            return {tuple(float(x) for x in k) for k in s.states}, s.quantities
        if case == "homogeneous-cooling":
            from ..data import read_cooling

            cols = read_cooling(path)
            return {(0.0, float(p), float(e)) for p, e in zip(cols["phi"], cols["e"])}, s.quantities
        from ..data import read_uniform_shear

        try:  # ktgf calibrate fits every state its reader takes: the frictionless rows
            d = read_uniform_shear(path)
        except InputError:
            return set(), s.quantities
        return {(0.0, float(p), float(e)) for p, e in zip(d.phi, d.e)}, s.quantities
    return None


@dataclass
class Validation:
    """Rows of :func:`validate` (file, case, state, quantity, model, dem, dem_sigma, error, role, note) and notes."""

    model: str
    rows: list[dict[str, Any]]
    sources: tuple[FitSource, ...]
    notes: list[str] = field(default_factory=list)

    def summary(self) -> list[dict[str, Any]]:
        """Mean and max |error| per case, quantity and role (fitted or predicted)."""
        out = []
        groups: dict[tuple, list[float]] = {}
        for r in self.rows:
            groups.setdefault((r["case"], r["quantity"], r["role"]), []).append(abs(r["error"]))
        for (case, q, role), e in groups.items():
            a = np.array(e, dtype=float)
            ok = a[np.isfinite(a)]
            out.append({"case": case, "quantity": q, "role": role, "rows": int(a.size), "answered": int(ok.size),
                        "mean_abs_error": float(ok.mean()) if ok.size else math.nan,
                        "max_abs_error": float(ok.max()) if ok.size else math.nan})
        return out


def validate(model: Any, paths: Sequence[str | Path], *, sources: Sequence[FitSource] = (),
             walls: dict[str, float] | None = None, n_cells: int = 200) -> Validation:
    """``model`` against every DEM file of ``paths`` (files or folders); rows marked from ``sources``."""
    files = data_files(paths)
    cases = [(p, detect_case(p)) for p in files]  # every file recognised before any model is run
    rows: list[dict[str, Any]] = []
    notes: list[str] = []
    for path, case in cases:
        table = read_table(path)
        if case == "uniform-shear":
            new = _uniform_shear(model, path)
        elif case == "frictional-shear":
            new = _frictional_shear(model, path, table)
        elif case == "couette":
            try:
                new = _couette(model, path, walls, n_cells)
            except _NoAnswer as exc:
                notes.append(str(exc))
                new = []
        else:
            new = _hcs(model, path, table)
        fitted = _fitted_keys(path, case, sources)
        for r in new:
            key = r.pop("_key")
            hit = fitted is not None and key in fitted[0] and (fitted[1] is None or r["quantity"] in fitted[1])
            r["role"] = "fitted" if hit else "predicted"
        rows += new
    if not sources:
        notes.append(f"no fit recorded for model {model.name!r} (published parameters, or a model file without "
                     "[[provenance.data]]): every row is marked predicted")
    order = ("file", "case", "state", "quantity", "model", "dem", "dem_sigma", "error", "role", "note")
    return Validation(model.name, [{k: r[k] for k in order} for r in rows], tuple(sources), notes)


__all__ = ["CASES", "REGISTERED_FITS", "FitSource", "Validation", "data_files", "detect_case", "fit_sources", "validate"]
