"""Model files: a registered model with changed options (and walls), as written by ``ktgf calibrate``.

Every command that takes ``--model`` also takes ``--model-file FILE``; this module is the one
reader.  Format (TOML)::

    [model]
    base = "proposed"                 # registered model (see `ktgf models`)
    name = "proposed-fit"             # optional: name shown in outputs (default: file stem)
    label = "Proposed (fit)"          # optional
    rdf = "torquato"                  # optional: replace the base model's RDF (a key of ktgf.closures.rdf.RDFS)

    [model.options]                   # any option of the model (Model.with_options)
    phi_c = 0.632
    beta = 1.93
    # friction = "coulomb"            # part choices by key: friction (none | coulomb), dissipation
    # mu = 0.3                        # ... and then that part's options (docs/friction.md)

    [walls]                           # optional (Couette fits): both walls
    specularity = 0.08
    wall_restitution = 0.9

    [fit]                             # optional, informative: what ktgf calibrate found
    [provenance]                      # optional, informative: data files with SHA-256, date, ktgf version, cost

Errors (unknown base model, RDF or option, a value out of range, an unknown field) are one
line naming the file and the field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InputError, KtgfError

_TOP = ("model", "walls", "fit", "provenance")
_MODEL_KEYS = ("base", "name", "label", "rdf", "options")
_WALL_KEYS = {"specularity": (0.0, 1.0), "wall_restitution": (0.0, 1.0)}


@dataclass(frozen=True)
class ModelFile:
    """A loaded model file: the model, the walls (may be empty) and the informative tables."""

    path: Path
    model: Any
    base: str
    options: dict[str, Any]
    walls: dict[str, float] = field(default_factory=dict)
    fit: dict[str, Any] = field(default_factory=dict)
    provenance: dict[str, Any] = field(default_factory=dict)
    rdf: str | None = None

    def covariance(self) -> tuple[list[str], Any] | None:
        """(fitted parameter names, their covariance) from ``[fit]``, or None if the file holds no fit.

        ``covariance`` if written (ktgf calibrate since the prediction bands), else rebuilt from
        ``standard_errors`` and ``correlation``.  A malformed table is a one-line error naming the field.
        """
        import numpy as np

        names = self.fit.get("parameters")
        if not names:
            return None
        if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
            raise _err(self.path, "fit.parameters", "must be a list of parameter names")
        n = len(names)
        where = "fit.covariance" if "covariance" in self.fit else "fit.standard_errors"
        try:
            if "covariance" in self.fit:
                cov = np.array(self.fit["covariance"], dtype=float)
            else:
                se = np.array(self.fit["standard_errors"], dtype=float)
                corr = np.array(self.fit.get("correlation", np.eye(n)), dtype=float)
                with np.errstate(invalid="ignore"):
                    cov = corr * np.outer(se, se)
        except (KeyError, TypeError, ValueError):
            raise _err(self.path, where, f"missing or not a {n} x {n} table of numbers") from None
        if cov.shape != (n, n):
            raise _err(self.path, where, f"shape {cov.shape} does not match the {n} parameters {', '.join(names)}")
        unknown = [k for k in names if k not in self.model.options() and k not in _WALL_KEYS]
        if unknown:
            raise _err(self.path, "fit.parameters", f"{', '.join(unknown)} not an option of model {self.base!r}")
        return list(names), cov


def _err(path: Path, where: str, msg: str) -> InputError:
    return InputError(f"model file {path.name}: field '{where}': {msg}")


def load_model_file(path: str | Path) -> ModelFile:
    """Read and check a model file; returns the model built from it."""
    from ..closures.models import get_model
    from ..closures.rdf import RDFS, get_rdf
    from ..io import read_toml

    path = Path(path)
    data = read_toml(path)
    for key in data:
        if key not in _TOP:
            raise _err(path, key, f"unknown table; valid: {', '.join(_TOP)}")
    sec = data.get("model")
    if not isinstance(sec, dict):
        raise _err(path, "model", "missing table [model] with at least base = \"<registered model>\"")
    for key in sec:
        if key not in _MODEL_KEYS:
            raise _err(path, f"model.{key}", f"unknown field; valid: {', '.join(_MODEL_KEYS)}")
    base = sec.get("base")
    if not isinstance(base, str):
        raise _err(path, "model.base", "missing or not a string (the registered model the file changes)")
    try:
        model = get_model(base)
    except KtgfError as exc:
        raise _err(path, "model.base", str(exc)) from None
    if "rdf" in sec:
        if not isinstance(sec["rdf"], str) or sec["rdf"].lower().replace("_", "-") not in (*RDFS, "cs"):
            raise _err(path, "model.rdf", f"unknown radial distribution function {sec['rdf']!r}; valid: {', '.join(sorted(RDFS))}")
        model = model.replace(rdf=get_rdf(sec["rdf"]))
    options = sec.get("options", {})
    if not isinstance(options, dict):
        raise _err(path, "model.options", "must be a table of option = value")
    valid = {**model.options(), **_part_choices(options)}
    for k, v in options.items():
        if k not in valid:
            raise _err(path, f"model.options.{k}", f"model {base!r} has no such option{_version_note(data)}; valid: {', '.join(valid)}")
        if isinstance(valid[k], float) and (isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)):
            raise _err(path, f"model.options.{k}", f"{v!r} is not a finite number")
    try:
        model = model.with_options(**options) if options else model
    except KtgfError as exc:
        raise _err(path, "model.options", str(exc)) from None
    if not (0.0 < model.phi_max <= 1.0):
        raise _err(path, "model.options", f"packing limit {model.phi_max:g} is out of range (0, 1]")
    name = sec.get("name", path.stem)
    label = sec.get("label", f"{model.label or base} ({name})")
    model = model.replace(name=str(name), label=str(label),
                          description=f"{base} with options from model file {path.name}: "
                                      + ", ".join(f"{k}={v}" for k, v in options.items()))
    walls = data.get("walls", {})
    if not isinstance(walls, dict):
        raise _err(path, "walls", "must be a table")
    for k, v in walls.items():
        if k not in _WALL_KEYS:
            raise _err(path, f"walls.{k}", f"unknown field; valid: {', '.join(_WALL_KEYS)}")
        lo, hi = _WALL_KEYS[k]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not lo < v <= hi:
            raise _err(path, f"walls.{k}", f"{v!r} is out of range: valid {lo:g} < {k} <= {hi:g}")
    return ModelFile(path, model, base, dict(options), {k: float(v) for k, v in walls.items()},
                     dict(data.get("fit", {})), dict(data.get("provenance", {})), sec.get("rdf"))


def _version_note(data: dict[str, Any]) -> str:
    """' (file written by ktgf X, this is ktgf Y)' when the file comes from another version, else ''."""
    from .. import __version__

    prov = data.get("provenance")
    written = prov.get("ktgf_version") if isinstance(prov, dict) else None
    return f" (file written by ktgf {written}, this is ktgf {__version__})" if written and written != __version__ else ""


def _part_choices(options: dict[str, Any]) -> dict[str, Any]:
    """Options that choose a part by key (``friction``, ``dissipation``) and, for a chosen part, its own options."""
    from dataclasses import fields

    from ..closures.dissipation import DISSIPATIONS
    from ..closures.friction.model_slot import FRICTIONS

    out: dict[str, Any] = {}
    for name, table in (("friction", FRICTIONS), ("dissipation", DISSIPATIONS)):
        key = options.get(name)
        if name in options:
            out[name] = ""
        if isinstance(key, str) and key in table:
            out.update({f.name: getattr(table[key](), f.name) for f in fields(table[key])})
    return out


def part_choice_options(model: Any, reference: Any) -> dict[str, Any]:
    """``friction``/``dissipation`` keys where ``model`` chose another part than ``reference`` (for writing)."""
    return {name: getattr(model, name).key for name in ("friction", "dissipation")
            if getattr(model, name).key != getattr(reference, name).key}


# -- writing ---------------------------------------------------------------------------------
def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        f = float(v)
        if math.isnan(f):
            return "nan"
        if math.isinf(f):
            return "inf" if f > 0 else "-inf"
        return repr(v) if isinstance(v, int) else repr(f)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if hasattr(v, "tolist"):
        return _toml_value(v.tolist())
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _table(name: str, items: dict[str, Any]) -> list[str]:
    lines = [f"[{name}]"]
    lines += [f"{k} = {_toml_value(v)}" for k, v in items.items() if not isinstance(v, dict) and v is not None]
    return lines


def dumps(base: str, options: dict[str, Any], *, name: str | None = None, label: str | None = None, rdf: str | None = None,
          walls: dict[str, float] | None = None, fit: dict[str, Any] | None = None,
          provenance: dict[str, Any] | None = None, comment: str = "") -> str:
    """The text of a model file (see the module docstring)."""
    lines = [f"# {ln}" for ln in comment.splitlines()] if comment else []
    lines += _table("model", {"base": base, "name": name, "label": label, "rdf": rdf}) + [""]
    lines += _table("model.options", options) + [""]
    if walls:
        lines += _table("walls", walls) + [""]
    if fit:
        lines += _table("fit", fit) + [""]
    if provenance:
        data = provenance.get("data", [])
        lines += _table("provenance", {k: v for k, v in provenance.items() if k != "data"}) + [""]
        for d in data:
            lines += ["[[provenance.data]]"] + [f"{k} = {_toml_value(v)}" for k, v in d.items()] + [""]
    return "\n".join(lines)


def write_model_file(path: str | Path, text: str) -> Path:
    """Write a model file, creating its folder; InputError (one line) if that is impossible."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise InputError(f"cannot write the model file {str(path)!r}: {exc.strerror or exc}") from None
    return path


def fit_text(result: Any, *, command: str = "", start_file: ModelFile | None = None) -> str:
    """Model-file text of a calibration (:class:`~ktgf.calibration.fit.FitResult`), with its provenance."""
    import datetime

    from .._version import __version__
    from ..closures.models import get_model
    from ..data import file_hash

    reference = get_model(result.base)
    if start_file is not None and start_file.rdf:  # options are written relative to the swapped part's defaults
        from ..closures.rdf import get_rdf

        reference = reference.replace(rdf=get_rdf(start_file.rdf))
    ref_opts = reference.options()
    opts = {**part_choice_options(result.model, reference),
            **{k: v for k, v in result.model.options().items()
               if k in result.names or (k not in ref_opts or ref_opts[k] != v) and isinstance(v, (int, float, str))}}
    fit = {
        "parameters": result.names, "values": [float(v) for v in result.values],
        "standard_errors": [float(v) for v in result.stderr], "correlation": [[float(c) for c in row] for row in result.correlation],
        "covariance": [[float(c) for c in row] for row in result.covariance],
        "errors": result.errors, "weights": result.weights, "cost": result.cost, "success": result.success,
        "message": result.message, "evaluations": result.evaluations, "at_bound": result.at_bound,
        "residual_labels": result.labels, "residuals": [float(r) for r in result.residuals],
    }
    prov = {
        "created": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "ktgf_version": __version__, "command": command, "cost": result.cost,
        "data": [{"file": Path(f).name, "path": str(Path(f).resolve()), "sha256": file_hash(Path(f))} for f in result.files],
    }
    name = f"{result.base}-calibrated"
    text = dumps(result.base, opts, name=name, rdf=start_file.rdf if start_file else None, label=f"{reference.label or result.base} (calibrated)",
                 walls=result.walls,
                 fit=fit, provenance=prov,
                 comment=f"ktgf model file written by ktgf calibrate ({'fit converged' if result.success else 'FIT FAILED: best point kept'})")
    return text
