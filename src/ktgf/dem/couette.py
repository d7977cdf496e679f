"""Planar Couette flow between bumpy walls in LAMMPS, written as ``dem_couette_e0.9_phi0.50.csv``.

Geometry of the shared case (shared/data/README.md): periodic in x (flow, L_x) and z (vorticity,
L_z = rows·√3/2); each wall a rigid hexagonal layer of touching spheres (d = 1, rows along x) with
centres at y = ∓H/2, moving at ∓U/2; N flowing spheres at mean φ over the slab between the planes
tangent to the wall-sphere tops (|y| ≤ (H − 1)/2); no gravity.  Contacts: the calibrated linear
spring–dashpot for particle–particle, and 2k_n, 2 m_eff γ_n for particle–wall (the wall spheres have
effectively infinite mass), so that a sphere–wall collision has the same t_c and e as a
sphere–sphere one.  LAMMPS ``pair_style granular`` (per-type coefficients, ``damping mass_velocity``:
η_n = m_eff γ_n), walls moved by ``fix move``.

Profiles in bins of 0.5 d across y, averaged in blocks of 2 strain units (strain = U t/H) after the
start-up: φ from the exact sphere/slab intersection of 0.05-wide centre histograms, u_x (centre in
bin), θ = (1/3)⟨|v − u|²⟩ with u the bin's window mean, ⟨c_i c_j⟩, and the stress (kinetic part from
those moments plus the per-atom virial, half of each contact to each partner).  Wall stresses from the
forces on the wall spheres: τ = (F_x,bottom − F_x,top)/(2A), p_yy = (F_y,top − F_y,bottom)/(2A).
"""

from __future__ import annotations

import itertools
import json
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from .contact import calibrate_restitution
from .lammps import Lammps, RunParameters, find_lammps
from .shear import RHO_S

BIN = 0.5
FINE = 0.05
BLOCK_STRAIN = 2.0
COLUMNS = ("y", "phi", "ux", "theta", "phi_sem", "ux_sem", "theta_sem", "phi_centre", "phi_wall", "uy", "uz",
           "Txx", "Tyy", "Tzz", "Txy", "ncount", "tau_xy", "p_xx", "p_yy", "p_zz")


@dataclass(frozen=True)
class CouetteRun(RunParameters):
    phi: float = 0.5
    e: float = 0.9
    mu: float = 0.0
    height: float = 20.0
    speed: float = 10.0
    cells_x: int = 12
    rows_z: int = 14
    strain: float = 200.0
    skip: float = 110.0
    contact_time: float = 0.003125
    steps_per_contact: float = 50.0
    seed: int = 1

    @property
    def key(self) -> str:
        return f"couette_phi{self.phi:g}_e{self.e:g}_mu{self.mu:g}_H{self.height:g}_U{self.speed:g}"

    @property
    def lz(self) -> float:
        return self.rows_z * math.sqrt(3.0) / 2.0

    @property
    def particles(self) -> int:
        slab = self.cells_x * self.lz * (self.height - 1.0)
        return round(self.phi * slab / (math.pi / 6.0))


def check_couette(run: CouetteRun) -> None:
    if not 0.0 < run.e <= 1.0:
        raise InputError(f"restitution coefficient e = {run.e:g} is out of range: valid 0 < e <= 1")
    if not run.mu >= 0.0:
        raise InputError(f"friction coefficient mu = {run.mu:g} is out of range: valid mu >= 0")
    if not 0.0 < run.phi < 0.6:
        raise InputError(f"mean solid fraction phi = {run.phi:g} is out of range: valid 0 < phi < 0.6 "
                         "(a denser cell jams at its centre)")
    if run.height < 4 or run.cells_x < 4 or run.rows_z < 4 or run.rows_z % 2:
        raise InputError(f"Couette cell H = {run.height:g}, {run.cells_x} x {run.rows_z} wall spheres is out of range: "
                         "valid H >= 4, >= 4 spheres per row, an even number >= 4 of rows")
    if run.speed <= 0:
        raise InputError(f"wall speed U = {run.speed:g} is out of range: valid U > 0")
    if not 0.0 < run.skip < run.strain - BLOCK_STRAIN:
        raise InputError(f"strain = {run.strain:g} with {run.skip:g} discarded leaves no averaging block: valid strain > skip + {BLOCK_STRAIN:g}")
    if run.particles < 100:
        raise InputError(f"the cell holds N = {run.particles} flowing spheres: valid N >= 100 (a larger cell or phi)")


def _positions(run: CouetteRun) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(bottom wall, top wall, flowing spheres) centres: flowing ones on a commensurate fcc lattice, surplus deleted at random."""
    lx, lz, h = float(run.cells_x), run.lz, run.height
    wall = np.array([[i + 0.5 * (j % 2), 0.0, j * math.sqrt(3.0) / 2.0] for j in range(run.rows_z) for i in range(run.cells_x)])
    bottom, top = wall + [0.0, -h / 2, 0.0], wall + [0.0, h / 2, 0.0]
    span = h - 2.0  # centres within |y| <= H/2 - 1: clear of the wall spheres
    nx, nz = max(1, int(lx / 1.42)), max(1, int(lz / 1.42))
    ny = max(1, int(span / 1.42))
    ax, ay, az = lx / nx, span / ny, lz / nz
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
    sites = np.array([[(i + b[0]) * ax, -span / 2 + (k + b[1]) * ay, (j + b[2]) * az]
                      for i in range(nx) for j in range(nz) for k in range(ny) for b in basis])
    sites = sites[sites[:, 1] <= span / 2 + 1e-9]
    if len(sites) < run.particles or min(ax, ay, az) / math.sqrt(2.0) < 1.0:
        raise InputError(f"mean solid fraction phi = {run.phi:g} is too dense to place {run.particles} spheres without overlap "
                         "on the start lattice: valid about phi <= 0.5")
    rng = np.random.default_rng(run.seed)
    keep = np.sort(rng.choice(len(sites), run.particles, replace=False))
    return bottom, top, sites[keep]


def _data_file(run: CouetteRun, bottom: np.ndarray, top: np.ndarray, flow: np.ndarray) -> str:
    lx, lz, h = float(run.cells_x), run.lz, run.height
    heavy = 1e6 * RHO_S  # wall spheres: m_eff of a sphere-wall contact = m (to 1e-6)
    rows = [(1, 1.0, RHO_S, p) for p in flow] + [(2, 1.0, heavy, p) for p in bottom] + [(3, 1.0, heavy, p) for p in top]
    lines = ["ktgf dem couette", "", f"{len(rows)} atoms", "3 atom types", "",
             f"0 {lx:.17g} xlo xhi", f"{-h / 2 - 1.0:.17g} {h / 2 + 1.0:.17g} ylo yhi", f"0 {lz:.17g} zlo zhi", "", "Atoms # sphere", ""]
    lines += [f"{i + 1} {t} {d:.17g} {rho:.17g} {p[0]:.17g} {p[1]:.17g} {p[2]:.17g}" for i, (t, d, rho, p) in enumerate(rows)]
    return "\n".join(lines) + "\n"


def _script(run: CouetteRun, e_model: float) -> tuple[str, dict]:
    from .contact import spring_dashpot

    kn, gn = spring_dashpot(e_model, run.contact_time)
    kt = 2.0 / 7.0 * kn
    dt = run.contact_time / run.steps_per_contact
    time_per_strain = run.height / run.speed
    steps_per_strain = time_per_strain / dt
    block = max(100, round(BLOCK_STRAIN * steps_per_strain / 100) * 100)
    every = block // 100
    skip = round(run.skip * steps_per_strain / block) * block
    total = round(run.strain * steps_per_strain / block) * block
    dt_exact = run.strain * time_per_strain / total
    u = run.speed / 2.0
    h = run.height
    nbins = round((h + 1.0) / BIN)
    nfine = round((h + 1.0) / FINE)
    seed = 1000 + 7919 * run.seed
    tang = f"tangential linear_history {{kt:.17g}} 0.0 {run.mu:.17g}"
    lines = [
        "# ktgf dem couette: planar Couette flow between bumpy walls, d = m = 1",
        "units lj", "atom_style sphere", "dimension 3", "boundary p f p", "newton off", "comm_modify vel yes",
        "read_data couette.data",
        "group flow type 1", "group bottom type 2", "group top type 3", "group walls type 2 3",
        "pair_style granular",
        f"pair_coeff 1 1 hooke {kn:.17g} {gn:.17g} {tang.format(kt=kt)} damping mass_velocity",
        # wall spheres have ~infinite mass (m_eff = 1): 2 k_n keeps t_c; the dashpot's m_eff*gamma_n doubles by itself
        f"pair_coeff 1 2*3 hooke {2 * kn:.17g} {gn:.17g} {tang.format(kt=2 * kt)} damping mass_velocity",
        f"pair_coeff 2*3 2*3 hooke {kn:.17g} 0.0 {tang.format(kt=kt)} damping mass_velocity",
        "neigh_modify exclude type 2 2", "neigh_modify exclude type 3 3", "neigh_modify exclude type 2 3",
        f"timestep {dt_exact:.17g}",
        "neighbor 0.15 bin", "neigh_modify delay 0 every 1 check yes",
        "fix integrate flow nve/sphere",
        f"fix mb bottom move linear {-u:.17g} 0 0", f"fix mt top move linear {u:.17g} 0 0",
        # start: the mean flow of a linear profile plus thermal velocities of the wall-speed scale
        f"velocity flow create {0.05 * run.speed ** 2:.17g} {seed} dist gaussian mom yes loop geom",
        f"velocity flow ramp vx {-u:.17g} {u:.17g} y {-h / 2:.17g} {h / 2:.17g} sum yes units box",
        "compute fb bottom reduce sum fx fy", "compute ft top reduce sum fx fy",
        "thermo 10000", "thermo_style custom step c_fb[1] c_ft[1] c_fb[2] c_ft[2] cpu",
        f"run {skip}",
        f"compute layers flow chunk/atom bin/1d y {-h / 2 - 0.5:.17g} {BIN:.17g} units box bound y {-h / 2 - 0.5:.17g} {h / 2 + 0.5:.17g}",
        f"compute fine flow chunk/atom bin/1d y {-h / 2 - 0.5:.17g} {FINE:.17g} units box bound y {-h / 2 - 0.5:.17g} {h / 2 + 0.5:.17g}",
        "compute vir flow stress/atom NULL virial",
        "variable vxx atom vx*vx", "variable vyy atom vy*vy", "variable vzz atom vz*vz", "variable vxy atom vx*vy",
        (f"fix prof flow ave/chunk {every} 100 {block} layers vx vy vz v_vxx v_vyy v_vzz v_vxy c_vir[1] c_vir[2] c_vir[3] c_vir[4] "
        "norm all file profile.txt"),
        f"fix hist flow ave/chunk {every} 100 {block} fine vx norm all file fine.txt",
        f"fix walls all ave/time {every} 100 {block} c_fb[1] c_ft[1] c_fb[2] c_ft[2] file walls.txt",
        f"run {total - skip}",
    ]
    return "\n".join(lines) + "\n", {"dt": dt_exact, "kn": kn, "gamma_n": gn, "block_steps": block, "bins": nbins,
                                     "fine_bins": nfine, "skip_steps": skip, "total_steps": total}


def _read_chunk_blocks(path: Path) -> np.ndarray:
    """All blocks of a ``fix ave/chunk`` file: array (blocks, chunks, columns)."""
    blocks: list[list[list[float]]] = []
    for ln in Path(path).read_text().splitlines():
        if not ln.strip() or ln.startswith("#"):
            continue
        parts = ln.split()
        if len(parts) == 3:
            blocks.append([])
        else:
            blocks[-1].append([float(v) for v in parts])
    return np.array(blocks, dtype=float)


def slab_volume(centre: np.ndarray, lo: float, hi: float, r: float = 0.5) -> np.ndarray:
    """Volume of a sphere of radius r centred at y = ``centre`` inside the slab lo ≤ y ≤ hi (exact)."""
    a = np.clip(lo - centre, -r, r)
    b = np.clip(hi - centre, -r, r)
    # ∫ π (r² − s²) ds from a to b
    return math.pi * ((r * r * b - b**3 / 3.0) - (r * r * a - a**3 / 3.0))


def _sem(blocks: np.ndarray) -> np.ndarray:
    return blocks.std(axis=0, ddof=1) / math.sqrt(len(blocks)) if len(blocks) > 1 else np.full(blocks.shape[1:], math.nan)


def _analyse(run: CouetteRun, where: Path, info: dict) -> dict:
    prof = _read_chunk_blocks(where / "profile.txt")  # columns: chunk, coord, count, vx, vy, vz, vxx, vyy, vzz, vxy, s1..s4
    fine = _read_chunk_blocks(where / "fine.txt")
    walls = np.array([[float(v) for v in ln.split()] for ln in (where / "walls.txt").read_text().splitlines()
                      if ln.strip() and not ln.startswith("#")])
    area = run.cells_x * run.lz
    h = run.height
    edges = -h / 2 - 0.5 + BIN * np.arange(info["bins"] + 1)
    centres_fine = -h / 2 - 0.5 + FINE * (np.arange(info["fine_bins"]) + 0.5)
    bin_volume = area * BIN
    # φ per block: each fine histogram bin's spheres (centre at the bin's centre) cut by each coarse bin
    overlap = np.array([[slab_volume(c, lo, hi) for c in centres_fine] for lo, hi in itertools.pairwise(edges)])
    phi_blocks = fine[:, :, 2] @ overlap.T / bin_volume
    count = prof[:, :, 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = {}
        w = count.sum(axis=0)
        for name, col in (("vx", 3), ("vy", 4), ("vz", 5), ("vxx", 6), ("vyy", 7), ("vzz", 8), ("vxy", 9),
                          ("s1", 10), ("s2", 11), ("s3", 12), ("s4", 13)):
            mean[name] = np.where(w > 0, (prof[:, :, col] * count).sum(axis=0) / w, 0.0)
        ux_blocks = prof[:, :, 3]
        txx = mean["vxx"] - mean["vx"] ** 2
        tyy = mean["vyy"] - mean["vy"] ** 2
        tzz = mean["vzz"] - mean["vz"] ** 2
        txy = mean["vxy"] - mean["vx"] * mean["vy"]
        theta = (txx + tyy + tzz) / 3.0
        # θ per block about the window mean u (for the block standard error)
        theta_blocks = ((prof[:, :, 6] + prof[:, :, 7] + prof[:, :, 8])
                        - 2 * (prof[:, :, 3] * mean["vx"] + prof[:, :, 4] * mean["vy"] + prof[:, :, 5] * mean["vz"])
                        + (mean["vx"] ** 2 + mean["vy"] ** 2 + mean["vz"] ** 2)) / 3.0
        n_bin = w / len(prof)  # mean count per bin
        dens = n_bin / bin_volume
        # ave/chunk averages per atom (norm all): the bin's stress sums the per-atom virials (stress*volume units)
        p_kin = {k: dens * t for k, t in (("xx", txx), ("yy", tyy), ("zz", tzz), ("xy", txy))}
        p_vir = {k: -n_bin * mean[s] / bin_volume for k, s in (("xx", "s1"), ("yy", "s2"), ("zz", "s3"), ("xy", "s4"))}
    occupied = n_bin > 0
    y = 0.5 * (edges[:-1] + edges[1:])
    wall_phi = np.array([slab_volume(np.array([-h / 2, h / 2]), lo, hi).sum() * run.cells_x * run.rows_z / bin_volume
                         for lo, hi in itertools.pairwise(edges)])
    centre_count = np.array([((centres_fine >= lo) & (centres_fine < hi)) for lo, hi in itertools.pairwise(edges)], float)
    phi_centre = (fine[:, :, 2].mean(axis=0) @ centre_count.T) * (math.pi / 6.0) / bin_volume
    rows = []
    for i in range(len(y)):
        occ = bool(occupied[i])
        rows.append({
            "y": y[i], "phi": float(phi_blocks[:, i].mean()), "ux": float(mean["vx"][i]) if occ else 0.0,
            "theta": float(theta[i]) if occ else 0.0, "phi_sem": float(_sem(phi_blocks[:, i:i + 1])[0]),
            "ux_sem": float(_sem(ux_blocks[:, i:i + 1])[0]) if occ else 0.0,
            "theta_sem": float(_sem(theta_blocks[:, i:i + 1])[0]) if occ else 0.0, "phi_centre": float(phi_centre[i]),
            "phi_wall": float(wall_phi[i]), "uy": float(mean["vy"][i]) if occ else 0.0, "uz": float(mean["vz"][i]) if occ else 0.0,
            "Txx": float(txx[i]) if occ else 0.0, "Tyy": float(tyy[i]) if occ else 0.0, "Tzz": float(tzz[i]) if occ else 0.0,
            "Txy": float(txy[i]) if occ else 0.0, "ncount": float(n_bin[i]),
            "tau_xy": float(-(p_kin["xy"][i] + p_vir["xy"][i])) if occ else 0.0,
            **{f"p_{k}": float(p_kin[k][i] + p_vir[k][i]) if occ else 0.0 for k in ("xx", "yy", "zz")},
        })
    rows = [{k: (0.0 if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()} for r in rows]
    fb_x, ft_x, fb_y, ft_y = walls[:, 1], walls[:, 2], walls[:, 3], walls[:, 4]
    tau_b = 0.5 * (fb_x - ft_x) / area
    p_b = 0.5 * (ft_y - fb_y) / area
    tau, dtau = float(tau_b.mean()), float(_sem(tau_b[:, None])[0])
    p, dp = float(p_b.mean()), float(_sem(p_b[:, None])[0])
    return {"rows": rows, "tau": tau, "dtau": dtau, "p_yy": p, "dp_yy": dp, "blocks": len(prof)}


def run_couette(run: CouetteRun, root: Path, *, lammps: Lammps | None = None) -> dict:
    """Run (or read back) one Couette cell in ``root/<case>/seed<k>``."""
    where = Path(root) / run.key / f"seed{run.seed}"
    done = where / "result.json"
    if done.is_file():
        try:
            res = json.loads(done.read_text())
            if res.get("digest") == run.digest():
                return res
        except (OSError, ValueError):
            pass
    check_couette(run)
    lammps = lammps or find_lammps()
    rest = calibrate_restitution(run.e, run.steps_per_contact, lammps=lammps) if run.e < 1 else None
    e_model = rest.e_model if rest else 1.0
    bottom, top, flow = _positions(run)
    where.mkdir(parents=True, exist_ok=True)
    for stale in ("profile.txt", "fine.txt", "walls.txt", "log.lammps"):
        (where / stale).unlink(missing_ok=True)
    (where / "couette.data").write_text(_data_file(run, bottom, top, flow))
    script, info = _script(run, e_model)
    (where / "in.couette").write_text(script)
    w0 = time.perf_counter()
    lammps.run(where / "in.couette", where)
    res = _analyse(run, where, info)
    res.update(digest=run.digest(), run=asdict(run), lammps_version=lammps.version, e_model=e_model, N=len(flow),
               wall_spheres=len(bottom), wall_seconds=time.perf_counter() - w0, **info)
    done.write_text(json.dumps(res, indent=1))
    return res


def csv_text(run: CouetteRun, res: dict) -> str:
    """The Couette file: the shared format's header (the fields ``ktgf calibrate`` reads) and the profile."""
    rows = res["rows"]
    occ = [r for r in rows if r["ncount"] > 0.5 and r["theta"] > 0]
    lo, hi = occ[0], occ[-1]
    u = run.speed / 2.0
    head = [
        (f"# DEM (LAMMPS {res['lammps_version']}, run by `ktgf dem couette`) planar Couette flow of "
        f"{'frictionless' if run.mu == 0 else 'frictional'} inelastic spheres between bumpy walls"),
        f"# case: ktgf_e{run.e:g}_phi{run.phi:.2f}_mu{run.mu:g}",
        "# units: d = 1 (sphere diameter), m = 1 (sphere mass), rho_s = 6/pi; velocities in the same units as U",
        f"# e (particle-particle = particle-wall normal restitution): {run.e:g} ; tangential friction: {run.mu:g}"
        + (" (smooth)" if run.mu == 0 else ""),
        (f"# geometry: periodic x (flow, Lx = {run.cells_x:g}) and z (vorticity, Lz = {run.lz:.6f}); walls = one hexagonal close-packed "
        f"layer of {res['wall_spheres']} touching spheres each (d = 1, rows along x), centres at y = -+{run.height / 2:g}; "
        f"H = {run.height:g} (wall-centre to wall-centre)"),
        (f"# N flowing spheres: {res['N']} ; mean solid fraction {run.phi:.4f} defined as N*pi/6/(Lx*Lz*(H-d)) "
        "(slab between planes tangent to wall-sphere tops)"),
        f"# walls move rigidly at u_x = -U/2 (bottom) and +U/2 (top), U = {run.speed:g} ; nominal shear rate U/H = {run.speed / run.height:g}",
        (f"# contact: linear spring-dashpot, kn = {res['kn']:.6g}, gamma_n = {res['gamma_n']:.6g} (e_model = {res['e_model']:.6g}), "
        f"kt = 2/7 kn, mu = {run.mu:g} (pp); 2kn, 2 m_eff gamma_n (particle-wall, wall = infinite mass); t_c = {run.contact_time:g} ; "
        f"dt = t_c/{run.steps_per_contact:g} = {res['dt']:.4g}"),
        f"# protocol: {run.skip:g} strain units (U t/H) discarded, then {run.strain - run.skip:g} averaged in {res['blocks']} blocks of {BLOCK_STRAIN:g}",
        (f"# wall shear stress tau = {res['tau']:.5g} +- {res['dtau']:.2g} ; wall normal stress p_yy = {res['p_yy']:.5g} +- {res['dp_yy']:.2g} ; "
        f"tau/p = {res['tau'] / res['p_yy']:.4f} ; I = (U/H) d / sqrt(p/rho_s) = {run.speed / run.height / math.sqrt(res['p_yy'] / RHO_S):.4f}"),
        f"# slip: first occupied bin bottom y={lo['y']:g} ux={lo['ux']:.5g} (wall {-u:g}), top y={hi['y']:g} ux={hi['ux']:.5g} (wall {u:g})",
        ("# columns: y = bin centre (bins of 0.5); phi = volume-based solid fraction of flowing spheres (exact sphere/slab intersection "
        "from 0.05-wide centre histograms); ux = mean velocity (centre-in-bin); theta = (1/3)<|v-u|^2> with u the time-averaged bin mean (per unit mass)"),
        ("# extra columns: *_sem = standard error from block means; phi_centre = centre-count based; phi_wall = solid fraction of the wall "
        "spheres themselves; Txx,Tyy,Tzz,Txy = <c_i c_j>; ncount = mean number of sphere centres in the bin; tau_xy,p_xx,p_yy,p_zz = stress "
        "profile (kinetic from velocity moments + per-atom virial, half of each contact's virial assigned to each partner)"),
    ]
    body = [",".join(COLUMNS)] + [",".join(f"{r[k]:.6g}" for k in COLUMNS) for r in rows]
    return "\n".join(head + body) + "\n"
