"""Validated run configuration (TOML → pydantic), checked completely before anything is compiled.

One section class per TOML table (:class:`Config`; ``[boundaries]``: one entry per non-periodic axis); examples:
``examples/hcs_3d.toml`` (the cooling box), ``examples/uniform_shear.toml``.  The case's own checks are its
:meth:`~ktgf.solver.cases.Case.check`.  Errors name the field (``grid.cells.0``, ``initial.solid_fraction``) and
the valid range.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, ValidationInfo, field_validator, model_validator

from ..closures import get_model
from ..couette.config import WallsConfig
from ..errors import InputError, KtgfError
from ..hcs.stability import BOX_CONSTANT, critical_wavenumbers
from ..io import plain, read_toml
from .boundaries import AXES, LEES_EDWARDS, WALL
from .cases import CASES, get_case, kinds
from .stencil import LIMITERS, RIEMANN_SOLVERS
from .grid import MIN_CELLS


class _Section(BaseModel):
    # strict: ``restitution = true`` must not become e = 1, nor ``cells = [8.5]`` 8;
    # allow_inf_nan=False: ``time.end = inf`` would run for ever
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class ModelSection(_Section):
    name: str = "ret"
    restitution: float = Field(0.8, gt=0.0, le=1.0, description="normal restitution coefficient e")
    options: dict[str, Any] = Field(default_factory=dict, description="model options, e.g. {zeta11 = 'ghd'}")


class ParticlesSection(_Section):
    diameter: float = Field(1e-3, gt=0.0, description="particle diameter d [m]")
    density: float = Field(2500.0, gt=0.0, description="material density rho_s [kg/m^3]")


class InitialSection(_Section):
    solid_fraction: float = Field(..., gt=0.0, lt=1.0, description="phi0")
    temperature: float | None = Field(None, gt=0.0, description="theta0 [m^2/s^2]; shear-mode: the closed form's")
    perturbation: Literal["random", "mode", "shear-mode", "none"] = "random"
    amplitude: float = Field(1e-2, ge=0.0, le=0.5)
    seed: int = Field(0, ge=0, le=2**63 - 1, description="seed of NumPy's default_rng")
    max_mode: int = Field(2, ge=1, description="random field: Fourier modes |n| <= max_mode")
    mode: list[int] | None = None
    kind: Literal["transverse", "longitudinal"] = "transverse"
    branch: int = Field(0, ge=0, le=4, description="eigenmode by decreasing growth rate: HCS 0-2, shear 0-4")
    shear_rate: float | None = Field(None, gt=0.0, description="chute: initial u = shear_rate * height above the base [1/s]")
    from_run: str | None = Field(None, min_length=1, description="start from this earlier run (its output folder or "
                                 "checkpoint.npz, or its TOML config: run first) mapped onto this grid")

    @model_validator(mode="after")
    def _temperature(self) -> InitialSection:
        if self.from_run is not None:
            bad = [k for k in ("temperature", "shear_rate", "mode") if getattr(self, k) is not None]
            if self.perturbation in ("mode", "shear-mode") or bad:
                what = f"perturbation = {self.perturbation!r}" if not bad else ", ".join(bad)
                raise ValueError(f"from_run starts from the earlier run's state: it takes no {what} (valid: "
                                 "perturbation = 'random' or 'none', amplitude, seed, max_mode)")
            return self
        # A shear-mode seed sits on the steady θ of the closed form (check_shear_mode): nothing to give.
        if self.temperature is None and self.perturbation != "shear-mode":
            raise ValueError("temperature is missing: give initial.temperature = theta0 > 0 [m^2/s^2] (optional "
                             "only for perturbation = 'shear-mode', which starts from the closed-form steady θ)")
        return self


class GridSection(_Section):
    cells: list[int] = Field(..., min_length=1, max_length=3)
    length: float | list[float] | None = Field(None, description="box side(s) [m]")
    length_d: float | list[float] | None = Field(None, description="box side(s) in particle diameters")
    relative_to: Literal["transverse", "longitudinal"] | None = None
    factor: float | None = Field(None, gt=0.0, description="box side / critical size")

    @field_validator("cells")
    @classmethod
    def _cells(cls, v: list[int]) -> list[int]:
        for a, n in enumerate(v):
            if n < MIN_CELLS:
                raise ValueError(f"cells[{a}] = {n} is out of range: valid cells >= {MIN_CELLS} (a box of a few cells)")
        return v

    @model_validator(mode="after")
    def _one_size(self) -> GridSection:
        given = [k for k in ("length", "length_d", "relative_to") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of length, length_d or relative_to (+ factor); got {given or 'none'}")
        if self.relative_to is not None and self.factor is None:
            raise ValueError("relative_to needs factor (box side / critical size)")
        for key in ("length", "length_d"):
            v = getattr(self, key)
            vals = v if isinstance(v, list) else ([v] if v is not None else [])
            if vals and (len(vals) not in (1, len(self.cells)) or any(not (x > 0 and math.isfinite(x)) for x in vals)):
                raise ValueError(f"{key} = {v} must be positive, one value or one per axis")
        return self


class NumericsSection(_Section):
    cfl: float = Field(0.4, gt=0.0, le=1.0)
    cfl_diffusion: float = Field(0.4, gt=0.0, le=1.0)
    cfl_source: float = Field(0.5, gt=0.0, lt=1.0)
    limiter: str = "vanleer"
    riemann: str = "hll"
    precision: Literal["float64", "float32", "mixed"] = "float64"
    phi_stop: float | None = Field(None, gt=0.0, lt=1.0, description="stop when max phi reaches this (default 0.99 phi_max)")
    implicit_tol: float = Field(1e-6, gt=0.0, lt=1.0, description="IMEX: relative residual of the stage solves")
    implicit_maxiter: int = Field(5, ge=1, le=100, description="IMEX: Krylov iterations of the stage solves, in tens")
    sweeps: int = Field(1, ge=1, le=5, description="IMEX: Picard passes on the implicit coefficients")
    acoustics: Literal["explicit", "implicit"] = Field(
        "explicit", description="IMEX: pressure waves explicit (step from |u| + c) or implicit (step from |u|)")
    sink: Literal["explicit", "implicit"] = Field(
        "explicit", description="IMEX: collisional sink explicit (step <= cfl_source/zeta0) or implicit (no such limit)")

    @field_validator("limiter", "riemann")
    @classmethod
    def _scheme(cls, v: str, info: ValidationInfo) -> str:
        valid = LIMITERS if info.field_name == "limiter" else RIEMANN_SOLVERS
        if v not in valid:
            raise ValueError(f"{info.field_name} {v!r} is not valid: choose one of {', '.join(valid)}")
        return v


class TimeSection(_Section):
    end: float = Field(..., gt=0.0)
    unit: Literal["tau", "haff", "s", "strain"] = Field(
        "tau", description="tau, haff: cooling box only; strain (shear rate x t): sheared cases only")
    outputs: int = Field(50, ge=1, le=100000)
    max_steps_per_call: int = Field(200, ge=1, le=2**31 - 1, description="steps per compiled call (progress granularity)")
    scheme: Literal["auto", "imex", "ssprk3"] = Field(
        "auto", description="imex (implicit diffusion), ssprk3 (explicit) or auto (the cheaper for the initial state)")
    steady_tol: float | None = Field(None, gt=0.0, lt=1.0, description="sheared cases: stop at the first output "
                                     "whose steady monitors changed by less than this since the previous one")


class OutputSection(_Section):
    directory: str = Field("ktgf-run", min_length=1)
    checkpoint_every: int = Field(10, ge=1, description="outputs between checkpoints")
    vtk_every: int = Field(0, ge=0, description="outputs between VTK files (0: first and last only)")
    vtk: bool = True
    png: bool = True


class ParallelSection(_Section):
    devices: int = Field(1, ge=1, description="JAX devices to shard the first grid axis over")


class BoundarySection(_Section):
    kind: Literal["periodic", "lees-edwards", "wall"] = "periodic"
    shear_rate: float | None = Field(None, gt=0.0, description="Lees-Edwards shear rate du_flow/dx_axis [1/s]")
    flow: Literal["x", "y", "z"] | None = Field(None, description="Lees-Edwards flow / wall motion direction (not this axis)")
    wall_speed: float | None = Field(None, ge=0.0, description="relative wall speed U [m/s]: lower wall at -U/2, upper at +U/2")
    walls: WallsConfig | None = Field(None, description="wall conditions (as in ktgf couette): both, or lower/upper via bottom/top")

    @model_validator(mode="after")
    def _complete(self) -> BoundarySection:
        if self.kind == "lees-edwards" and (self.shear_rate is None or self.flow is None):
            raise ValueError("a lees-edwards boundary needs shear_rate (> 0, 1/s) and flow ('x', 'y' or 'z')")
        if self.kind == "wall" and (self.walls is None or self.flow is None or self.wall_speed is None):
            raise ValueError("a wall boundary needs walls (e.g. {type = 'johnson-jackson', specularity = 0.1}), "
                             "flow ('x', 'y' or 'z') and wall_speed (>= 0, m/s)")
        extra = {"shear_rate": self.kind != "lees-edwards", "flow": self.kind == "periodic",
                 "wall_speed": self.kind != "wall", "walls": self.kind != "wall"}
        if bad := [k for k, refused in extra.items() if refused and getattr(self, k) is not None]:
            raise ValueError(f"a {self.kind} boundary takes no {', '.join(bad)}")
        return self


class BoundariesSection(_Section):
    x: BoundarySection = BoundarySection()
    y: BoundarySection = BoundarySection()
    z: BoundarySection = BoundarySection()

    @model_validator(mode="after")
    def _one_shear(self) -> BoundariesSection:
        le = [a for a in AXES if getattr(self, a).kind == "lees-edwards"]
        walls = [a for a in AXES if getattr(self, a).kind == "wall"]
        if len(le) > 1:
            raise ValueError(f"at most one axis can be lees-edwards (one shear gradient); got {', '.join(le)}")
        if len(walls) > 1 or (le and walls):
            raise ValueError(f"one sheared axis at most: lees-edwards on {le or 'none'}, walls on {walls or 'none'}")
        for a in le + walls:
            flow = getattr(self, a).flow
            if flow == a:
                raise ValueError(f"{a}.flow = {a!r} is the gradient axis itself: valid flow is another axis")
            if getattr(self, flow).kind != "periodic":
                raise ValueError(f"{a}.flow = {flow!r}: the flow axis must be periodic")
        return self

    def wall_axis(self) -> str | None:
        return next((a for a in AXES if getattr(self, a).kind == "wall"), None)

    def shear_axis(self) -> str | None:
        return next((a for a in AXES if getattr(self, a).kind == "lees-edwards"), None)


class CaseSection(_Section):
    kind: str = Field("cooling", description="a registered case (ktgf.solver.cases): cooling (periodic box), uniform-shear "
                      "(Lees-Edwards box), couette (two moving walls), chute (gravity-driven layer on an inclined base)")
    inclination_deg: float | None = Field(None, gt=0.0, lt=90.0, description="chute: base inclination [degrees]")
    gravity: float = Field(9.81, gt=0.0, description="chute: acceleration of gravity g [m/s^2]")

    @field_validator("kind", mode="before")
    @classmethod
    def _kind(cls, v: Any) -> Any:
        if not isinstance(v, str) or v not in CASES:
            *head, last = [repr(k) for k in CASES]
            raise ValueError(f"Input should be {', '.join(head)} or {last}")
        return v


class Config(_Section):
    model: ModelSection = ModelSection()
    particles: ParticlesSection = ParticlesSection()
    initial: InitialSection
    grid: GridSection
    numerics: NumericsSection = NumericsSection()
    time: TimeSection
    output: OutputSection = OutputSection()
    parallel: ParallelSection = ParallelSection()
    case: CaseSection = CaseSection()
    boundaries: BoundariesSection = BoundariesSection()


def _fmt_error(err: dict[str, Any]) -> str:
    loc = ".".join(str(p) for p in err["loc"]) or "config"
    msg = err["msg"].removeprefix("Value error, ")
    got = err.get("input")
    tail = f" (got {got!r})" if got is not None and not isinstance(got, dict) else ""
    return f"field {loc}: {msg}{tail}"


def parse_config(data: dict[str, Any], source: str = "config") -> Config:
    """Validate a config dict; raise :class:`InputError` naming every bad field, then check the physics."""
    try:
        cfg = Config.model_validate(plain(data))
    except ValidationError as exc:
        raise InputError(f"{source}: " + "; ".join(_fmt_error(e) for e in exc.errors())) from None
    check_physics(cfg, source)
    return cfg


def load_config(path: str | Path) -> Config:
    """Read and validate a TOML run configuration."""
    return parse_config(read_toml(path), str(path))


def _check_friction(cfg: Config, model: Any, source: str) -> None:
    """What the 3D solver does not do with frictional particles yet (docs/friction.md §7), one line each."""
    kind, case = cfg.case.kind, get_case(cfg.case.kind)
    if model.friction.has_stress and not case.imposed_shear:
        # The rate-independent viscosity is regularised with ε γ̇_ref, γ̇_ref the case's imposed shear rate.
        raise InputError(f"{source}: field model.options.stress = {model.friction.stress!r}: a frictional stress "
                         f"needs a case with an imposed shear rate for its regularisation (valid case.kind: "
                         f"{kinds(lambda c: c.imposed_shear, ', ', str)}; got {kind!r})")
    if model.friction.mu > 0.0 and case.hcs:  # the HCS dissipation: Walton's rule has none at weak μ
        try:
            model.reduced(cfg.initial.solid_fraction, cfg.model.restitution, hcs=True)
        except KtgfError as exc:
            raise InputError(f"{source}: field model.options.mu: {exc}") from None
    wall = cfg.boundaries.wall_axis()  # check_case: only on a case between walls
    walls = getattr(cfg.boundaries, wall).walls if wall else None
    rough = [w for w in (walls.build_pair() if walls is not None else ()) if w.friction_angle > 0.0]
    if rough and not (model.friction.has_stress and all(w.momentum == "johnson-jackson" for w in rough)):
        # the JJ frictional wall traction is p_f tan δ_w: it needs a frictional normal stress p_f
        raise InputError(f"{source}: field boundaries.{wall}.walls.friction_angle = {rough[0].friction_angle:g} acts on "
                         "the frictional normal stress: valid > 0 only with a johnson-jackson momentum wall and a model "
                         "with a frictional stress (model.options.stress)")


def check_physics(cfg: Config, source: str = "config") -> None:
    """Cross-field checks that need the model: φ0 below the packing limit, a valid model name/options."""
    try:
        model = get_model(cfg.model.name, **cfg.model.options)
    except KtgfError as exc:
        raise InputError(f"{source}: field model.name/options: {exc}") from None
    phi0 = cfg.initial.solid_fraction
    stop = cfg.numerics.phi_stop if cfg.numerics.phi_stop is not None else 0.99 * model.phi_max
    if phi0 >= model.phi_max:
        raise InputError(f"{source}: field initial.solid_fraction = {phi0:g} is out of range: valid 0 < phi < "
                         f"{model.phi_max:g} (packing limit of model {model.name!r})")
    if phi0 >= stop:
        raise InputError(f"{source}: field initial.solid_fraction = {phi0:g} is at or above numerics.phi_stop = {stop:g}")
    mode, cells = cfg.initial.mode, cfg.grid.cells
    if cfg.initial.perturbation in ("mode", "shear-mode") and (mode is None or len(mode) != len(cells) or not any(mode)):
        raise InputError(f"{source}: field initial.mode = {mode} must have {len(cells)} integers, not all 0")
    if mode is not None and any(abs(n) > c // 2 for n, c in zip(mode, cells)):
        raise InputError(f"{source}: field initial.mode = {mode} is out of range: valid |mode[a]| <= cells[a]/2 = "
                         f"{[c // 2 for c in cells]} (the grid resolves no shorter wave)")
    if cfg.initial.max_mode > max(cells) // 2:
        raise InputError(f"{source}: field initial.max_mode = {cfg.initial.max_mode} is out of range: valid "
                         f"1 <= max_mode <= {max(cells) // 2} (half the largest cell count)")
    check_case(cfg, source)
    _check_friction(cfg, model, source)
    if cfg.grid.relative_to is not None:
        kp, kl = critical_wavenumbers(model.reduced(phi0, cfg.model.restitution, hcs=True))
        k = kp if cfg.grid.relative_to == "transverse" else kl
        if not float(k) > 0:
            raise InputError(f"{source}: field grid.relative_to = {cfg.grid.relative_to!r}: model {model.name!r} at "
                             f"phi = {phi0:g}, e = {cfg.model.restitution:g} has no {cfg.grid.relative_to} instability "
                             "(infinite critical size); give grid.length instead")


def check_case(cfg: Config, source: str = "config") -> None:
    """The case and its boundaries fit together and fit the grid (one-line errors naming the field)."""
    ndim, kind, b = len(cfg.grid.cells), cfg.case.kind, cfg.boundaries
    for a in AXES[ndim:]:
        if getattr(b, a).kind != "periodic":
            raise InputError(f"{source}: field boundaries.{a}.kind = {getattr(b, a).kind!r}: the grid has {ndim} "
                             f"axis/axes ({', '.join(AXES[:ndim])}); axis {a} has no boundary to set")
    shear, wall, case = b.shear_axis(), b.wall_axis(), get_case(kind)
    if not case.inclined and cfg.case.inclination_deg is not None:
        raise InputError(f"{source}: field case.inclination_deg applies to case.kind = {kinds(lambda c: c.inclined)} only")
    if case.boundary is not None and (shear if case.boundary == LEES_EDWARDS else wall) is None:
        raise InputError(f"{source}: field case.kind = {kind!r} needs one boundaries.<axis> with kind = "
                         f"{case.boundary!r} (valid axes: {', '.join(AXES[:ndim])})")
    case.check(cfg, source, shear, wall)
    if not case.inclined and cfg.initial.shear_rate is not None:
        raise InputError(f"{source}: field initial.shear_rate sets the start of a chute only (other cases: the boundaries)")
    for key in ("acoustics", "sink"):
        if getattr(cfg.numerics, key) == "implicit" and cfg.time.scheme == "ssprk3":
            raise InputError(f"{source}: field numerics.{key} = 'implicit' needs time.scheme = 'imex' or 'auto' "
                             "(got 'ssprk3', an explicit scheme)")
    for axis, need in ((shear, LEES_EDWARDS), (wall, WALL)):
        if axis is not None and case.boundary != need:
            raise InputError(f"{source}: field boundaries.{axis}.kind = {need!r} needs case.kind = "
                             f"{kinds(lambda c, need=need: c.boundary == need)}")
    if wall is not None:
        try:
            getattr(b, wall).walls.build_pair()
        except KtgfError as exc:
            raise InputError(f"{source}: field boundaries.{wall}.walls: {exc}") from None
    sheared = not case.hcs
    if sheared and cfg.time.unit in ("tau", "haff"):
        raise InputError(f"{source}: field time.unit = {cfg.time.unit!r} is for the cooling case (Haff's law); "
                         f"valid for case.kind = {kind!r}: 's' or 'strain'")
    if not sheared and cfg.time.unit == "strain":
        raise InputError(f"{source}: field time.unit = 'strain' needs a sheared case; valid for the cooling case: "
                         "'tau', 'haff' or 's'")
    if sheared and cfg.grid.relative_to is not None:
        raise InputError(f"{source}: field grid.relative_to sizes a cooling box (HCS critical size); "
                         f"give grid.length or grid.length_d for case.kind = {kind!r}")
    if sheared and cfg.initial.perturbation == "mode":
        raise InputError(f"{source}: field initial.perturbation = 'mode' is an HCS eigenmode; valid for "
                         f"case.kind = {kind!r}: 'random', 'none'" + (" or 'shear-mode'" if shear else ""))
    check_shear_mode(cfg, source)


def check_shear_mode(cfg: Config, source: str = "config") -> None:
    """A uniform-shear normal-mode seed (``perturbation = "shear-mode"``) fits its case and box."""
    ini, b = cfg.initial, cfg.boundaries
    if ini.perturbation == "mode" and ini.branch > 2:
        raise InputError(f"{source}: field initial.branch = {ini.branch} is out of range: valid 0 <= branch <= 2 "
                         "for an HCS longitudinal mode")
    if ini.perturbation != "shear-mode":
        return
    if get_case(cfg.case.kind).boundary != LEES_EDWARDS:  # a normal mode of uniform shear
        raise InputError(f"{source}: field initial.perturbation = 'shear-mode' needs case.kind = "
                         f"{kinds(lambda c: c.boundary == LEES_EDWARDS)} (got {cfg.case.kind!r})")
    flow = AXES.index(getattr(b, b.shear_axis()).flow)
    if flow < len(ini.mode) and ini.mode[flow] != 0:
        raise InputError(f"{source}: field initial.mode = {ini.mode} varies along the flow axis {AXES[flow]}: "
                         f"valid mode[{flow}] = 0 (a normal mode of uniform shear has k_flow = 0)")
    try:  # the analysis refuses e = 1 and shear-dependent dissipation
        theta = initial_temperature(cfg)
    except KtgfError as exc:
        raise InputError(f"{source}: field initial.perturbation = 'shear-mode': {exc}") from None
    if ini.temperature is not None and abs(ini.temperature - theta) > SHEAR_MODE_THETA_RTOL * theta:
        raise InputError(f"{source}: field initial.temperature = {ini.temperature:g} m^2/s^2 differs from the steady "
                         f"θ = {theta:.6g} m^2/s^2 that perturbation = 'shear-mode' starts from: omit the field")


#: Relative tolerance on a given initial.temperature against the closed-form θ of a shear-mode seed.
SHEAR_MODE_THETA_RTOL = 1e-6


def initial_temperature(cfg: Config) -> float:
    """θ0 [m²/s²]: ``initial.temperature``, or for ``perturbation = "shear-mode"`` the steady θ of the
    closed form at the box's γ̇ (:func:`ktgf.shear.stability.shear_base_state`), which the seed starts from."""
    ini, b = cfg.initial, cfg.boundaries
    if ini.perturbation != "shear-mode":
        return float(ini.temperature)
    from ..shear.stability import shear_base_state

    le = getattr(b, b.shear_axis())
    return shear_base_state(get_model(cfg.model.name, **cfg.model.options), ini.solid_fraction, cfg.model.restitution,
                            float(le.shear_rate), d=cfg.particles.diameter, rho_s=cfg.particles.density).theta


def config_value(d: Any, dotted: str) -> Any:
    """The value at a dotted key (``grid.cells``) of a configuration dict (None if absent)."""
    for key in dotted.split("."):
        d = d.get(key) if isinstance(d, dict) else None
    return d


def changed_fields(a: Any, b: Any, prefix: str = "") -> list[str]:
    """Dotted names of the leaves that differ between two configuration dicts (sorted)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return [f for key in sorted(set(a) | set(b)) for f in changed_fields(a.get(key), b.get(key), f"{prefix}{key}.")]
    return [] if a == b else [prefix.rstrip(".") or "config"]


def box_lengths(cfg: Config) -> tuple[float, ...]:
    """Box sides [m] from ``grid.length``, ``grid.length_d`` or ``relative_to``·``factor``."""
    g, d, ndim = cfg.grid, cfg.particles.diameter, len(cfg.grid.cells)

    def per_axis(v: Any, scale: float) -> tuple[float, ...]:
        vals = v if isinstance(v, list) else [v]
        vals = vals * ndim if len(vals) == 1 else vals
        return tuple(float(x) * scale for x in vals)

    if g.length is not None:
        return per_axis(g.length, 1.0)
    if g.length_d is not None:
        return per_axis(g.length_d, d)
    phi0 = cfg.initial.solid_fraction
    model = get_model(cfg.model.name, **cfg.model.options)
    kp, kl = critical_wavenumbers(model.reduced(phi0, cfg.model.restitution, hcs=True))
    k = float(kp if g.relative_to == "transverse" else kl)
    return per_axis(g.factor * BOX_CONSTANT / (phi0 * k), d)
