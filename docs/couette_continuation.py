"""Solution curves of the DEM Couette cell at e = e_w = 0.7 with Visc.div. (docs/dense.md §5.2).

Run: ``python docs/couette_continuation.py`` (about 20 s); writes
``docs/images/couette_continuation.png`` and prints the folds and the solutions at the ends.

(a) in the mean solid fraction (0.3 → 0.5) at specularity 0.16773, one of the cases on which
natural-parameter continuation stalled: the curve has two folds, so natural continuation
stops at the first one; (b) in the specularity (mean φ 0.5): the unjammed solution of spec 0.245
folds back near spec 0.232 onto a near-jammed branch, and a separate jammed-plug branch runs
across the whole range.  Below the fold the model has no unjammed solution.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ktgf.closures import get_model  # noqa: E402
from ktgf.couette import PlanarCell, Wall, arclength  # noqa: E402
from ktgf.couette.run import JAM_TOLERANCE, Material, build_problem  # noqa: E402
from ktgf.couette.solver import solve  # noqa: E402

N_CELLS = 200
MODEL = get_model("visc-div")


def cell(spec: float, mean_phi: float = 0.5):
    w = Wall(specularity=spec, restitution=0.7)
    return build_problem(MODEL, PlanarCell(19.0, 10.0), w, w, mean_phi, Material(1.0, 6 / math.pi, 0.7), N_CELLS, 1.5)


def curve(family, X0, lam_min=-1.0):
    """Points (λ, max φ, wall shear stress) along the curve from X0; stops at λ = 1 or when it turns back."""
    try:
        _, path = arclength.follow(family, X0, 0.0, 1.0, lam_min=lam_min, max_steps=800)
    except arclength.ArclengthStall as exc:
        print("   ", exc)
        path = exc.path
    rows = []
    for lam, X in zip(path.lam, path.X):
        t = family(lam).terms(X)
        rows.append((lam, float(t["phi"].max()), float(np.mean(t["F"]))))
    return np.array(rows), path


def main() -> None:
    spec = 0.16773
    X03, _ = solve(cell(spec, 0.3))
    mean_phi = lambda lam: 0.3 + 0.2 * lam  # noqa: E731
    a, pa = curve(lambda lam: cell(spec, mean_phi(lam)), X03)
    print(f"(a) spec {spec}: folds at mean phi {[round(mean_phi(f), 4) for f in pa.folds]}; "
          f"{len(pa.lam)} points, {pa.rejected_steps} rejected")

    s_hi, s_lo = 0.245, 0.16
    spec_at = lambda lam: math.exp(math.log(s_hi) + lam * math.log(s_lo / s_hi))  # noqa: E731
    X_hi, _ = solve(cell(s_hi))
    b1, pb1 = curve(lambda lam: cell(spec_at(lam)), X_hi, lam_min=-0.6)
    print(f"(b) from the unjammed solution at spec {s_hi}: folds at spec {[round(spec_at(f), 5) for f in pb1.folds]}")
    X_lo, _ = solve(cell(s_lo))
    spec_up = lambda lam: math.exp(math.log(s_lo) + lam * math.log(0.4 / s_lo))  # noqa: E731
    b2, pb2 = curve(lambda lam: cell(spec_up(lam)), X_lo)
    print(f"    from the solver's solution at spec {s_lo}: folds {pb2.folds}; max phi {b2[0, 1]:.5f} … {b2[-1, 1]:.5f}")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.plot(mean_phi(a[:, 0]), a[:, 1], "-", lw=1.5)
    for f in pa.folds:
        ax1.axvline(mean_phi(f), color="0.6", ls=":", lw=1)
    ax1.axhline(MODEL.phi_max * (1 - JAM_TOLERANCE), color="r", ls="--", lw=1,
                label="jammed-core limit of the validity flag")
    ax1.set_xlabel("mean solid fraction (homotopy parameter)")
    ax1.set_ylabel("max φ")
    ax1.set_title(f"(a) continuation in mean φ, specularity {spec}")
    ax1.legend(loc="lower right", fontsize=8)
    ax2.plot([spec_at(x) for x in b1[:, 0]], b1[:, 1], "-", lw=1.5, label="from the unjammed solution at 0.245")
    ax2.plot([spec_up(x) for x in b2[:, 0]], b2[:, 1], "-", lw=1.5, label="from the solution found at 0.16")
    ax2.axhline(MODEL.phi_max * (1 - JAM_TOLERANCE), color="r", ls="--", lw=1)
    ax2.set_xlim(0.15, 0.35)
    ax2.set_xlabel("specularity φ'")
    ax2.set_ylabel("max φ")
    ax2.set_title("(b) continuation in specularity, mean φ 0.5")
    ax2.legend(loc="lower right", fontsize=8)
    fig.suptitle("DEM Couette cell, e = e_w = 0.7, Visc.div., 200 cells")
    fig.tight_layout()
    out = Path(__file__).parent / "images" / "couette_continuation.png"
    fig.savefig(out, dpi=120)
    print("wrote", out)


if __name__ == "__main__":
    main()
