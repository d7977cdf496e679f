"""Section 4: the 3D homogeneous cooling gas below and above the critical size (model.md §9).

For each model of ``settings.cooling_models`` two periodic cubes are run: one of side
``cooling_below`` × L⊥ (should stay homogeneous and follow Haff's law) and one of side
``cooling_above`` × L∥ (should grow vortices and clusters), with L⊥, L∥ from the closed form
of model.md §8.  At φ = 0.5 (above φ_f = 0.49, where the Proposed RDF departs from RET's) the two
models have different critical sizes; the paper's claim is that the Proposed RDF keeps RET's
ability to predict the instability, so the section compares, box by box, whether each model's
run does what its own linear theory predicts and whether the two models agree.

The section runs the 3D solver (:class:`ktgf.solver.Simulation`) through :func:`report_cooling_run` once per run::

    report_cooling_run(model: ktgf.Model, *, phi: float, e: float, box: float, n_cells: int,
                       t_end: float, seed: int, d: float, rho_s: float, theta0: float) -> xarray.Dataset

(``box`` = side of the cube in the units of ``d``; ``t_end`` in units of the initial collision
time 1/ν0(θ0); uniform φ, θ0 and a small random velocity perturbation from ``seed``), returning

* coordinate ``time`` (units of 1/ν0(θ0)) with ``theta_mean`` (volume-averaged θ), ``flow_energy``
  (kinetic energy of the mean flow over the thermal energy (3/2)∫ρθ) and ``phi_std``
  (standard deviation of φ over the cells divided by the mean φ);
* coordinates ``x``, ``y`` (units of d) with ``phi_slice``, ``ux_slice``, ``uy_slice``: the
  fields in the mid-plane z = box/2 at the final time;
* attrs from :func:`ktgf.io.run_metadata`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from ..closures.models import get_model
from ..hcs.haff import haff_temperature
from ..hcs.stability import critical_box_size, critical_wavenumbers
from ..plotting.cooling_gas import plot_slices, plot_time_series
from .framework import Section, SectionContext, model_inputs, register_section
from .settings import ReportSettings

#: Growth of the density contrast above which the page says that clusters formed.
CLUSTER_GROWTH = 2.0
RHO_S_DEM = 6.0 / math.pi



def run_box(model: Any, box: float, s: ReportSettings) -> xr.Dataset:
    """One 3D cooling run."""
    return report_cooling_run(model, phi=s.cooling_phi, e=s.cooling_e, box=box, n_cells=s.cooling_cells, t_end=s.cooling_t_end,
              seed=s.cooling_seed, d=1.0, rho_s=RHO_S_DEM, theta0=1.0)


def report_cooling_run(model: Any, *, phi: float, e: float, box: float, n_cells: int, t_end: float, seed: int,
                       d: float, rho_s: float, theta0: float, outputs: int = 60) -> xr.Dataset:
    """A 3D homogeneous cooling gas in a periodic cube, summarised for the report (this section).

    Parameters
    ----------
    model : Model
        Registered model (rebuilt from its name and options inside the run config).
    phi, e, theta0 : float
        Uniform solid fraction, restitution and initial temperature [m²/s²].
    box : float
        Side of the cube in particle diameters.
    n_cells : int
        Cells per side.
    t_end : float
        End time in units of the initial collision time 1/ν0(θ0).
    seed : int
        Seed of the small random initial velocity field.

    Returns
    -------
    xarray.Dataset
        ``time`` (units 1/ν0(θ0)) with ``theta_mean``, ``flow_energy`` (mean-flow kinetic energy over
        the thermal energy (3/2)θ), ``phi_std`` (std of φ over mean φ); ``x``, ``y`` (units of d) with
        the mid-plane fields ``phi_slice``, ``ux_slice``, ``uy_slice`` at the final time.
    """
    from ..closures.coefficients import nu0
    from ..solver.config import parse_config
    from ..solver.run import Simulation  # JAX is imported only when the section runs
    from ..solver.state import primitive

    collision_time = 1.0 / float(nu0(phi, theta0, d))
    cfg = parse_config({
        "model": {"name": model.name, "restitution": e, "options": model.options()},
        "particles": {"diameter": d, "density": rho_s},
        "initial": {"solid_fraction": phi, "temperature": theta0, "perturbation": "random", "seed": seed},
        "grid": {"cells": [n_cells] * 3, "length_d": box},
        "time": {"end": t_end * collision_time, "unit": "s", "outputs": outputs},
        "output": {"vtk": False, "png": False},
    })
    sim = Simulation(cfg)
    hist = sim.run(progress=False, write_files=False)
    with sim.precision():
        W = np.asarray(primitive(sim.state))
    mid = n_cells // 2
    centres = (np.arange(n_cells) + 0.5) * box / n_cells
    ds = xr.Dataset(
        {
            "theta_mean": ("time", hist["theta_mean"].values),
            "flow_energy": ("time", hist["kinetic_energy"].values / (1.5 * hist["theta_mean"].values)),
            "phi_std": ("time", np.sqrt(hist["density_variance"].values)),
            "phi_slice": (("x", "y"), W[0][:, :, mid] / rho_s),
            "ux_slice": (("x", "y"), W[1][:, :, mid]),
            "uy_slice": (("x", "y"), W[2][:, :, mid]),
        },
        coords={"time": hist["time"].values / collision_time, "x": centres, "y": centres},
        attrs=hist.attrs,
    )
    return ds


def inputs(s: ReportSettings) -> dict[str, Any]:
    return {"models": model_inputs(s.cooling_models), "phi": s.cooling_phi, "e": s.cooling_e, "below": s.cooling_below,
            "above": s.cooling_above, "cells": s.cooling_cells, "t_end": s.cooling_t_end, "seed": s.cooling_seed}


def boxes(name: str, s: ReportSettings) -> dict[str, float]:
    """Box sides [d] of the two runs of a model: below L⊥ and above L∥."""
    kp, kl = critical_wavenumbers(get_model(name).reduced(s.cooling_phi, s.cooling_e))
    return {"below": s.cooling_below * float(critical_box_size(s.cooling_phi, kp)),
            "above": s.cooling_above * float(critical_box_size(s.cooling_phi, kl))}


def run(ctx: SectionContext) -> None:
    s = ctx.settings
    runs: list[tuple[str, str, float, xr.Dataset]] = []
    for name in s.cooling_models:
        m = get_model(name)
        for kind, side in boxes(name, s).items():
            ctx.step(f"3D run {m.label}, L = {side:.1f} d")
            runs.append((name, kind, side, run_box(m, side, s)))
    # Runs share neither grids nor time samples: put them on the first run's time axis and pad slices.
    t = np.asarray(runs[0][3].time, dtype=float)
    nx = max(r[3].sizes["x"] for r in runs)
    series: dict[str, list[np.ndarray]] = {k: [] for k in ("theta_over_haff", "flow_energy", "phi_std")}
    slices: dict[str, list[np.ndarray]] = {k: [] for k in ("phi_slice", "ux_slice", "uy_slice", "x", "y")}
    rows, numbers = [], {}
    for name, kind, side, ds in runs:
        ti = np.asarray(ds.time, dtype=float)
        zeta = float(get_model(name).reduced(s.cooling_phi, s.cooling_e).zeta0)  # ζ0/ν0(θ0): Haff time t0 = 2/ζ0*
        ratio = np.asarray(ds.theta_mean, dtype=float) / (float(ds.theta_mean[0]) * haff_temperature(ti, 1.0, 2.0 / zeta))
        series["theta_over_haff"].append(np.interp(t, ti, ratio, right=np.nan))
        series["flow_energy"].append(np.interp(t, ti, np.asarray(ds.flow_energy, dtype=float), right=np.nan))
        series["phi_std"].append(np.interp(t, ti, np.asarray(ds.phi_std, dtype=float), right=np.nan))
        for k in ("phi_slice", "ux_slice", "uy_slice"):
            a = np.full((nx, nx), np.nan)
            v = np.asarray(ds[k], dtype=float)
            a[: v.shape[0], : v.shape[1]] = v
            slices[k].append(a)
        for k in ("x", "y"):
            a = np.full(nx, np.nan)
            a[: ds.sizes[k]] = np.asarray(ds[k], dtype=float)
            slices[k].append(a)
        label = f"{get_model(name).label}, L = {side:.1f} d " + ("(< L⊥)" if kind == "below" else "(> L∥)")
        haff_dev = float(np.max(np.abs(ratio - 1.0)))
        fe, ps = np.asarray(ds.flow_energy, dtype=float), np.asarray(ds.phi_std, dtype=float)
        # growth of the mean flow from its seeded value; density contrast from its smallest value
        # (the seeded velocity first converts part of its energy into a density transient)
        flow_growth, phi_growth = float(fe[-1] / fe[0]), float(ps[-1] / ps.min())
        rows.append([label, side, float(ps[-1]), phi_growth, float(fe[-1]), flow_growth, 100 * haff_dev])
        numbers[f"{name}/{kind}"] = {"box": side, "phi_std_end": float(ps[-1]), "flow_energy_end": float(fe[-1]),
                                      "flow_growth": flow_growth, "phi_growth": phi_growth, "haff_max_dev": haff_dev}
    labels = [r[0] for r in rows]
    ts = xr.Dataset(
        {k: (("run", "time"), np.array(v)) for k, v in series.items()},
        coords={"run": labels, "time": t},
        attrs={k: str(v) for k, v in runs[0][3].attrs.items()},
    )
    sl = xr.Dataset(
        {k: (("run", "i", "j"), np.array(v)) for k, v in slices.items() if k.endswith("slice")}
        | {"x": (("run", "i"), np.array(slices["x"])), "y": (("run", "j"), np.array(slices["y"]))},
        coords={"run": labels}, attrs=ts.attrs,
    )
    for d in (ts, sl):  # everything is reduced: lengths in d, time in 1/ν0(θ0), velocities in √θ0
        for v in [*d.data_vars, *(c for c in d.coords if d[c].dtype.kind == "f")]:
            d[v].attrs.setdefault("units", "1")
    ts["time"].attrs["long_name"] = "time in units of the initial collision time 1/nu0(theta0)"
    plot_time_series(ts, ctx.figure_path("cooling_time_series"))
    ctx.add_figure("cooling_time_series", f"3D cooling gas at φ = {s.cooling_phi:g}, e = {s.cooling_e:g}: temperature relative to Haff's law, "
                   "energy of the mean flow and density contrast against time.", ts)
    plot_slices(sl, ctx.figure_path("cooling_slices"))
    ctx.add_figure("cooling_slices", slices_caption(sl, numbers), sl)
    ctx.table("3D cooling runs", ["run", "L/d", "final std(φ)/φ", "growth of std(φ)/φ from its minimum",
                                  "final flow/thermal energy", "growth of flow/thermal energy", "max |θ/θ_Haff − 1| %"], rows)
    same = identical_runs(numbers)
    if same:
        ctx.paragraph(same)
    ctx.number("cooling_runs", numbers)
    ok = verdicts(numbers)
    ctx.table("RET/Proposed comparison (the paper's claim)", ["model", "box", "L/d", "linear theory", "run", "as predicted"],
              [[get_model(k.split('/')[0]).label, f"{s.cooling_below:g}·L⊥" if k.endswith("below") else f"{s.cooling_above:g}·L∥",
                v["box"], "stable" if k.endswith("below") else "unstable",
                "grows" if v["flow_growth"] > 1 else "decays", "yes" if ok[k] else "no"] for k, v in numbers.items()])


def verdicts(runs: dict[str, Any]) -> dict[str, bool]:
    """Per run: did it do what linear theory predicts (mean flow decays below L⊥, grows above L∥)?"""
    out = {}
    for key, v in runs.items():
        kind = key.split("/")[1]
        grows = v.get("flow_growth", float("nan")) > 1.0
        out[key] = grows if kind == "above" else not grows
    return out


def comparison(runs: dict[str, Any]) -> str:
    """The paper's comparison: does the Proposed model predict the instability as RET does?"""
    ok = verdicts(runs)
    kinds = sorted({k.split("/")[1] for k in runs})
    if not {"ret", "proposed"} <= {k.split("/")[0] for k in runs}:
        return ""
    same = all(ok.get(f"ret/{k}") == ok.get(f"proposed/{k}") for k in kinds)
    both = all(ok.get(f"{m}/{k}", False) for m in ("ret", "proposed") for k in kinds)
    if both:
        return ("RET and Proposed both follow their linear theory in every box (homogeneous below L⊥, unstable "
                "above L∥): the Proposed RDF keeps RET's ability to predict the instability, as the paper claims.")
    if same:
        return "RET and Proposed behave alike box by box, but not every run follows its linear theory (see the table)."
    return "RET and Proposed differ box by box (see the table): the paper's claim is not reproduced at these settings."


def slices_caption(sl: xr.Dataset, numbers: dict[str, Any]) -> str:
    """Caption of the slice figure saying what the numbers show (clusters only if the contrast grew)."""
    phi = sl.phi_slice.values
    lo, hi = float(np.nanmin(phi)), float(np.nanmax(phi))
    grow = max((v["phi_growth"] for k, v in numbers.items() if k.endswith("/above")), default=float("nan"))
    head = f"Mid-plane slices at the end of each run: φ spans {lo:.4g}–{hi:.4g}"
    if grow >= CLUSTER_GROWTH:
        return head + f"; in the boxes above L∥ the density contrast grew ×{grow:.3g}, clusters show in φ, vortices in the velocity."
    return (head + f"; the density contrast grew only ×{grow:.3g} in the boxes above L∥ (less than ×{CLUSTER_GROWTH:g}), "
            "so no clusters are visible by this end time; the velocity panels show the vortices' in-plane flow.")


def identical_runs(numbers: dict[str, Any], rtol: float = 1e-6) -> str:
    """A sentence naming models whose runs gave the same numbers (e.g. RET and Proposed below φ_f), or ''."""
    names = list(dict.fromkeys(k.split("/")[0] for k in numbers))
    pairs = []
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            va = [numbers.get(f"{a}/{k}") for k in ("below", "above")]
            vb = [numbers.get(f"{b}/{k}") for k in ("below", "above")]
            if all(x and y and all(abs(x[q] - y[q]) <= rtol * max(abs(x[q]), abs(y[q]), 1e-300) for q in x) for x, y in zip(va, vb)):
                pairs.append(f"{get_model(a).label} and {get_model(b).label}")
    if not pairs:
        return ""
    return ("The runs of " + "; ".join(pairs) + " give identical numbers (to 1e-6): at this φ their closures coincide "
            "(the RDFs and viscosity laws differ only above the freezing point φ_f), so their rows and curves overlap.")


def discuss(nb: dict[str, Any]) -> list[str]:
    out = []
    runs = nb.get("cooling_runs", {})
    for key, v in runs.items():
        name, kind = key.split("/")
        lab = get_model(name).label
        flow = v.get("flow_growth", float("nan"))
        verdict = "grows" if flow > 1 else "decays"
        where = "below L⊥" if kind == "below" else "above L∥"
        out.append(f"{lab}, L = {v['box']:.1f} d ({where}): the mean-flow energy relative to θ {verdict} "
                   f"(×{flow:.3g}); the density contrast ends at {v['phi_std_end']:.2g} "
                   f"(×{v.get('phi_growth', float('nan')):.3g} from its minimum); θ stays within "
                   f"{100 * v['haff_max_dev']:.2g} % of Haff's law.")
    verdict = comparison(runs)
    if verdict:
        out.append(verdict)
    return out


SECTION = register_section(Section(
    "cooling_gas", "4. 3D homogeneous cooling gas", run, inputs, order=40,
    modules=("ktgf.solver",), discuss=discuss,
))
