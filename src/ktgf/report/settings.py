"""Inputs of the reproduction report: one validated, frozen settings object per run.

``ReportSettings.preset(quick=...)`` gives the two standard runs: the full report and the
``--quick`` one (coarser grids, fewer points; what CI runs, < 5 min on 2 cores).  Every
field ends up in the page's "rerun" table and, through each section's ``inputs``, in the
cache key of the sections that use it.
"""

from __future__ import annotations

import typing
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from ..closures.models import PAPER_MODELS, get_model
from ..data import DATA_ENV, locate_data_dir  # noqa: F401  (re-exported)
from ..errors import InputError, UnknownModelError

#: Environment variable naming the DEM reference-data folder (overridden by ``--data``).

Restitution = Field(gt=0.0, le=1.0)


class ReportSettings(BaseModel):
    """Every input of one report run.

    Units for the Couette and 3D cases follow the DEM data: d = 1, m = 1 (ρ_s = 6/π).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    out: Path = Field(Path("ktgf-report"), description="Output folder of the report")
    quick: bool = Field(False, description="Coarse grids and fewer points (CI run)")
    data_dir: Path | None = Field(None, description=f"DEM reference data folder (default: ${DATA_ENV} or ../shared/data)")
    models: tuple[str, ...] = Field(PAPER_MODELS, min_length=1, description="Models compared (registry names)")

    # (1) transport coefficients
    coefficient_e: tuple[float, ...] = Field((0.9, 0.7), min_length=1, description="Restitution values of the coefficient figures")
    coefficient_points: int = Field(300, ge=10, le=20000, description="Points in φ per curve")
    coefficient_phi_max: float = Field(0.6, gt=0.0, lt=1.0, description="Largest φ plotted")

    # (2) homogeneous cooling state
    stability_e: tuple[float, ...] = Field((0.5, 0.7, 0.8, 0.9, 0.95), min_length=1, description="Restitution values of the stability map")
    stability_points: int = Field(291, ge=10, le=20000, description="Points in φ of the stability map (291: step 0.002)")
    stability_phi: tuple[float, float] = Field((0.02, 0.6), description="φ range of the stability map")
    dispersion_phi: float = Field(0.3, gt=0.0, lt=0.64, description="Solid fraction of the dispersion-relation state")
    dispersion_e: float = Field(0.9, gt=0.0, le=1.0, description="Restitution of the dispersion-relation state")
    dispersion_points: int = Field(400, ge=20, le=100000, description="Wavenumbers of the dispersion relations")
    haff_states: tuple[tuple[float, float], ...] = Field(
        ((0.1, 0.9), (0.4, 0.7)), min_length=1, description="(φ, e) states of the Haff's-law figure"
    )

    # (3) Couette cell (the DEM case of dem_couette_e0.9_phi0.50.csv)
    couette_phi_mean: float = Field(0.5, gt=0.0, lt=0.64, description="Mean solid fraction of the Couette cell")
    couette_e: float = Field(0.9, gt=0.0, le=1.0, description="Restitution (particle-particle and particle-wall)")
    couette_height: float = Field(19.0, gt=0.0, description="Gap H [d] between the planes tangent to the wall spheres (DEM: 19)")
    couette_wall_speed: float = Field(10.0, gt=0.0, description="Relative wall speed U in the DEM units, d = m = 1 (the DEM run: U = 10)")
    couette_cells: int = Field(200, ge=8, le=100000, description="Grid cells across the Couette gap")

    # (4) 3D homogeneous cooling gas
    cooling_models: tuple[str, ...] = Field(("ret", "proposed"), min_length=1, description="Models run in 3D")
    cooling_phi: float = Field(0.5, gt=0.0, lt=0.64, description="Solid fraction of the 3D cooling runs (0.5 > φ_f = 0.49: RET and Proposed differ)")
    cooling_e: float = Field(0.7, gt=0.0, le=1.0, description="Restitution of the 3D cooling runs")
    cooling_below: float = Field(0.7, gt=0.0, lt=1.0, description="Side of the small box as a fraction of L⊥ (stays homogeneous)")
    cooling_above: float = Field(1.4, gt=1.0, le=10.0, description="Side of the large box as a multiple of L∥ (vortices and clusters)")
    cooling_cells: int = Field(32, ge=8, le=1024, description="Grid cells per side of the 3D box (32: 0.5 and 1.6 mean free paths per cell in the small and large box at phi = 0.5)")
    cooling_t_end: float = Field(400.0, gt=0.0, description="End time in units of the initial collision time 1/ν0(θ0)")
    cooling_seed: int = Field(0, ge=0, description="Seed of the initial velocity perturbation")

    # (5) dense regime: uniform shear and Couette wall stresses against DEM
    dense_models: tuple[str, ...] | None = Field(None, description="Models of the dense-regime section (default: models plus 'dense' if registered)")
    dense_points: int = Field(150, ge=10, le=20000, description="Points in φ of the dense-regime uniform-shear curves")

    @field_validator("models", "cooling_models", "dense_models")
    @classmethod
    def _known_models(cls, names: tuple[str, ...] | None) -> tuple[str, ...] | None:
        if names is None:
            return None
        try:
            return tuple(get_model(n).name for n in names)
        except UnknownModelError as exc:  # a KeyError, which pydantic would not attribute to the field
            raise ValueError(str(exc)) from None

    @field_validator("coefficient_e", "stability_e")
    @classmethod
    def _restitution(cls, values: tuple[float, ...]) -> tuple[float, ...]:
        for v in values:
            if not 0.0 < v <= 1.0:
                raise ValueError(f"restitution {v:g} is outside (0, 1]")
        return values

    @field_validator("haff_states")
    @classmethod
    def _states(cls, states: tuple[tuple[float, float], ...]) -> tuple[tuple[float, float], ...]:
        for phi, e in states:
            if not 0.0 < phi < 0.64 or not 0.0 < e <= 1.0:
                raise ValueError(f"state (φ, e) = ({phi:g}, {e:g}) needs 0 < φ < 0.64 and 0 < e <= 1")
        return states

    @field_validator("stability_phi")
    @classmethod
    def _phi_range(cls, r: tuple[float, float]) -> tuple[float, float]:
        if not 0.0 < r[0] < r[1] < 1.0:
            raise ValueError(f"φ range ({r[0]:g}, {r[1]:g}) needs 0 < low < high < 1")
        return r

    @classmethod
    def preset(cls, *, quick: bool = False, **overrides: Any) -> ReportSettings:
        """The full report, or with ``quick=True`` the coarse one; ``overrides`` replace single fields.

        Raises :class:`~ktgf.errors.InputError` naming the field and its valid range.
        """
        values: dict[str, Any] = {"quick": quick}
        if quick:
            values.update(
                coefficient_e=(0.9,), coefficient_points=80, stability_e=(0.7, 0.9), stability_points=59,
                dispersion_points=120, couette_cells=40, cooling_cells=16, cooling_t_end=150.0, dense_points=50,
            )
        values.update({k: v for k, v in overrides.items() if v is not None})
        try:
            return cls(**values)
        except ValidationError as exc:
            err = exc.errors()[0]
            field = ".".join(str(p) for p in err["loc"])
            desc = cls.model_fields[str(err["loc"][0])].description if err["loc"] else ""
            raise InputError(
                f"report setting {field} = {err.get('input')!r}: {err['msg']}" + (f" ({desc})" if desc else "")
            ) from None

    @classmethod
    def from_sources(cls, *, quick: bool = False, config: Path | None = None, sets: list[str] | tuple[str, ...] = (),
                     **explicit: Any) -> ReportSettings:
        """Settings from, in increasing priority: the preset, a TOML file, ``key=value`` overrides, explicit options.

        ``config`` is a TOML file of ``setting = value`` lines (any field of this class; ``quick = true``
        selects the quick preset); ``sets`` are ``"key=value"`` strings with TOML values (``0.5``,
        ``[0.7, 0.9]``, ``"ret"``) or, for lists, comma-separated text (``models=ret,proposed``).
        Raises :class:`~ktgf.errors.InputError` (one line, naming the key) for unknown keys and bad values.
        """
        values: dict[str, Any] = {}
        if config is not None:
            from ..io import read_toml

            for key, v in read_toml(config).items():
                values[cls._known(key, f"in {config}")] = v
        for item in sets:
            key, eq, text = item.partition("=")
            key = key.strip()
            if not eq or not key:
                raise InputError(f"--set {item!r} is not key=value (e.g. --set cooling_phi=0.5)")
            cls._known(key, "in --set")
            value = cls._parse_value(key, text.strip())
            if typing.get_origin(cls.model_fields[key].annotation) is tuple and not isinstance(value, list):
                value = [value]  # one model, one restitution: a list of one
            values[key] = value
        quick = bool(values.pop("quick", False)) or quick
        return cls.preset(quick=quick, **{**values, **{k: v for k, v in explicit.items() if v is not None}})

    @classmethod
    def _known(cls, key: str, where: str) -> str:
        if key not in cls.model_fields:
            import difflib

            near = difflib.get_close_matches(key, list(cls.model_fields), n=1)
            hint = f"; did you mean {near[0]!r}?" if near else f"; valid: {', '.join(cls.model_fields)}"
            raise InputError(f"unknown report setting {key!r} {where}{hint}")
        return key

    @classmethod
    def _parse_value(cls, key: str, text: str) -> Any:
        import tomllib

        try:
            return tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            pass
        if "," in text:  # a bare list: models=ret,proposed or stability_e=0.7,0.9
            return [cls._parse_value(key, part.strip()) for part in text.split(",") if part.strip()]
        return text  # a bare word (a model name, a path): pydantic validates it

    @classmethod
    def documented_keys(cls) -> list[str]:
        """Every setting a config file or ``--set`` may name (the page's settings table lists them)."""
        return list(cls.model_fields)

    def rerun_options(self) -> str:
        """The CLI options that reproduce this run."""
        opts = ["--quick"] if self.quick else []
        opts.append(f"--out {self.out}")
        if self.data_dir is not None:
            opts.append(f"--data {self.data_dir}")
        return " ".join(["ktgf reproduce", *opts])


