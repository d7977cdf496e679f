"""Uniform (Lees–Edwards) shear of inelastic, optionally frictional spheres in LAMMPS.

Protocol (units d = m = 1, γ̇ = 1): N spheres on an fcc lattice at the target φ (the lattice of
⌈(N/4)^(1/3)⌉³ cells, surplus sites deleted at random), Gaussian velocities at the expected
temperature on top of the linear streaming profile, then sheared by ``fix deform xy erate 1
remap v`` (the LAMMPS form of Lees–Edwards boundaries) for ``strain`` units.  The first ``skip``
strain units are discarded; the rest (the window) is averaged in blocks of one strain unit,
pooled over seeds for the standard errors.  Each state is checked for a steady state (means of the
window's halves), crystallisation (global Q6 of snapshots) and a linear velocity profile.
Stress from LAMMPS ``compute pressure`` with the peculiar kinetic part (``temp/deform``): p = tr P/3,
τ = −P_xy.  T = m⟨c²⟩/3 (peculiar), T_rot = I⟨(ω − ⟨ω⟩)²⟩/3 with I = m d²/10.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from . import analysis
from .contact import calibrate_restitution, collision_frequency
from .lammps import Lammps, RunParameters, find_lammps

#: DEM units: ρ_s = 6/π (d = m = 1), moment of inertia of a solid sphere I = m d²/10.
RHO_S = 6.0 / math.pi
INERTIA = 0.1
#: Samples per strain unit in the time series, rows (averages of samples) per strain unit.
SAMPLES_PER_STRAIN = 100
ROWS_PER_STRAIN = 50
#: Snapshots for the Q6 check, bins of the velocity profile.
SNAPSHOTS = 4
PROFILE_BINS = 10
#: A state is flagged when Q6 exceeds this (liquid ≈ 0.02–0.05 at N = 864, fcc 0.575), when the
#: fitted profile slope is off by more than PROFILE_SLOPE_TOL or deviates by more than PROFILE_DEV_TOL.
Q6_CRYSTAL = 0.1
PROFILE_SLOPE_TOL = 0.1
PROFILE_DEV_TOL = 0.05
#: Steady-state test: the halves of the window differ by more than DRIFT_SIGMA standard errors and DRIFT_REL.
DRIFT_SIGMA = 3.0
DRIFT_REL = 0.02
#: Quantities of the time series (columns of series.txt after the step column).
SERIES = ("T", "Trot", "pxx", "pyy", "pzz", "pxy", "contacts")


@dataclass(frozen=True)
class ShearRun(RunParameters):
    """One LAMMPS run: a state (φ, e, μ, N) and seed with its protocol."""

    phi: float
    e: float
    mu: float = 0.0
    particles: int = 864
    seed: int = 1
    strain: float = 10.0
    skip: float = 2.0
    contact_fraction: float = 0.01
    steps_per_contact: float = 50.0

    @property
    def key(self) -> str:
        return f"mu{self.mu:g}_phi{self.phi:g}_e{self.e:g}_N{self.particles}_fc{self.contact_fraction:g}"


def jamming_point(mu: float) -> float:
    """The jamming fraction φ_J(μ) of ktgf's registered frictional model (where its RDF diverges; docs/friction.md)."""
    from ..closures import get_model

    return float(get_model("frictional", mu=float(mu)).phi_max)


def check_state(phi: float, e: float, mu: float, particles: int, strain: float = 10.0, skip: float = 2.0,
                contact_fraction: float = 0.01) -> None:
    """One-line :class:`InputError` for a state a run cannot handle."""
    if not 0.0 < e <= 1.0:
        raise InputError(f"restitution coefficient e = {e:g} is out of range: valid 0 < e <= 1")
    if e == 1.0:
        raise InputError("restitution coefficient e = 1: elastic spheres heat up without bound under shear; valid 0 < e < 1 for dem shear")
    if not mu >= 0.0:
        raise InputError(f"friction coefficient mu = {mu:g} is out of range: valid mu >= 0")
    if particles < 100:
        raise InputError(f"particles N = {particles} is too few for a periodic box: valid N >= 100")
    phi_c = jamming_point(mu)
    if not 0.0 < phi < phi_c:
        if phi >= phi_c:
            raise InputError(f"solid fraction phi = {phi:g} is at or above the jamming point phi_c(mu = {mu:g}) = {phi_c:.3f}: "
                             "the spheres would jam instead of shearing; valid 0 < phi < phi_c")
        raise InputError(f"solid fraction phi = {phi:g} is out of range: valid 0 < phi < {phi_c:.3f}")
    if not 0.0 < skip < strain:
        raise InputError(f"strain = {strain:g} with {skip:g} discarded leaves no window: valid strain > skip > 0")
    if not 0.0 < contact_fraction <= 0.1:
        raise InputError(f"contact-time fraction f_c = {contact_fraction:g} is out of range: valid 0 < f_c <= 0.1 (rigid limit)")


def expected_temperature(phi: float, e: float) -> float:
    """θ/(γ̇d)² of the RET uniform-shear closed form (frictionless): only sets the contact time and start velocities."""
    from ..closures import get_model
    from ..shear.steady import steady_temperature

    return float(steady_temperature(get_model("ret"), phi, e))


def contact_time(phi: float, T: float, contact_fraction: float) -> float:
    """t_c = f_c/ν_E at (φ, T)."""
    return contact_fraction / collision_frequency(phi, T)


def _script(run: ShearRun, kn: float, gamma_n: float, dt: float, T0: float) -> tuple[str, dict]:
    N = run.particles
    L = (N * math.pi / 6.0 / run.phi) ** (1.0 / 3.0)
    cells = math.ceil((N / 4.0) ** (1.0 / 3.0) - 1e-9)
    a = L / cells
    surplus = 4 * cells**3 - N
    steps_per_strain = round(1.0 / dt)
    every = max(1, steps_per_strain // SAMPLES_PER_STRAIN)
    per_row = SAMPLES_PER_STRAIN // ROWS_PER_STRAIN
    row = every * per_row
    skip_steps = round(run.skip * steps_per_strain / row) * row
    total_steps = round(run.strain * steps_per_strain / row) * row
    window = total_steps - skip_steps
    dt_exact = run.strain / total_steps  # whole rows per strain unit: dt adjusted by < 1e-5 relative
    snap = max(row, window // SNAPSHOTS // row * row)
    seed = 1000 + 7919 * run.seed
    lines = [
        "# ktgf dem shear: Lees-Edwards uniform shear, gdot = 1, d = m = 1",
        "units lj", "atom_style sphere", "dimension 3", "boundary p p p", "newton off", "comm_modify vel yes",
        f"region box prism 0 {L:.17g} 0 {L:.17g} 0 {L:.17g} 0 0 0 units box", "create_box 1 box",
        f"lattice fcc {4.0 / a**3:.17g}", "create_atoms 1 box",
    ]
    if surplus:
        lines.append(f"delete_atoms random count {surplus} yes all NULL {seed + 1}")
    lines += [
        f"set type 1 diameter 1.0 density {RHO_S:.17g}",
        f"pair_style gran/hooke/history {kn:.17g} {2.0 / 7.0 * kn:.17g} {gamma_n:.17g} 0.0 {run.mu:.17g} 0",
        "pair_coeff * *", f"timestep {dt_exact:.17g}",
        "neighbor 0.15 bin", "neigh_modify delay 0 every 1 check yes",
        "fix integrate all nve/sphere",
        "fix shear all deform 1 xy erate 1.0 remap v flip yes",
        f"velocity all create {T0:.17g} {seed} dist gaussian mom yes loop geom",
        f"velocity all ramp vx 0 {L:.17g} y 0 {L:.17g} sum yes units box",
        "compute tdef all temp/deform", "compute_modify tdef extra/dof 0",
        "compute p all pressure tdef",
        "compute om all property/atom omegax omegay omegaz",
        "variable w2 atom c_om[1]^2+c_om[2]^2+c_om[3]^2",
        "compute wm all reduce ave c_om[1] c_om[2] c_om[3] v_w2",
        f"variable trot equal {INERTIA:.17g}/3*(c_wm[4]-c_wm[1]^2-c_wm[2]^2-c_wm[3]^2)",
        "compute cn all contact/atom", "compute cnm all reduce ave c_cn",
        f"fix series all ave/time {every} {per_row} {row} c_tdef v_trot c_p[1] c_p[2] c_p[3] c_p[4] c_cnm file series.txt",
        "thermo_modify temp tdef", f"thermo {row * ROWS_PER_STRAIN}",
        "thermo_style custom step c_tdef c_p cpu",
        f"run {skip_steps}",
        f"compute layers all chunk/atom bin/1d y lower {1.0 / PROFILE_BINS:.17g} units reduced",
        # a running average written every row: its last block is the average over the whole window
        f"fix profile all ave/chunk {every} {per_row} {row} layers vx ave running file profile.txt",
        f"dump snaps all custom {snap} snaps.dump id x y z", "dump_modify snaps sort id",
        f"run {window}",
    ]
    return "\n".join(lines) + "\n", {"L": L, "dt": dt_exact, "total_steps": total_steps, "skip_steps": skip_steps}


def run_dir_for(root: Path, run: ShearRun) -> Path:
    return Path(root) / run.key / f"seed{run.seed}"


def run_shear(run: ShearRun, root: Path, *, lammps: Lammps | None = None) -> dict:
    """Run one seed of a state in ``root/<state>/seed<k>`` (kept: input, log, series) and return its block data.

    A folder whose ``result.json`` matches this run is not rerun (resumable sweeps).
    """
    where = run_dir_for(root, run)
    done = where / "result.json"
    if done.is_file():
        try:
            res = json.loads(done.read_text())
            if res.get("digest") == run.digest():
                return res
        except (OSError, ValueError):
            pass
    check_state(run.phi, run.e, run.mu, run.particles, run.strain, run.skip, run.contact_fraction)
    lammps = lammps or find_lammps()
    rest = calibrate_restitution(run.e, run.steps_per_contact, lammps=lammps)
    T_est = expected_temperature(run.phi, run.e)
    t_c = contact_time(run.phi, T_est, run.contact_fraction)
    kn, gamma_n = rest.parameters(t_c)
    dt = t_c / run.steps_per_contact
    script, geom = _script(run, kn, gamma_n, dt, T_est)
    where.mkdir(parents=True, exist_ok=True)
    for stale in ("series.txt", "profile.txt", "snaps.dump", "log.lammps"):
        (where / stale).unlink(missing_ok=True)
    (where / "in.shear").write_text(script)
    c0 = children_cpu()
    w0 = time.perf_counter()
    lammps.run(where / "in.shear", where)
    cpu = children_cpu() - c0
    res = _analyse(run, where, geom)
    res.update(digest=run.digest(), run=asdict(run), lammps_version=lammps.version, kn=kn, kt=2.0 / 7.0 * kn,
               gamma_n=gamma_n, e_model=rest.e_model, restitution_two_body_error=rest.mean_error,
               t_c=t_c, dt=geom["dt"], T_expected=T_est, L=geom["L"],
               wall_seconds=time.perf_counter() - w0, cpu_seconds=cpu, lammps_loop_seconds=_loop_time(where / "log.lammps"))
    done.write_text(json.dumps(res, indent=1))
    return res


def children_cpu() -> float:
    """CPU seconds (user + system) of this process's finished children: LAMMPS's own CPU time."""
    import resource

    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _loop_time(log: Path) -> float:
    """LAMMPS's "Loop time" (wall seconds of its time steps)."""
    total = 0.0
    for ln in log.read_text(errors="replace").splitlines():
        if ln.startswith("Loop time of"):
            total += float(ln.split()[3])
    return total


def _analyse(run: ShearRun, where: Path, geom: dict) -> dict:
    series = analysis.read_ave_time(where / "series.txt")
    strain = series[:, 0] * geom["dt"]
    values = series[:, 1:]
    rows = int(np.count_nonzero(strain > run.skip + 1e-9))
    # blocks of one strain unit (at least 2, at most one row each)
    blocks = analysis.block_means(strain, values, run.skip, run.strain, min(rows, max(2, round(run.strain - run.skip))))
    half = analysis.block_means(strain, values, run.skip, run.strain, 2)
    k = max(1, min(4, rows // 2))
    eighths = analysis.block_means(strain, values, run.skip, run.strain, 2 * k)
    drifts = {}
    for name, col in (("T", 0), ("p", None)):
        q = eighths[:, col] if col is not None else eighths[:, 2:5].mean(axis=1)
        drifts[name] = analysis.drift(q[:k], q[k:])
    prof = analysis.read_ave_chunk(where / "profile.txt")
    slope, dev = analysis.profile_linearity(prof[:, 1] * geom["L"], prof[:, 3], prof[:, 2], 1.0, geom["L"])
    q6 = [analysis.q6_global(lo, H, x) for lo, H, x in analysis.read_dump_frames(where / "snaps.dump")]
    return {"blocks": blocks.tolist(), "halves": half.tolist(), "drift": drifts,
            "profile_slope": slope, "profile_deviation": dev, "q6": q6, "series_columns": list(SERIES)}


def derived(block: np.ndarray, phi: float) -> dict[str, float]:
    """The file's observables from one block's means (T, Trot, Pxx, Pyy, Pzz, Pxy, contacts)."""
    T, Trot, pxx, pyy, pzz, pxy, cn = block
    n = 6.0 * phi / math.pi
    p = (pxx + pyy + pzz) / 3.0
    tau = -pxy  # γ̇ = 1
    eta0 = 5.0 / 16.0 * math.sqrt(T / math.pi)
    nu0 = 16.0 / 5.0 * math.sqrt(math.pi) * n * math.sqrt(T)
    return {"T": T, "Trot_over_T": Trot / T, "p_star": p / RHO_S, "tau_star": tau / RHO_S, "tau_over_p": tau / p,
            "p_over_nT": p / (n * T), "eta_over_eta0": tau / eta0, "eta_star": tau / math.sqrt(T),
            "contacts_per_particle": cn, "astar": 1.0 / nu0}


@dataclass
class ShearState:
    """A state's averages over blocks and seeds, with standard errors and checks."""

    mu: float
    phi: float
    e: float
    N: int
    seeds: list[int]
    values: dict[str, float]
    errors: dict[str, float]
    checks: dict = field(default_factory=dict)
    contact: dict = field(default_factory=dict)


def combine(runs: list[ShearRun], results: list[dict]) -> ShearState:
    """Pool the blocks of all seeds of one state into means and standard errors, and collect its checks."""
    r0 = runs[0]
    per_block = [derived(np.array(b), r0.phi) for res in results for b in res["blocks"]]
    values, errors = {}, {}
    for k in per_block[0]:
        values[k], errors[k] = analysis.mean_and_error([d[k] for d in per_block])
    drift_T = max((res["drift"]["T"] for res in results), key=lambda d: abs(d[1]))
    drift_p = max((res["drift"]["p"] for res in results), key=lambda d: abs(d[1]))
    steady = all(not (abs(z) > DRIFT_SIGMA and abs(rel) > DRIFT_REL) for rel, z in (drift_T, drift_p))
    q6 = max(max(res["q6"]) for res in results)
    slope = [res["profile_slope"] for res in results]
    dev = max(res["profile_deviation"] for res in results)
    linear = all(abs(s - 1.0) <= PROFILE_SLOPE_TOL for s in slope) and dev <= PROFILE_DEV_TOL
    T = values["T"]
    t_c = results[0]["t_c"]
    checks = {"steady": steady, "drift_T": drift_T[0], "drift_T_sigma": drift_T[1], "drift_p": drift_p[0],
              "drift_p_sigma": drift_p[1], "q6_max": q6, "crystallised": q6 > Q6_CRYSTAL, "profile_slope_min": min(slope),
              "profile_slope_max": max(slope), "profile_deviation_max": dev, "linear_profile": linear,
              "contact_fraction_measured": t_c * collision_frequency(r0.phi, T),
              "cpu_seconds": sum(res.get("cpu_seconds", math.nan) for res in results)}
    contact = {k: results[0][k] for k in ("kn", "kt", "gamma_n", "e_model", "restitution_two_body_error", "t_c", "dt", "lammps_version")}
    contact.update(steps_per_contact=r0.steps_per_contact, contact_fraction=r0.contact_fraction,
                   strain=r0.strain, skip=r0.skip)
    return ShearState(r0.mu, r0.phi, r0.e, r0.particles, [r.seed for r in runs], values, errors, checks, contact)


def warnings_of(state: ShearState) -> list[str]:
    """One line per failed check of a state."""
    c, out = state.checks, []
    where = f"mu={state.mu:g} phi={state.phi:g} e={state.e:g}"
    if not c["steady"]:
        out.append(f"{where}: not steady (T drifts {100 * c['drift_T']:+.1f}%, p {100 * c['drift_p']:+.1f}% between the window's halves); "
                   "use a longer --strain")
    if c["crystallised"]:
        out.append(f"{where}: crystallised (Q6 = {c['q6_max']:.3f} > {Q6_CRYSTAL})")
    if not c["linear_profile"]:
        out.append(f"{where}: velocity profile not linear (slope/gdot {c['profile_slope_min']:.3f}..{c['profile_slope_max']:.3f}, "
                   f"largest deviation {100 * c['profile_deviation_max']:.1f}% of gdot L)")
    return out
