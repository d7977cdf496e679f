"""Reproduce the table of docs/uniform_shear_stability.md: growth rates of uniform shear, k_x = 0.

Run from the repository root:  python docs/shear_stability_table.py
All rates in units of the shear rate γ̇ (they do not depend on γ̇, d or ρ_s), e = 0.9.
"""

from __future__ import annotations

import numpy as np

from ktgf.closures import list_models
from ktgf.shear import shear_modes

D, GDOT, RHO_S, E = 1e-3, 100.0, 2500.0, 0.9
kd = np.geomspace(1e-3, 1.0, 400)


def largest(phi, model, ky, kz):
    return shear_modes(model, phi, E, GDOT, ky, kz, d=D, rho_s=RHO_S).growth_rates[..., 0].real / GDOT


def unstable_box(s):
    """Smallest periodic side L/d = 2π/(kd) whose lowest mode grows (inf: none grows)."""
    grow = kd[s > 1e-12]
    return f"{2 * np.pi / grow.max():.0f}" if grow.size else "stable"


print("| model | φ | ζ0/γ̇ | c_layer = σ/(γ̇(kd)²), kd → 0 | max σ/γ̇, k ∥ y (at kd) | L/d above which k ∥ y grows "
      "| max σ/γ̇, k ∥ z (at kd) | L/d above which k ∥ z grows |")
print("|---|---|---|---|---|---|---|---|")
for m in list_models():
    for phi in (0.1, 0.3, 0.5):
        small = shear_modes(m, phi, E, GDOT, 1e-4 / D, 0.0, d=D, rho_s=RHO_S)
        s0 = small.growth_rates / GDOT
        slow = s0[(np.abs(s0.imag) < 1e-12) & (np.abs(s0) > 0)]
        c_layer = slow[np.argmin(np.abs(slow))].real / 1e-4**2
        sy, sz = largest(phi, m, kd / D, 0.0), largest(phi, m, 0.0, kd / D)
        iy, iz = np.argmax(sy), np.argmax(sz)
        print(f"| {m.name} | {phi} | {small.base.c.zeta0 / GDOT:.4f} | {c_layer:.4g} | {sy[iy]:.3g} ({kd[iy]:.3g}) | "
              f"{unstable_box(sy)} | {sz[iz]:.3g} ({kd[iz]:.3g}) | {unstable_box(sz)} |")
