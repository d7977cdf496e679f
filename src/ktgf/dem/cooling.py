"""Homogeneous cooling of frictionless inelastic spheres in LAMMPS, written as ``dem_hcs_cooling.csv``.

Protocol (shared/data/README.md): N spheres on an fcc lattice at φ in a periodic cube, Gaussian
velocities at T0 = 1, equilibrated with elastic contacts for 20 Enskog collisions per sphere, then
cooled freely with the calibrated contact of restitution e until T < T0/4.  Haff's law,
T^(−1/2) = T0^(−1/2) + (A/2) t, is fitted by least squares over T0 → T0/4 (``A_main``) and
T0 → T0/2 (``A_early``); A = ζ/√T.  The ratios divide by the Enskog value with the Sonine
correction (van Noije & Ernst, Granular Matter 1, 57 (1998), Eq. (29) for d = 3):

    A_E = (4√π/3)(1 − e²) χ_CS n (1 + 3 a2/16),   a2 = 16(1 − e)(1 − 2e²)/(81 − 17e + 30e²(1 − e)).

Contact time t_c = f_c/ν_E(φ, T0): as the gas cools, t_c ν_E falls (ever more rigid).
Not checked: clustering (the README's flow-energy test); keep N φ small enough for the
homogeneous state to last to T0/4 (the shared boxes are).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from . import analysis
from .contact import calibrate_restitution, collision_frequency, spring_dashpot
from .lammps import Lammps, RunParameters, find_lammps
from .shear import RHO_S

COLUMNS = ("phi", "e", "N", "seeds", "A_main", "A_main_sem", "A_early", "ratio_main", "ratio_early", "p_over_nT")
#: Elastic collisions per sphere before cooling starts; samples per Enskog collision time.
EQUILIBRATION_COLLISIONS = 20.0
SAMPLES_PER_COLLISION = 5


@dataclass(frozen=True)
class CoolingRun(RunParameters):
    phi: float
    e: float
    particles: int = 6912
    seed: int = 1
    contact_fraction: float = 0.01
    steps_per_contact: float = 50.0

    @property
    def key(self) -> str:
        return f"hcs_phi{self.phi:g}_e{self.e:g}_N{self.particles}_fc{self.contact_fraction:g}"


def check_cooling(phi: float, e: float, particles: int, contact_fraction: float = 0.01) -> None:
    if not 0.0 < e < 1.0:
        raise InputError(f"restitution coefficient e = {e:g} is out of range: valid 0 < e < 1 (an elastic gas does not cool)")
    if particles < 100:
        raise InputError(f"particles N = {particles} is too few for a periodic box: valid N >= 100")
    if not 0.0 < phi < 0.494:
        raise InputError(f"solid fraction phi = {phi:g} is out of range: valid 0 < phi < 0.494 "
                         "(the hard-sphere freezing point: a denser elastic gas crystallises before it cools)")
    if not 0.0 < contact_fraction <= 0.1:
        raise InputError(f"contact-time fraction f_c = {contact_fraction:g} is out of range: valid 0 < f_c <= 0.1 (rigid limit)")


def sonine_a2(e: float) -> float:
    """a2 of the homogeneous cooling state in 3D (van Noije & Ernst 1998, Eq. (29))."""
    return 16.0 * (1.0 - e) * (1.0 - 2.0 * e**2) / (81.0 - 17.0 * e + 30.0 * e**2 * (1.0 - e))


def enskog_haff_rate(phi: float, e: float) -> float:
    """A_E = (4√π/3)(1 − e²) χ_CS n (1 + 3 a2/16) (d = m = 1)."""
    from ..closures.rdf import CarnahanStarling

    n = 6.0 * phi / math.pi
    return 4.0 * math.sqrt(math.pi) / 3.0 * (1.0 - e**2) * float(CarnahanStarling().chi(phi)) * n * (1.0 + 3.0 * sonine_a2(e) / 16.0)


def _script(run: CoolingRun, e_model: float) -> tuple[str, dict]:
    N = run.particles
    L = (N * math.pi / 6.0 / run.phi) ** (1.0 / 3.0)
    cells = math.ceil((N / 4.0) ** (1.0 / 3.0) - 1e-9)
    surplus = 4 * cells**3 - N
    nu0 = collision_frequency(run.phi, 1.0)
    t_c = run.contact_fraction / nu0
    dt = t_c / run.steps_per_contact
    kn_el, _ = spring_dashpot(1.0, t_c)
    kn, gn = spring_dashpot(e_model, t_c)
    every = max(1, round(1.0 / nu0 / SAMPLES_PER_COLLISION / dt))
    eq_steps = round(EQUILIBRATION_COLLISIONS / nu0 / dt)
    # Enskog time to T0/4 is 2/A_E; allow three times that before giving up
    max_steps = round(3.0 * 2.0 / enskog_haff_rate(run.phi, run.e) / dt)
    seed = 1000 + 7919 * run.seed
    lines = [
        "# ktgf dem cooling: homogeneous cooling, d = m = 1, T0 = 1",
        "units lj", "atom_style sphere", "dimension 3", "boundary p p p", "newton off", "comm_modify vel yes",
        f"region box block 0 {L:.17g} 0 {L:.17g} 0 {L:.17g} units box", "create_box 1 box",
        f"lattice fcc {4.0 / (L / cells) ** 3:.17g}", "create_atoms 1 box",
    ]
    if surplus:
        lines.append(f"delete_atoms random count {surplus} yes all NULL {seed + 1}")
    lines += [
        f"set type 1 diameter 1.0 density {RHO_S:.17g}",
        f"pair_style gran/hooke/history {kn_el:.17g} {2.0 / 7.0 * kn_el:.17g} 0.0 0.0 0.0 0",
        "pair_coeff * *", f"timestep {dt:.17g}",
        "neighbor 0.15 bin", "neigh_modify delay 0 every 1 check yes",
        "fix integrate all nve/sphere",
        f"velocity all create 1.0 {seed} dist gaussian mom yes loop geom",
        "compute t all temp", "compute_modify t extra/dof 0", "compute p all pressure t",
        "thermo_modify temp t", f"thermo {every * 100}", "thermo_style custom step c_t c_p cpu",
        f"run {eq_steps}",
        "variable T0 equal $(c_t)",
        "reset_timestep 0",
        f"pair_style gran/hooke/history {kn:.17g} {2.0 / 7.0 * kn:.17g} {gn:.17g} 0.0 0.0 0",
        "pair_coeff * *",
        "variable tnow equal c_t",
        f"fix series all ave/time {every} 1 {every} c_t c_p file series.txt",
        f"fix stop all halt {every} v_tnow < $(0.24*v_T0) error continue",
        f"run {max_steps}",
    ]
    return "\n".join(lines) + "\n", {"dt": dt, "t_c": t_c, "kn": kn, "gamma_n": gn, "L": L}


def haff_fit(t: np.ndarray, T: np.ndarray, T0: float, fraction: float) -> float:
    """A from a least-squares line through T^(−1/2) against t while T ≥ fraction·T0 (Haff: slope A/2)."""
    end = np.flatnonzero(T < fraction * T0)
    stop = int(end[0]) if end.size else len(T)
    slope = np.polyfit(t[:stop], T[:stop] ** -0.5, 1)[0]
    return float(2.0 * slope)


def run_cooling(run: CoolingRun, root: Path, *, lammps: Lammps | None = None) -> dict:
    """Run one seed in ``root/<state>/seed<k>`` (resumable like :func:`ktgf.dem.shear.run_shear`)."""
    where = Path(root) / run.key / f"seed{run.seed}"
    done = where / "result.json"
    if done.is_file():
        try:
            res = json.loads(done.read_text())
            if res.get("digest") == run.digest():
                return res
        except (OSError, ValueError):
            pass
    check_cooling(run.phi, run.e, run.particles, run.contact_fraction)
    lammps = lammps or find_lammps()
    rest = calibrate_restitution(run.e, run.steps_per_contact, lammps=lammps)
    script, info = _script(run, rest.e_model)
    where.mkdir(parents=True, exist_ok=True)
    for stale in ("series.txt", "log.lammps"):
        (where / stale).unlink(missing_ok=True)
    (where / "in.cooling").write_text(script)
    w0 = time.perf_counter()
    lammps.run(where / "in.cooling", where)
    s = analysis.read_ave_time(where / "series.txt")
    t, T, P = s[:, 0] * info["dt"], s[:, 1], s[:, 2:5].mean(axis=1)
    T0 = float(T[0])
    if T.min() >= 0.25 * T0:
        raise InputError(f"cooling run phi={run.phi:g} e={run.e:g} did not reach T0/4 within 3 Enskog cooling times; see {where / 'log.lammps'}")
    # T0 is the first sample (one sampling interval after the switch); t from there
    t = t - t[0]
    n = 6.0 * run.phi / math.pi
    main = T >= 0.25 * T0
    res = {"digest": run.digest(), "run": asdict(run), "A_main": haff_fit(t, T, T0, 0.25), "A_early": haff_fit(t, T, T0, 0.5),
           "p_over_nT": float(np.mean(P[main] / (n * T[main]))), "e_model": rest.e_model, **info,
           "lammps_version": lammps.version, "wall_seconds": time.perf_counter() - w0}
    done.write_text(json.dumps(res, indent=1))
    return res


def combine_cooling(runs: list[CoolingRun], results: list[dict]) -> dict:
    """One row of the file: means over seeds, the standard error of A_main over seeds, ratios to A_E."""
    r0 = runs[0]
    a_main = np.array([r["A_main"] for r in results])
    a_early = np.array([r["A_early"] for r in results])
    a_e = enskog_haff_rate(r0.phi, r0.e)
    sem = float(a_main.std(ddof=1) / math.sqrt(len(a_main))) if len(a_main) > 1 else float("nan")
    return {"phi": r0.phi, "e": r0.e, "N": r0.particles, "seeds": len(runs), "A_main": float(a_main.mean()), "A_main_sem": sem,
            "A_early": float(a_early.mean()), "ratio_main": float(a_main.mean() / a_e), "ratio_early": float(a_early.mean() / a_e),
            "p_over_nT": float(np.mean([r["p_over_nT"] for r in results])),
            "_contact": {k: results[0][k] for k in ("kn", "gamma_n", "t_c", "dt", "e_model", "lammps_version")}}


def csv_text(rows: list[dict]) -> str:
    version = rows[0]["_contact"]["lammps_version"] if rows else "no states"
    head = [f"# Homogeneous cooling of frictionless inelastic spheres, LAMMPS DEM run by `ktgf dem cooling` (LAMMPS {version})",
            "# A = zeta/sqrt(T) in units d=m=1 (zeta = -dlnT/dt, T = m<c^2>/3): fitted Haff slope over T0 -> T0/4 (A_main) and T0 -> T0/2 (A_early)",
            "# ratio_* = A / A_Enskog with A_Enskog = (4 sqrt(pi)/3)(1-e^2) chi_CS n (1+3a2/16); sem = standard error over seeds"]
    for r in rows:
        c = r["_contact"]
        head.append(f"# state phi={r['phi']:g} e={r['e']:g} N={r['N']}: kn={c['kn']:.6g} gamma_n={c['gamma_n']:.6g} "
                    f"(e_model={c['e_model']:.6g}) t_c={c['t_c']:.4g} dt={c['dt']:.4g}")
    body = [",".join(COLUMNS)] + [",".join(f"{r[k]:.6g}" if isinstance(r[k], float) else str(r[k]) for k in COLUMNS) for r in rows]
    return "\n".join(head + body) + "\n"
