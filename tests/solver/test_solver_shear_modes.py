"""Growth rates of shear-flow perturbations in the 3D solver against the linear analysis of uniform shear.

One normal mode of :func:`ktgf.shear.stability.shear_modes` (k_x = 0: wave vector along the
gradient y or the vorticity z, so that the perturbation is a constant-coefficient normal mode
exp(σt)) is put on the steady uniform shear of a Lees–Edwards box with a tiny amplitude.  The
Fourier coefficients of (δφ, δu_x, δu_y, δu_z, δθ) at its wave vector are projected on the
mode by its left eigenvector, which is orthogonal to every other (generalised) eigenvector, so
the other modes, excited by the discretisation error of the seed, do not leak into the fit, and log(amplitude) is fitted
against time.  The oracle is the eigenvalue problem, computed outside the solver.  Tolerance
2 % of |σ|.  A second-order scheme's error on a diffusive rate is ~(kΔx)²/12 (0.3 % at 32 cells
per wavelength); the slow layering mode is more sensitive (2.9 % at 32 cells, 0.42 % at 64: its
rate is a small difference of fast pressure, stress and energy terms), so it is fitted at 64.

Base state: RET, φ = 0.3, e = 0.9, γ̇ = 100/s, wavelength L = 16 d (the modes of
docs/uniform_shear_stability.md): k ∥ y σ/γ̇ = −0.0512 (layering), −0.2022 (shear wave),
−0.4397 ± 1.852i (sound), −0.9612 (heat); k ∥ z −0.2022 (twice, a Jordan pair: not fitted),
−0.5159 (heat), −0.5868 ± 1.769i (sound).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.growth import fit_rate, fourier_coefficient

from ktgf.closures import get_model
from ktgf.shear.stability import shear_matrix
from ktgf.solver.boundaries import Boundaries
from ktgf.solver.flows import add_base_flow, linear_profile
from ktgf.solver.grid import Grid
from ktgf.solver.initial import shear_axes, shear_mode
from ktgf.solver.physics import Physics
from ktgf.solver.state import primitive
from ktgf.solver.stepping import Numerics, advance

MODEL, PHI, E, D, RHO_S, RATE = "ret", 0.3, 0.9, 1e-3, 2500.0, 100.0
L = 16 * D


def shear_box(direction: str, n: int) -> tuple[Grid, tuple[int, ...]]:
    """A Lees–Edwards box resolving one wavelength L along the gradient or vorticity direction, and its mode."""
    if direction == "gradient":  # 1D along the gradient axis x, flow along y (not a grid axis)
        return Grid((n,), (L,), Boundaries(("lees-edwards",), shear_rate=RATE, flow=1)), (1,)
    # vorticity: 4 cells along the gradient axis x (uniform in x), n along y = vorticity, flow along z
    return Grid((4, n), (4 * D, L), Boundaries(("lees-edwards", "periodic"), shear_rate=RATE, flow=2)), (0, 1)


def measure_shear_rate(direction: str, n: int, branch: int, strain: float, amplitude: float = 1e-4,
                       scheme: str = "imex") -> tuple[complex, complex]:
    """(measured, theoretical) σ/γ̇ of mode ``branch`` on an ``n``-cell wavelength, fitted over ``strain``."""
    m = get_model(MODEL)
    phys = Physics(m, E, D, RHO_S, 0.99 * m.phi_max)
    grid, mode = shear_box(direction, n)
    U, modes = shear_mode(grid, phys, PHI, mode, amplitude, branch)
    U = add_base_flow(U, grid)
    f, a, v = shear_axes(grid)
    k = grid.wavevector(mode)
    sigma, base = modes.growth_rates[branch], modes.base
    scale = np.array([PHI, *[np.sqrt(base.theta)] * 3, base.theta])  # well-conditioned units
    A = shear_matrix(base, 0.0, k[a], k[v]) * scale[None, :] / scale[:, None]
    left = np.linalg.svd((A - sigma * np.eye(5)).conj().T)[2][-1].conj()  # null vector of (A − σ)^H
    seed = modes.vectors[:, branch] / scale
    times = np.linspace(0.0, strain / RATE, 9)
    t, proj = 0.0, []
    num = Numerics(scheme=scheme)
    for target in times:
        U, t, _, status, _ = advance(U, t, float(target), 10**6, grid, phys, num)
        assert int(status) == 0
        W = np.array(primitive(U))
        W[1 + f] -= linear_profile(grid)
        fields = (W[0] / RHO_S, W[1 + f], W[1 + a], W[1 + v], W[4])
        y = np.array([fourier_coefficient(x, grid, mode) for x in fields])
        proj.append(np.vdot(left, y / scale) / np.vdot(left, seed))
    return fit_rate(times * RATE, np.array(proj)), complex(sigma / RATE)


@pytest.mark.analytic
@pytest.mark.parametrize(
    "direction, n, branch, strain",
    [   # one grid per direction (one compilation each); explicit SSP-RK3: cheaper to compile than IMEX
        ("gradient", 64, 0, 6.0),   # layering (shear-banding) mode, slow: the hardest to resolve
        ("gradient", 64, 2, 4.0),    # sound wave: complex σ
        ("vorticity", 32, 2, 4.0),   # heat mode
        ("vorticity", 32, 3, 3.0),   # sound wave: complex σ
    ],
)
def test_shear_growth_rates(direction: str, n: int, branch: int, strain: float) -> None:
    measured, theory = measure_shear_rate(direction, n, branch, strain, scheme="ssprk3")
    print(f"{direction} n={n} branch {branch}: relative error {abs(measured - theory) / abs(theory):.4f}",
          measured, theory)
    assert abs(measured - theory) <= 0.02 * abs(theory), (measured, theory)


@pytest.mark.analytic
@pytest.mark.slow
def test_layering_rate_converges_with_resolution() -> None:
    """The layering mode's error falls faster than second order (measured: 22 %, 2.9 %, 0.42 % at
    16, 32, 64 cells per wavelength: the upwind dissipation of the convective scheme on a mode
    whose rate is a small difference of large terms).  Default IMEX scheme.  145 s at load 8 on 2 cores."""
    errors = []
    for n in (16, 32, 64):
        measured, theory = measure_shear_rate("gradient", n, 0, 10.0)
        errors.append(abs(measured - theory) / abs(theory))
    print("relative errors", errors)
    assert errors[1] < errors[0] / 4 and errors[2] < errors[1] / 4 and errors[2] < 0.01, errors


def _config(mode: list[int], kind: str = "uniform-shear", branch: int = 2, flow: str = "z", temperature: str = "") -> str:
    return f"""
[case]
kind = "{kind}"
[model]
name = "{MODEL}"
restitution = {E}
[initial]
solid_fraction = {PHI}
{temperature}
perturbation = "shear-mode"
mode = {mode}
branch = {branch}
amplitude = 1e-4
[grid]
cells = [4, 32]
length_d = [4.0, 16.0]
[boundaries]
x = {{ kind = "lees-edwards", shear_rate = {RATE}, flow = "{flow}" }}
[time]
end = 3.0
unit = "strain"
outputs = 6
[output]
png = false
vtk = false
"""


@pytest.mark.analytic
@pytest.mark.slow
def test_shear_mode_seed_from_a_config_decays_at_the_eigenvalue_rate() -> None:
    """``perturbation = "shear-mode"`` through the run machinery (``ktgf run``): the peculiar kinetic
    energy of a real mode decays as exp(2σt) (heat mode along the vorticity, σ/γ̇ = −0.516).
    Slow only for its own compilation (49 s at load 8 on 2 cores)."""
    import tomllib

    from ktgf.solver.config import parse_config
    from ktgf.solver.run import Simulation

    sim = Simulation(parse_config(tomllib.loads(_config([0, 1]))))
    ds = sim.run(progress=False, write_files=False)
    strain = np.asarray(ds["time"]) * RATE
    slope = np.polyfit(strain, np.log(np.asarray(ds["peculiar_energy"])), 1)[0]
    m = get_model(MODEL)
    grid, mode = shear_box("vorticity", 32)
    _, modes = shear_mode(grid, Physics(m, E, D, RHO_S, 0.99 * m.phi_max), PHI, mode, 1e-4, 2)
    sigma = modes.growth_rates[2].real / RATE
    assert abs(slope / 2 - sigma) <= 0.02 * abs(sigma), (slope / 2, sigma)


@pytest.mark.contract
@pytest.mark.parametrize("kind, branch, pert, flow, field", [
    ("uniform-shear", 2, "shear-mode", "y", "initial.mode"),  # k along the flow: a Kelvin mode, not a normal mode
    ("cooling", 2, "shear-mode", "z", "initial.perturbation"),
    ("cooling", 3, "mode", "z", "initial.branch"),  # three HCS longitudinal modes
    ("elastic", 2, "shear-mode", "z", "initial.perturbation"),  # e = 1: no steady uniform shear
])
def test_bad_shear_mode_config_names_the_field(kind: str, branch: int, pert: str, flow: str, field: str) -> None:
    import tomllib

    from ktgf.errors import InputError
    from ktgf.solver.config import parse_config

    text = _config([0, 1], kind="uniform-shear" if kind == "elastic" else kind, branch=branch, flow=flow,
                   temperature="temperature = 1e-2" if kind == "cooling" else "")
    if kind == "elastic":
        text = text.replace(f"restitution = {E}", "restitution = 1.0")
    text = text.replace('"shear-mode"', f'"{pert}"')
    if kind == "cooling":
        text = text.replace('x = { kind = "lees-edwards", shear_rate = 100.0, flow = "z" }', "").replace(
            'unit = "strain"', 'unit = "s"')
    with pytest.raises(InputError) as exc:
        parse_config(tomllib.loads(text))
    assert "\n" not in str(exc.value) and field in str(exc.value), str(exc.value)


@pytest.mark.contract
def test_shear_mode_temperature_is_the_closed_form_or_refused() -> None:
    """``initial.temperature`` is optional for a shear-mode seed (θ0 is the closed-form steady θ);
    a value that differs is refused in one line naming the field, a missing one elsewhere too."""
    import tomllib

    from ktgf.shear.steady import steady_shear
    from ktgf.errors import InputError
    from ktgf.solver.config import initial_temperature, parse_config

    theta = float(steady_shear(get_model(MODEL), PHI, E).T) * (RATE * D) ** 2
    cfg = parse_config(tomllib.loads(_config([0, 1])))
    assert cfg.initial.temperature is None
    assert initial_temperature(cfg) == pytest.approx(theta, rel=1e-12)
    parse_config(tomllib.loads(_config([0, 1], temperature=f"temperature = {theta!r}")))  # the same θ: accepted
    with pytest.raises(InputError) as exc:
        parse_config(tomllib.loads(_config([0, 1], temperature="temperature = 1e-2")))
    msg = str(exc.value)
    assert "\n" not in msg and "initial.temperature = 0.01" in msg and f"{theta:.6g}" in msg, msg
    random = _config([0, 1]).replace('"shear-mode"', '"random"')
    with pytest.raises(InputError) as exc:
        parse_config(tomllib.loads(random))
    assert "\n" not in str(exc.value) and "initial.temperature" in str(exc.value), str(exc.value)
