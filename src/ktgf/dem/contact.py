"""The DEM contact law and its restitution calibration.

Normal force: linear spring–dashpot, F_n = k_n δ − m_eff γ_n v_n (LAMMPS ``gran/hooke/history``,
m_eff = m/2 for equal spheres).  Free solution (Schäfer, Dippel & Wolf, J. Phys. I France 6, 5
(1996), Eq. (2.9)): a damped oscillator of frequency ω = √(k_n/m_eff − γ_n²/4) whose half
period is the contact time and whose amplitude ratio is the restitution,

    t_c = π/ω,     e = exp(−γ_n t_c/2),
    so   γ_n = −2 ln e / t_c,     k_n = m_eff (π² + ln² e)/t_c².                              (1)

Eq. (1) is exact in continuous time (the dashpot's small pull before separation included; LAMMPS
keeps it unless ``limit_damping`` is set).  Velocity Verlet at a finite step t_c/Δt and the
arbitrary phase of the first contact within a step change e slightly, so :func:`calibrate_restitution`
runs two-sphere collisions in LAMMPS at the production ratio t_c/Δt, several impact phases at once,
and finds the ``e_model`` that, put into Eq. (1), gives the target e on average.  The law is linear,
so in units of t_c the result depends only on (e, t_c/Δt): it is cached per that pair (and LAMMPS
version).  Tangential: spring with history k_t = (2/7) k_n (tangential and normal periods equal for
solid spheres), no tangential dashpot, Coulomb cap μ|F_n|.

Contact time from the state: t_c = f_c/ν_E with the Enskog collision frequency of hard spheres
(Chapman & Cowling, 3rd ed., §16.5), ν_E = 4 √π n d² χ √(T/m), T = m⟨c²⟩/3.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .lammps import Lammps, find_lammps

#: Mass of the equal spheres (DEM units d = m = 1) and their reduced mass.
MASS = 1.0
REDUCED_MASS = 0.5
#: Impact phases of a calibration (contact starting at (k + 1/2)/PHASES of a step, k = 0..PHASES−1).  The
#: restitution of one collision is a sawtooth in the phase: the dashpot's last, attractive step either
#: falls inside the contact or not, a jump of ≈ 2 e |ln e| Δt/t_c; 64 phases put the mean within ~1e-4.
PHASES = 64
#: Calibration stops when the phase-averaged restitution is this close to the target.
TOLERANCE = 1e-6


def spring_dashpot(e_model: float, t_c: float) -> tuple[float, float]:
    """(k_n, γ_n) of Eq. (1) for restitution ``e_model`` and contact time ``t_c`` (m_eff = 1/2)."""
    ln_e = math.log(e_model)
    return REDUCED_MASS * (math.pi**2 + ln_e**2) / t_c**2, -2.0 * ln_e / t_c


def collision_frequency(phi: float, T: float) -> float:
    """Enskog collision frequency per sphere ν_E = 4 √π n χ_CS √T (d = m = 1, n = 6φ/π, Carnahan–Starling χ)."""
    from ..closures.rdf import CarnahanStarling

    n = 6.0 * phi / math.pi
    chi = float(CarnahanStarling().chi(phi))
    return 4.0 * math.sqrt(math.pi) * n * chi * math.sqrt(T)


def _two_body_script(e_model: float, steps_per_contact: float, speed: float = 1.0) -> tuple[str, int]:
    """LAMMPS input: PHASES head-on pairs far apart, contact starting at phase k/PHASES of a step."""
    kn, gn = spring_dashpot(e_model, 1.0)
    dt = 1.0 / steps_per_contact
    lead = 3  # whole steps of flight before the first possible contact
    lines = [
        "units lj", "atom_style sphere", "dimension 3", "boundary f f f", "newton off", "comm_modify vel yes",
        f"region box block -4 4 -4 4 -4 {4 * PHASES + 4} units box", "create_box 1 box",
    ]
    for k in range(PHASES):
        gap = speed * dt * (lead + (k + 0.5) / PHASES)
        z = 4.0 * k
        lines += [f"create_atoms 1 single {-0.5 - gap / 2:.17g} 0 {z} units box",
                  f"create_atoms 1 single {0.5 + gap / 2:.17g} 0 {z} units box"]
    steps = lead + 2 + math.ceil(1.3 * steps_per_contact) + 5
    lines += [
        f"set type 1 diameter 1.0 density {6.0 / math.pi:.17g}",
        f"pair_style gran/hooke/history {kn:.17g} {2.0 / 7.0 * kn:.17g} {gn:.17g} 0.0 0.0 0",
        "pair_coeff * *", f"timestep {dt:.17g}",
        "neighbor 0.5 bin", "neigh_modify delay 0 every 1 check yes",
        "fix 1 all nve/sphere",
        # odd ids were created on the left: they move right, the even ones left
        "variable odd atom (id%2)", "group left variable odd", "group right subtract all left",
        f"velocity left set {speed / 2:.17g} 0 0 units box", f"velocity right set {-speed / 2:.17g} 0 0 units box",
        f"run {steps}", "write_dump all custom final.dump id vx modify sort id format float %.17g",
    ]
    return "\n".join(lines) + "\n", steps


def two_body_restitution(e_model: float, steps_per_contact: float, *, lammps: Lammps | None = None,
                         workdir: Path | None = None) -> np.ndarray:
    """Restitution of PHASES head-on collisions run in LAMMPS with the Eq. (1) law for ``e_model`` at t_c/Δt = ``steps_per_contact``."""
    lammps = lammps or find_lammps()
    with tempfile.TemporaryDirectory(prefix="ktgf-dem-e-") as tmp:
        where = Path(workdir) if workdir is not None else Path(tmp)
        where.mkdir(parents=True, exist_ok=True)
        script, _ = _two_body_script(e_model, steps_per_contact)
        (where / "in.two_body").write_text(script)
        lammps.run(where / "in.two_body", where, log="log.two_body")
        rows = _read_dump_table(where / "final.dump")
    vx = rows[:, 1].reshape(PHASES, 2)
    # left sphere (odd id) came in at +1/2, right at −1/2: e = (v_right − v_left)/1
    return vx[:, 1] - vx[:, 0]


def _read_dump_table(path: Path) -> np.ndarray:
    lines = Path(path).read_text().splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("ITEM: ATOMS")) + 1
    return np.array([[float(v) for v in ln.split()] for ln in lines[start:] if ln.strip()])


@dataclass(frozen=True)
class Restitution:
    """A calibrated contact: target ``e``, the ``e_model`` to put into Eq. (1), and the two-body check.

    ``mean_error`` is the phase-averaged restitution minus e (what a gas of random impact phases
    sees); ``spread`` the standard deviation and ``max_error`` the worst single collision.
    """

    e: float
    steps_per_contact: float
    e_model: float
    mean_error: float
    max_error: float
    spread: float
    lammps_version: str

    def parameters(self, t_c: float) -> tuple[float, float]:
        """(k_n, γ_n) for contact time ``t_c``."""
        return spring_dashpot(self.e_model, t_c)


def cache_path() -> Path:
    """The calibration cache file: ``$KTGF_CACHE_DIR/dem_restitution.json`` (default ``~/.cache/ktgf``)."""
    root = os.environ.get("KTGF_CACHE_DIR") or os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "ktgf")
    return Path(root) / "dem_restitution.json"


def _cache_key(e: float, steps_per_contact: float, version: str) -> str:
    return f"e={e:.12g} steps_per_contact={steps_per_contact:.12g} phases={PHASES} lammps={version}"


def calibrate_restitution(e: float, steps_per_contact: float = 50.0, *, lammps: Lammps | None = None,
                          use_cache: bool = True, max_iterations: int = 20) -> Restitution:
    """The ``e_model`` whose LAMMPS two-body collisions at t_c/Δt = ``steps_per_contact`` give restitution ``e``.

    Elastic contacts (e = 1) need no dashpot.  Fixed-point iteration on ln e_model (e is nearly
    proportional to e_model); results are cached (:func:`cache_path`).
    """
    from ..errors import InputError

    if not 0.0 < e <= 1.0:
        raise InputError(f"restitution coefficient e = {e:g} is out of range: valid 0 < e <= 1")
    if not steps_per_contact >= 10:
        raise InputError(f"steps per contact = {steps_per_contact:g} is out of range: valid >= 10 (a coarser step does not resolve a collision)")
    lammps = lammps or find_lammps()
    key = _cache_key(e, steps_per_contact, lammps.version)
    path = cache_path()
    cache = {}
    if use_cache and path.is_file():
        try:
            cache = json.loads(path.read_text())
        except (OSError, ValueError):
            cache = {}
        try:
            if key in cache:
                return Restitution(**cache[key])
        except TypeError:  # an entry of another ktgf version: calibrate again
            pass
    e_model = e
    for _ in range(max_iterations):
        measured = two_body_restitution(e_model, steps_per_contact, lammps=lammps)
        mean = float(measured.mean())
        if abs(mean - e) < TOLERANCE:
            break
        e_model = min(1.0, e_model * e / mean)
    result = Restitution(e=float(e), steps_per_contact=float(steps_per_contact), e_model=float(e_model),
                         mean_error=mean - e, max_error=float(np.max(np.abs(measured - e))),
                         spread=float(measured.std()), lammps_version=lammps.version)
    if use_cache:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            cache[key] = result.__dict__
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(json.dumps(cache, indent=1))
            tmp.replace(path)
        except OSError:  # a read-only cache costs a recalibration next time, nothing else
            pass
    return result
