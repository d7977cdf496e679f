"""The shared DEM file formats (``shared/data/README.md``) written from ktgf's own LAMMPS runs.

``friction`` (default): the columns of ``dem_uniform_shear_friction.csv`` (any μ);
``smooth``: the columns of ``dem_uniform_shear.csv`` (frictionless rows only).  Both carry the
units line the readers check (``d = m = 1``, ``gdot = 1``) and, in the header, the LAMMPS
version, contact parameters, seeds and each state's checks.
"""

from __future__ import annotations

import json
from typing import Any

from ..errors import InputError
from .shear import ShearState

FRICTION_COLUMNS = ("mu", "phi", "e", "N", "seeds", "T", "dT", "Trot_over_T", "dTrot_over_T", "p_star", "dp_star",
                    "tau_star", "dtau_star", "tau_over_p", "dtau_over_p", "p_over_nT", "dp_over_nT",
                    "eta_over_eta0", "deta_over_eta0", "contacts_per_particle")
SMOOTH_COLUMNS = ("phi", "e", "N", "seeds", "T", "dT", "eta_star", "deta_star", "eta_over_eta0", "deta_over_eta0",
                  "p_over_nT", "dp_over_nT", "astar")

_FRICTION_HEADER = """\
# Uniform (Lees-Edwards) shear of FRICTIONAL inelastic spheres, LAMMPS DEM run by `ktgf dem shear` ({version})
# units d = m = 1, rho_s = 6/pi; shear rate gdot = 1; T = m<c^2>/3 (translational, peculiar velocity); Trot = rotational temperature I<w'^2>/3 (sphere I = m d^2/10)
# p = tr(P)/3 (kinetic + contact), tau = -P_xy; p_star = p/(rho_s d^2 gdot^2), tau_star likewise; tau_over_p = tau/p; eta0 = (5/16) sqrt(m T/pi); d* = standard error over seeds/blocks
# contact: linear spring-dashpot normal (restitution e, calibrated), linear tangential spring with history, Coulomb friction coefficient mu; contacts_per_particle = mean contacts per sphere"""
_SMOOTH_HEADER = """\
# Uniform (Lees-Edwards) shear of frictionless inelastic spheres, LAMMPS DEM run by `ktgf dem shear` ({version})
# units d = m = 1; shear rate gdot = 1; T = m<c^2>/3 (peculiar velocity); eta = -P_xy/gdot; eta0 = (5/16) sqrt(m T/pi)
# eta_star = eta d^2/sqrt(m T); p_over_nT with p = tr(P)/3; astar = gdot/nu0, nu0 = (16/5) sqrt(pi) n sqrt(T); d* = uncertainty"""


def rows(states: list[ShearState], columns: str = "friction") -> list[dict[str, Any]]:
    """One dict per state in the chosen file's columns."""
    if columns == "smooth" and any(s.mu != 0 for s in states):
        raise InputError("--columns smooth is the frictionless file's format: valid only when every mu = 0 (use --columns friction)")
    names = SMOOTH_COLUMNS if columns == "smooth" else FRICTION_COLUMNS
    out = []
    for s in states:
        v, d = s.values, s.errors
        full = {"mu": s.mu, "phi": s.phi, "e": s.e, "N": s.N, "seeds": len(s.seeds)}
        for k in ("T", "Trot_over_T", "p_star", "tau_star", "tau_over_p", "p_over_nT", "eta_over_eta0", "eta_star"):
            full[k], full["d" + k] = v[k], d[k]
        full["contacts_per_particle"] = v["contacts_per_particle"]
        full["astar"] = v["astar"]
        out.append({k: full[k] for k in names})
    return out


def header_lines(states: list[ShearState]) -> list[str]:
    """Per-state provenance: seeds, protocol, contact parameters, checks."""
    out = []
    for s in states:
        c, k = s.checks, s.contact
        out.append(f"# state mu={s.mu:g} phi={s.phi:g} e={s.e:g} N={s.N}: seeds {','.join(map(str, s.seeds))}; "
                   f"strain {k['skip']:g}-{k['strain']:g} averaged in blocks of 1; kn={k['kn']:.6g} kt={k['kt']:.6g} "
                   f"gamma_n={k['gamma_n']:.6g} (e_model={k['e_model']:.6g}, two-body e error {k['restitution_two_body_error']:.1e}) "
                   f"t_c={k['t_c']:.4g} dt=t_c/{k['steps_per_contact']:g} f_c={k['contact_fraction']:g} "
                   f"(measured t_c*nu_E={c['contact_fraction_measured']:.4f})")
        out.append(f"#   checks: steady={c['steady']} (halves: T {100 * c['drift_T']:+.1f}% = {c['drift_T_sigma']:+.1f} sigma, "
                   f"p {100 * c['drift_p']:+.1f}% = {c['drift_p_sigma']:+.1f} sigma); Q6 max={c['q6_max']:.3f}; velocity profile "
                   f"slope/gdot {c['profile_slope_min']:.3f}-{c['profile_slope_max']:.3f}, max deviation "
                   f"{100 * c['profile_deviation_max']:.1f}% of gdot L; LAMMPS CPU {c['cpu_seconds']:.0f} s")
    return out


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def csv_text(states: list[ShearState], columns: str = "friction") -> str:
    """The CSV file (header, column titles, rows)."""
    version = states[0].contact["lammps_version"] if states else "no states"
    head = (_SMOOTH_HEADER if columns == "smooth" else _FRICTION_HEADER).format(version=f"LAMMPS {version}")
    table = rows(states, columns)
    names = SMOOTH_COLUMNS if columns == "smooth" else FRICTION_COLUMNS
    body = [",".join(names)] + [",".join(_fmt(r[k]) for k in names) for r in table]
    return "\n".join([head, *header_lines(states), *body]) + "\n"


def json_text(states: list[ShearState]) -> str:
    return json.dumps([{"mu": s.mu, "phi": s.phi, "e": s.e, "N": s.N, "seeds": s.seeds, "values": s.values,
                        "errors": s.errors, "checks": s.checks, "contact": s.contact} for s in states], indent=2, default=float)
