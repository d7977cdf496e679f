"""Validated configuration of a Couette run (TOML → pydantic), with errors that name the field.

Example (``examples/couette_planar.toml``)::

    model = "ret"
    mean_solid_fraction = 0.5
    restitution = 0.9
    particle_diameter = 1e-3      # m
    particle_density = 2500.0     # kg/m^3

    [geometry]
    kind = "planar"               # or "annular" with inner_radius, outer_radius, omega
    gap = 0.02                    # m
    wall_speed = 1.0              # m/s

    [walls]                       # both walls; [walls.bottom] / [walls.top] override
    type = "johnson-jackson"      # johnson-jackson | prescribed | zero-flux | no-slip-adiabatic | bumpy
    specularity = 0.1
    restitution = 0.9
    # type = "bumpy": wall_sphere_diameter = 1.0 and wall_sphere_gap = 0.0 (units of d; the default,
    # touching spheres of the particles' size) replace the specularity

    [numerics]
    n_cells = 200
    stretch = 1.5

    [output]
    path = "couette.nc"
    phi_rcp = 0.64
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from ..closures import get_model
from ..errors import InputError, KtgfError
from ..io import plain, read_toml
from .geometry import AnnularCell, PlanarCell
from .run import Material
from .walls import ENERGY_CONDITIONS, MOMENTUM_CONDITIONS, WALL_TYPES, Wall


class _Strict(BaseModel):
    # strict: ``restitution = true`` must not become e = 1; no inf/NaN anywhere
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class PlanarConfig(_Strict):
    kind: Literal["planar"] = "planar"
    gap: float = Field(gt=0, description="wall-to-wall distance H [m]")
    wall_speed: float = Field(gt=0, description="relative wall speed U [m/s]")

    def build(self) -> PlanarCell:
        return PlanarCell(self.gap, self.wall_speed)


class AnnularConfig(_Strict):
    kind: Literal["annular"]
    inner_radius: float = Field(gt=0, description="R_i [m]")
    outer_radius: float = Field(gt=0, description="R_o [m] > R_i")
    omega: float = Field(gt=0, description="angular velocity of the inner cylinder [rad/s]")

    @model_validator(mode="after")
    def _radii(self) -> AnnularConfig:
        if self.outer_radius <= self.inner_radius:
            raise ValueError(f"outer_radius = {self.outer_radius:g} must be > inner_radius = {self.inner_radius:g}")
        return self

    def build(self) -> AnnularCell:
        return AnnularCell(self.inner_radius, self.outer_radius, self.omega)


class WallConfig(_Strict):
    type: str | None = Field(None, description=f"preset: {', '.join(WALL_TYPES)}")
    momentum: str | None = Field(None, description=f"one of {', '.join(MOMENTUM_CONDITIONS)}")
    energy: str | None = Field(None, description=f"one of {', '.join(ENERGY_CONDITIONS)}")
    specularity: float | None = Field(None, gt=0, le=1)
    restitution: float | None = Field(None, gt=0, le=1)
    packing_limit: float | None = Field(None, gt=0, lt=1)
    slip: float | None = None
    temperature: float | None = Field(None, gt=0)
    heat_flux: Literal["total", "conductive"] | None = None
    friction_angle: float | None = Field(None, ge=0, lt=90, description="wall friction angle delta_w [degrees]")
    slip_regularisation: float | None = Field(None, gt=0, le=1)
    wall_sphere_diameter: float | None = Field(None, gt=0, description="bumpy wall: wall-sphere diameter d_w/d")
    wall_sphere_gap: float | None = Field(None, ge=0, description="bumpy wall: gap between wall spheres s/d")

    @field_validator("type")
    @classmethod
    def _type(cls, v: str | None) -> str | None:
        if v is not None and v not in WALL_TYPES:
            raise ValueError(f"unknown wall type {v!r}; valid: {', '.join(WALL_TYPES)}")
        return v

    @field_validator("momentum")
    @classmethod
    def _momentum(cls, v: str | None) -> str | None:
        if v is not None and v not in MOMENTUM_CONDITIONS:
            raise ValueError(f"unknown momentum condition {v!r}; valid: {', '.join(MOMENTUM_CONDITIONS)}")
        return v

    @field_validator("energy")
    @classmethod
    def _energy(cls, v: str | None) -> str | None:
        if v is not None and v not in ENERGY_CONDITIONS:
            raise ValueError(f"unknown energy condition {v!r}; valid: {', '.join(ENERGY_CONDITIONS)}")
        return v

    def merged(self, other: WallConfig | None) -> WallConfig:
        """This wall's settings overridden by ``other`` (a per-wall table)."""
        if other is None:
            return self
        return WallConfig(**{**self.model_dump(exclude_none=True), **other.model_dump(exclude_none=True)})

    def build(self) -> Wall:
        data = self.model_dump(exclude_none=True)
        wall_type = data.pop("type", "johnson-jackson" if "momentum" not in data and "energy" not in data else None)
        if wall_type is not None:
            m, e = WALL_TYPES[wall_type]
            data.setdefault("momentum", m)
            data.setdefault("energy", e)
        return Wall(**data)


class WallsConfig(WallConfig):
    bottom: WallConfig | None = None
    top: WallConfig | None = None

    def build_pair(self) -> tuple[Wall, Wall]:
        base = WallConfig(**self.model_dump(exclude_none=True, exclude={"bottom", "top"}))
        return base.merged(self.bottom).build(), base.merged(self.top).build()


class NumericsConfig(_Strict):
    n_cells: int = Field(200, ge=8, le=100000)
    stretch: float = Field(1.5, ge=0, le=5)
    tol: float = Field(1e-10, gt=0, lt=1e-3)


def check_output_path(path: str | Path, what: str = "output.path") -> Path:
    """A netCDF file name (``.nc``) that is not a folder; raise :class:`InputError` otherwise."""
    p = Path(path)
    if p.name in ("", ".", "..") or p.is_dir():
        raise InputError(f"{what} = {str(path)!r} is a folder: give a netCDF file name such as 'couette.nc'")
    if p.suffix.lower() != ".nc":
        raise InputError(f"{what} = {str(path)!r} has extension {p.suffix or '(none)'!r}: valid .nc (netCDF)")
    return p


class OutputConfig(_Strict):
    path: str = "couette.nc"
    phi_rcp: float = Field(0.64, gt=0, lt=1, description="random close packing used to flag invalid runs")

    @field_validator("path")
    @classmethod
    def _path(cls, v: str) -> str:
        try:
            check_output_path(v, "path")
        except InputError as exc:
            raise ValueError(str(exc)) from None
        return v


class CouetteConfig(_Strict):
    model: str = Field(description="closure model name (see `ktgf models`)")
    model_options: dict[str, Any] = Field(default_factory=dict)
    mean_solid_fraction: float = Field(gt=0, lt=1)
    restitution: float = Field(gt=0, le=1)
    particle_diameter: float = Field(gt=0, description="d [m]")
    particle_density: float = Field(gt=0, description="rho_s [kg/m^3]")
    geometry: Annotated[Union[PlanarConfig, AnnularConfig], Field(discriminator="kind")]
    walls: WallsConfig = Field(default_factory=WallsConfig)
    numerics: NumericsConfig = Field(default_factory=NumericsConfig)
    output: OutputConfig = Field(default_factory=OutputConfig)

    @field_validator("model")
    @classmethod
    def _model(cls, v: str) -> str:
        try:
            get_model(v)
        except KtgfError as exc:
            raise ValueError(str(exc)) from None
        return v

    @model_validator(mode="after")
    def _inventory(self) -> CouetteConfig:
        m = self.build_model()
        if self.mean_solid_fraction >= m.phi_max:
            raise ValueError(
                f"mean_solid_fraction = {self.mean_solid_fraction:g} is out of range: valid 0 < mean_solid_fraction "
                f"< {m.phi_max:g} (packing limit of model {self.model!r})"
            )
        if self.mean_solid_fraction >= self.output.phi_rcp:
            # the whole inventory would be above random close packing: every solution is invalid (model.md §9)
            raise ValueError(
                f"mean_solid_fraction = {self.mean_solid_fraction:g} is out of range: valid 0 < mean_solid_fraction "
                f"< output.phi_rcp = {self.output.phi_rcp:g} (random close packing)"
            )
        gap = self.geometry.gap if isinstance(self.geometry, PlanarConfig) else self.geometry.outer_radius - self.geometry.inner_radius
        if gap < self.particle_diameter:
            raise ValueError(f"the gap ({gap:g} m) must be at least one particle diameter ({self.particle_diameter:g} m)")
        return self

    def build_model(self):
        try:
            return get_model(self.model, **self.model_options)
        except KtgfError as exc:
            raise ValueError(str(exc)) from None

    def material(self) -> Material:
        return Material(self.particle_diameter, self.particle_density, self.restitution)


def _format(exc: ValidationError) -> str:
    parts = []
    for err in exc.errors():
        parts_loc = [str(p) for p in err["loc"]]
        # drop the discriminator tag pydantic inserts (geometry.planar.gap -> geometry.gap)
        loc = ".".join(p for i, p in enumerate(parts_loc) if not (i and parts_loc[i - 1] == "geometry" and p in ("planar", "annular")))
        msg = err["msg"].removeprefix("Value error, ")
        if err.get("input") is not None and err["type"] not in ("value_error", "missing", "extra_forbidden"):
            msg += f" (got {err['input']!r})"
        parts.append(f"field '{loc}': {msg}" if loc else msg)
    return "invalid Couette config: " + "; ".join(parts)


def parse_config(data: dict[str, Any]) -> CouetteConfig:
    """Validate a config mapping; raise :class:`InputError` naming the offending field(s)."""
    try:
        return CouetteConfig.model_validate(plain(data))
    except ValidationError as exc:
        raise InputError(_format(exc)) from None


def load_config(path: str | Path) -> CouetteConfig:
    """Read and validate a TOML config file."""
    data = read_toml(path)
    return parse_config(data)


def run_config(cfg: CouetteConfig, model: Any = None, **overrides: Any):
    """Run the cell described by ``cfg`` (see :func:`ktgf.couette.run.run`), with ``model`` instead of the config's if given."""
    from .run import run

    bottom, top = cfg.walls.build_pair()
    return run(
        cfg.build_model() if model is None else model, cfg.geometry.build(), bottom, top, cfg.mean_solid_fraction, cfg.material(),
        n_cells=cfg.numerics.n_cells, stretch=cfg.numerics.stretch, phi_rcp=cfg.output.phi_rcp,
        tol=cfg.numerics.tol, **overrides,
    )
