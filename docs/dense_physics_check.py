"""Reproduce the measured tables of docs/dense_physics.md (comparisons only: nothing here is fitted).

Run from the repository root:  python docs/dense_physics_check.py [DATA_DIR]   (default: the data shipped with ktgf)

1. The contact value χ that each DEM uniform-shear point implies, χ_DEM = (p/(nT) − 1)/(2(1 + e)φ)
   (the Enskog/RET equation of state p/(nT) = 1 + 2(1 + e)φχ, model.md §3), against RDFs with their
   published constants.
2. Uniform shear of RET with the Chialvo–Sundaresan RDF (published a = 0.58, exponent 1.5, φ_c = 0.64;
   no parameter fitted) and of the registered `dense`, against the frictionless DEM (e = 0.9).
3. The jamming laws φ_J(μ) at the shared friction coefficient μ = 0.5 with their default μ scales,
   and the μ scale each would need for φ_J(0.5) = 0.58 (mu_scale_for), beside the densest flowing DEM
   state at μ = 0.5 (φ = 0.57).
4. Jenkins & Zhang's closed form (as coded in SedFoam) against ktgf's Walton average: friction loss
   e − e_eff, excess dissipation and T_rot/T.
5. The three EKT correlation lengths L/d stored in SedFoam's history (re-typed, d = 1) beside ktgf's
   `jenkins-berzi-2010` at c = 1, at the frictionless DEM states with the CS13 RDF.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

from ktgf import get_model
from ktgf.closures.dissipation import CorrelationLength
from ktgf.closures.friction.collisions import WaltonRestitution
from ktgf.closures.friction.jamming import JammingFraction
from ktgf.closures.friction.jenkins_zhang import JenkinsZhangRestitution
from ktgf.closures.jamming import CoordinationJamming, mu_scale_for
from ktgf.closures.rdf import CarnahanStarling, ChialvoSundaresan, Torquato
from ktgf.data import shipped_data_dir, uniform_shear_records
from ktgf.shear.steady import steady_shear

data = Path(sys.argv[1]) if len(sys.argv) > 1 else shipped_data_dir()
COLS = ["phi", "e", "T", "eta_over_eta0", "p_over_nT"]
smooth = np.sort(np.concatenate([uniform_shear_records(data / name)[COLS] for name in
                                 ("dem_uniform_shear.csv", "dem_uniform_shear_extra.csv")]), order="phi")
rough = np.concatenate([uniform_shear_records(data / name, where={"mu": 0.5}) for name in
                        ("dem_uniform_shear_friction.csv", "dem_uniform_shear_friction_extra.csv")])
rough = np.sort(rough, order="phi")


def implied_chi(rows: np.ndarray) -> np.ndarray:
    return (rows["p_over_nT"] - 1.0) / (2.0 * (1.0 + rows["e"]) * rows["phi"])


print("### χ implied by the DEM equation of state, against RDFs with published constants\n")
rdfs = [("CS", CarnahanStarling()), ("Torquato φ_c 0.64", Torquato()), ("CS13 φ_c 0.64", ChialvoSundaresan()),
        ("CS13 φ_c 0.634", ChialvoSundaresan(phi_c=0.634)), ("`dense` (β 4.052)", get_model("dense").rdf)]
print("| μ | φ | e | χ_DEM | " + " | ".join(name for name, _ in rdfs) + " |")
print("|---|---|---|---|" + "---|" * len(rdfs))
for mu, rows in ((0.0, smooth), (0.5, rough)):
    chi = implied_chi(rows)
    for i, r in enumerate(rows):
        cells = [f"{float(rdf.chi(r['phi'])):.2f}" if r["phi"] < rdf.phi_max else "—" for _, rdf in rdfs]
        print(f"| {mu:g} | {r['phi']:g} | {r['e']:g} | {chi[i]:.2f} | " + " | ".join(cells) + " |")

print("\n### Uniform shear against the frictionless DEM (e = 0.9): relative errors\n")
ret_cs13 = dataclasses.replace(get_model("ret"), rdf=ChialvoSundaresan())
ret_cs13_ekt = dataclasses.replace(ret_cs13, dissipation=CorrelationLength())  # c = 1, the registry's default
models = [("RET + CS13 RDF (published constants)", ret_cs13),
          ("RET + CS13 RDF + EKT `jenkins-berzi-2010` (c = 1, default)", ret_cs13_ekt),
          ("`dense`", get_model("dense")), ("`proposed` (β 1.75)", get_model("proposed"))]
print("| model | φ | err p/(nT) | err η* | err T | err τ/p | L/d |")
print("|---|---|---|---|---|---|---|")
for name, model in models:
    ok = smooth["phi"] < model.phi_max
    s = steady_shear(model, smooth["phi"][ok], smooth["e"][ok])
    # DEM τ/p from its columns (γ̇ = d = m = 1): τ = η0 (η/η0), η0 = (5/16)√(T/π); p = (p/(nT)) n T, n = 6φ/π
    dem_ratio = (smooth["eta_over_eta0"] * 5.0 / 16.0 * np.sqrt(smooth["T"] / np.pi)
                 / (smooth["p_over_nT"] * 6.0 * smooth["phi"] / np.pi * smooth["T"]))
    for i, r in enumerate(smooth[ok]):
        pick = [float(np.broadcast_to(m, s.phi.shape)[i]) for m in (s.p_over_nT, s.eta_over_eta0, s.T, s.tau_over_p)]
        errs = [x / r[c] - 1.0 for x, c in zip(pick[:3], ("p_over_nT", "eta_over_eta0", "T"))]
        errs.append(pick[3] / dem_ratio[ok][i] - 1.0)
        length = float(np.broadcast_to(s.L_over_d, s.phi.shape)[i])
        print(f"| {name} | {r['phi']:g} | " + " | ".join(f"{100 * x:+.0f} %" for x in errs) + f" | {length:.2f} |")

print("\n### φ_J(μ = 0.5) of the jamming laws; the densest flowing DEM state at μ = 0.5 has φ = "
      f"{rough['phi'].max():g}\n")
print("| law | φ_J(0) | φ_J(0.5), default μ scale | μ scale for φ_J(0.5) = 0.58 |")
print("|---|---|---|---|")
for law in (JammingFraction(), CoordinationJamming()):
    print(f"| {law.describe()} | {float(law.phi_c(0.0)):.4f} | {float(law.phi_c(0.5)):.4f} | "
          f"{mu_scale_for(law, 0.5, 0.58):.3f} |")

print("\n### Jenkins–Zhang (SedFoam's code) against ktgf's Walton average: relative differences W/JZ − 1\n")
print("| e | μ | β0 | e − e_eff (JZ) | friction loss | excess dissipation | T_rot/T (JZ) | T_rot/T (W) |")
print("|---|---|---|---|---|---|---|---|")
jz = JenkinsZhangRestitution()
for e, mu, beta0 in ((0.9999, 0.001, 0.0), (0.9999, 0.003, 0.0), (0.9999, 0.001, 1.0), (0.9, 0.01, 0.0),
                     (0.7, 0.01, 0.0), (0.7, 0.5, 1.0), (0.99, 1.0, 0.0)):
    walton = WaltonRestitution(beta0=max(beta0, 1e-12))
    loss_jz, loss_w = e - float(jz.effective_restitution(e, mu)), e - float(walton.effective_restitution(e, mu))
    excess_jz, excess_w = float(jz.inelasticity(e, mu)) - (1 - e**2), float(walton.inelasticity(e, mu)) - (1 - e**2)
    r_jz, r_w = float(jz.rotational_ratio(e, mu)), float(walton.rotational_ratio(e, mu))
    print(f"| {e:g} | {mu:g} | {beta0:g} | {loss_jz:.5g} | {100 * (loss_w / loss_jz - 1):+.2f} % | "
          f"{100 * (excess_w / excess_jz - 1):+.2f} % | {r_jz:.4g} | {r_w:.4g} |")


def sedfoam_lengths(phi: np.ndarray, e: float, g0: np.ndarray) -> list[np.ndarray]:
    """L/d of SedFoam's `extended_` branch in three stored versions (kineticTheoryModel.C), re-typed, d = 1."""
    sqrt_pi = np.sqrt(np.pi)
    first = np.maximum(1.0, 0.5 * (30.0 / (1.0 + np.pi / 12.0) * (1 - e) * phi**2 * g0) ** (1 / 3))
    f2 = (4.0 / 5.0 * phi**2 * g0 * (1 + e) / sqrt_pi + sqrt_pi * g0 * (1 + e) * (3 * e - 1) * phi**2 / (15 * (3 - e))
          + phi * sqrt_pi / (6 * (3 - e)))
    f3 = 12.0 / sqrt_pi * (1 - e**2) * phi**2 * g0
    second = np.maximum(1.0, (f3 / f2) ** (1 / 3) * (0.25 * (phi * g0) ** (1 / 3)) ** (2 / 3))
    third = np.maximum(1.0, 0.5 * (30 * phi**2 * (1 - e) / (1 - np.pi * (1 + e) * (1 - 3 * e)
                                                             / (1 - 0.25 * (1 - e) ** 2 - 5.0 / 24 * (1 - e**2))))
                       ** (1 / 3) * (phi * g0) ** (2 / 9))
    return [first, second, third]


print("\n### EKT L/d at the frictionless DEM states (e = 0.9, CS13 RDF): SedFoam's three stored forms and ktgf's\n")
dense_rows = smooth[smooth["phi"] >= 0.5]
g0 = ChialvoSundaresan().chi(dense_rows["phi"])
forms = sedfoam_lengths(dense_rows["phi"], 0.9, g0)
ktgf_length = np.broadcast_to(steady_shear(ret_cs13_ekt, dense_rows["phi"], dense_rows["e"]).L_over_d, dense_rows.shape)
print("| φ | SedFoam, earlier | SedFoam, f3/f2 form | SedFoam, commit 079bc886 | ktgf `jenkins-berzi-2010`, c = 1 |")
print("|---|---|---|---|---|")
for i, r in enumerate(dense_rows):
    print(f"| {r['phi']:g} | {forms[0][i]:.2f} | {forms[1][i]:.2f} | {forms[2][i]:.2f} | {ktgf_length[i]:.2f} |")
