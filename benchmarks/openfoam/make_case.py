"""Write an OpenFOAM (v1912, openfoam.com) twoPhaseEulerFoam case equivalent to a ktgf 3D cooling box.

    PYTHONPATH=src python benchmarks/openfoam/make_case.py benchmarks/openfoam/cooling_box.toml CASE_DIR

The granular phase: a periodic (cyclic) cube of N³ cells, solid fraction φ, restitution e,
particle diameter and density, and the *same* initial fields as the ktgf run (ktgf's seeded
perturbation, :func:`ktgf.solver.run.Simulation.initial_state`, written cell by cell).
kineticTheory closures chosen to be those of ktgf's ``enskog`` model (Lun et al. 1984 with the
Carnahan–Starling g0) as far as OpenFOAM has them — see :data:`GRANULAR` and docs/openfoam.md.

twoPhaseEulerFoam has no single-phase granular gas: a continuous phase must fill the voids.
It is made as light and as inviscid as the solver tolerates (:data:`GAS`), with the weakest drag
it offers, so that the gas neither carries momentum nor dissipates granular energy (drag
dissipation J1 = 3K Θ against collisional dissipation; the ratio is printed by
:func:`gas_effect`). Gravity is zero. Every dictionary is written here (no tutorial files copied).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

#: kineticTheory model choices (OpenFOAM names) nearest to ktgf's ``enskog`` model.
GRANULAR = {
    "radialModel": "CarnahanStarling",  # g0 = (1 - φ/2)/(1 - φ)³: the same as ktgf's carnahan-starling
    "granularPressureModel": "Lun",  # p = ρ_s φ Θ (1 + 2(1 + e) φ g0): Enskog's (Lun et al. 1984)
    "viscosityModel": "Gidaspow",  # Gidaspow (1994) form of the Enskog viscosity: differs from Lun's by O(1 - e)
    "conductivityModel": "Gidaspow",  # likewise; no mass-flux (μ ∇φ) term, which Lun's theory has neither
    "frictionalStressModel": "Schaeffer",  # zero below alphaMinFriction, which is set above any φ reached
}

#: The continuous phase: an isothermal ideal gas (air's molar mass, 300 K, 1 bar: ρ = 1.16 kg/m³)
#: with μ = 1e-9 Pa s (air: 1.8e-5) and Schiller–Naumann drag.  Constant-density gases
#: (ρ = 0.01 and 1.2 kg/m³) made the pressure solver diverge (docs/openfoam.md).
GAS = {"molWeight": 28.9, "T": 300.0, "p": 1e5, "mu": 1e-9, "drag": "SchillerNaumann"}


#: Cp [J/(kg K)] of both phases: so large that the energy equations twoPhaseEulerFoam always solves
#: leave T constant (with real values the p·∂α/∂t work of the light gas drove T.air negative).
HEAT_CAPACITY = 1e10


def _header(cls: str, obj: str, location: str) -> str:
    return ("FoamFile\n{\n    version     2.0;\n    format      ascii;\n"
            f"    class       {cls};\n    location    \"{location}\";\n    object      {obj};\n}}\n\n")


def _hdr(rel: str, cls: str = "dictionary") -> str:
    """Header of the file at ``rel`` (e.g. ``constant/g``): object and location from the path."""
    location, obj = rel.split("/")
    return _header(cls, obj, location)


def _dict(body: dict[str, Any], indent: int = 0) -> str:
    """OpenFOAM dictionary text of a nested dict (values: str, number, dict, or raw text)."""
    pad = " " * indent
    out = []
    for key, val in body.items():
        if isinstance(val, dict):
            out.append(f"{pad}{key}\n{pad}{{\n{_dict(val, indent + 4)}{pad}}}\n")
        else:
            out.append(f"{pad}{key:<16} {_fmt(val)};\n")
    return "".join(out)


def _fmt(v: Any) -> str:
    if isinstance(v, bool):
        return "on" if v else "off"
    if isinstance(v, float):
        return f"{v:.10g}"
    return str(v)


_PATCHES = ("x0", "x1", "y0", "y1", "z0", "z1")


def _cyclic_boundary() -> str:
    return "".join(f"    {p}\n    {{\n        type            cyclic;\n    }}\n" for p in _PATCHES)


def _field(name: str, cls: str, values: np.ndarray | float | tuple, dims: str) -> str:
    """A volScalarField / volVectorField with cyclic patches; values uniform or one per cell (x fastest)."""
    if isinstance(values, np.ndarray):
        vals = values.reshape(-1, values.shape[-1]) if values.ndim > 1 else values
        if cls == "volVectorField":
            rows = "\n".join(f"({a:.10g} {b:.10g} {c:.10g})" for a, b, c in vals)
            internal = f"nonuniform List<vector>\n{len(vals)}\n(\n{rows}\n)"
        else:
            rows = "\n".join(f"{a:.10g}" for a in vals)
            internal = f"nonuniform List<scalar>\n{len(vals)}\n(\n{rows}\n)"
    elif isinstance(values, tuple):
        internal = "uniform (" + " ".join(f"{v:.10g}" for v in values) + ")"
    else:
        internal = f"uniform {values:.10g}"
    return (_header(cls, name, "0") + f"dimensions      {dims};\n\ninternalField   {internal};\n\n"
            "boundaryField\n{\n" + _cyclic_boundary() + "}\n")


def case_parameters(cfg: Any) -> dict[str, Any]:
    """Everything the case needs from a validated ktgf config: box, cells, φ, e, d, ρ_s, θ0, end time [s],
    and ktgf's acoustic step limit cfl·Δx/(3c) of the uniform initial state (c: granular sound speed)."""
    import jax.numpy as jnp

    from ktgf.errors import InputError
    from ktgf.solver.run import Simulation

    cells = cfg.grid.cells
    if cfg.case.kind != "cooling" or len(cells) != 3 or len(set(cells)) != 1:
        raise InputError(f"make_case: field grid.cells = {cells}, case.kind = {cfg.case.kind!r}: "
                         "valid a cooling box with N³ cells (cells = [N, N, N])")
    sim = Simulation(cfg)
    side, n = float(sim.grid.lengths[0]), int(cells[0])
    with sim.precision():
        rho0 = jnp.asarray(cfg.initial.solid_fraction * cfg.particles.density)
        c0 = float(sim.phys.sound_speed(jnp.asarray(sim.theta0), sim.phys.reduced(rho0)))
    return {"sim": sim, "cells": n, "length": side, "phi": cfg.initial.solid_fraction, "e": cfg.model.restitution,
            "d": cfg.particles.diameter, "rho_s": cfg.particles.density, "theta0": float(sim.theta0),
            "t_end": float(sim.output_times[-1]), "t_haff": float(sim.t_haff),
            "output_times": np.asarray(sim.output_times), "sound_speed0": c0,
            "acoustic_dt0": cfg.numerics.cfl * side / n / (3.0 * c0)}


def initial_fields(sim: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ktgf's initial φ, u, θ per cell in OpenFOAM's blockMesh order (x fastest, then y, then z)."""
    from ktgf.solver.state import primitive

    with sim.precision():
        W = np.asarray(primitive(sim.initial_state()), np.float64)  # rho, u_x, u_y, u_z, theta
    rho, u, theta = W[0], W[1:4], W[4]
    phi = rho / sim.phys.material_density
    flat = lambda a: a.reshape(-1, order="F")  # noqa: E731 - (i, j, k) -> i + N (j + N k)
    return flat(phi), np.stack([flat(c) for c in u], axis=-1), flat(theta)


def gas_effect(p: dict[str, Any], gas: dict[str, Any] = GAS) -> dict[str, float]:
    """Order-of-magnitude effect of the gas: drag dissipation 3K (Stokes K = 18 μ φ/d²) over the
    collisional one 12(1 - e²) φ² ρ_s g0 √Θ/(d √π) at θ0, and the gas/solid density ratio."""
    phi, d = p["phi"], p["d"]
    g0 = (1 - phi / 2) / (1 - phi) ** 3
    rho_gas = gas["p"] * gas["molWeight"] * 1e-3 / (8.314462618 * gas["T"])
    drag = 3 * 18 * gas["mu"] * phi / d**2
    coll = 12 * (1 - p["e"] ** 2) * phi**2 * p["rho_s"] * g0 * math.sqrt(p["theta0"]) / (d * math.sqrt(math.pi))
    return {"drag_over_collisional_dissipation": drag / coll, "gas_density": rho_gas,
            "density_ratio": rho_gas / p["rho_s"]}


def write_case(cfg: Any, directory: str | Path, *, max_co: float = 0.2, writes: int | None = None,
               gas: dict[str, Any] = GAS) -> dict[str, Any]:
    """Write the case into ``directory`` (created); returns the parameters used."""
    p = case_parameters(cfg)
    root = Path(directory)
    for sub in ("0", "constant", "system"):
        (root / sub).mkdir(parents=True, exist_ok=True)
    n, L = p["cells"], p["length"]
    files: dict[str, str] = {}
    v = [(0, 0, 0), (L, 0, 0), (L, L, 0), (0, L, 0), (0, 0, L), (L, 0, L), (L, L, L), (0, L, L)]
    faces = {"x0": "(0 4 7 3)", "x1": "(1 2 6 5)", "y0": "(0 1 5 4)", "y1": "(3 7 6 2)",
             "z0": "(0 3 2 1)", "z1": "(4 5 6 7)"}
    boundary = "".join(f"    {name}\n    {{\n        type cyclic;\n"
                       f"        neighbourPatch {name[0]}{1 - int(name[1])};\n        faces ({f});\n    }}\n"
                       for name, f in faces.items())
    files["system/blockMeshDict"] = (
        _header("dictionary", "blockMeshDict", "system") + "scale 1;\n\nvertices\n(\n"
        + "".join(f"    ({a:.12g} {b:.12g} {c:.12g})\n" for a, b, c in v) + ");\n\n"
        f"blocks\n(\n    hex (0 1 2 3 4 5 6 7) ({n} {n} {n}) simpleGrading (1 1 1)\n);\n\nedges ();\n\n"
        f"boundary\n(\n{boundary});\n")
    dt0 = p["acoustic_dt0"]  # OpenFOAM's Courant number ignores the granular sound speed: cap the step
    writes = writes or max(1, len(p["output_times"]) - 1)
    files["system/controlDict"] = _header("dictionary", "controlDict", "system") + _dict({
        "application": "twoPhaseEulerFoam", "startFrom": "startTime", "startTime": 0, "stopAt": "endTime",
        "endTime": p["t_end"], "deltaT": dt0, "writeControl": "adjustableRunTime", "writeInterval": p["t_end"] / writes,
        "purgeWrite": 0, "writeFormat": "ascii", "writePrecision": 8, "writeCompression": "off", "timeFormat": "general",
        "timePrecision": 8, "runTimeModifiable": "off", "adjustTimeStep": "yes", "maxCo": max_co, "maxDeltaT": dt0,
    }) + ("functions\n{\n    thetaMean\n    {\n        type            volFieldValue;\n"
          "        libs            (fieldFunctionObjects);\n        writeControl    timeStep;\n        writeInterval   1;\n"
          "        writeFields     false;\n        regionType      all;\n        operation       weightedVolAverage;\n"
          "        weightField     alpha.particles;\n        fields          (Theta.particles alpha.particles);\n    }\n}\n")
    files["system/fvSchemes"] = _header("dictionary", "fvSchemes", "system") + (
        "ddtSchemes { default Euler; }\n\ngradSchemes { default Gauss linear; }\n\n"
        "divSchemes\n{\n    default none;\n"
        "    \"div\\(phi,alpha.*\\)\" Gauss vanLeer;\n    \"div\\(phir,alpha.*\\)\" Gauss vanLeer;\n"
        "    \"div\\(alphaRhoPhi.*,U.*\\)\" Gauss limitedLinearV 1;\n    \"div\\(phi.*,U.*\\)\" Gauss limitedLinearV 1;\n"
        "    \"div\\(alphaRhoPhi.*,(h|e).*\\)\" Gauss limitedLinear 1;\n    \"div\\(alphaRhoPhi.*,K.*\\)\" Gauss limitedLinear 1;\n"
        "    \"div\\(alphaPhi.*,p\\)\" Gauss limitedLinear 1;\n"
        "    div(alphaRhoPhi.particles,Theta.particles) Gauss limitedLinear 1;\n"
        "    \"div\\(\\(\\(\\(alpha.*thermo:rho.*\\)\\*nuEff.*\\)\\*dev2\\(T\\(grad\\(U.*\\)\\)\\)\\)\\)\" Gauss linear;\n"
        "    \"div\\(\\(\\(\\(thermo:rho.particles\\*nut.particles\\)\\*dev2\\(T\\(grad\\(U.particles\\)\\)\\)\\)"
        "\\+\\(\\(\\(thermo:rho.particles\\*lambda.particles\\)\\*div\\(phi.particles\\)\\)\\*I\\)\\)\\)\" Gauss linear;\n}\n\n"
        "laplacianSchemes { default Gauss linear uncorrected; bounded Gauss linear uncorrected; }\n\n"
        "interpolationSchemes { default linear; }\n\nsnGradSchemes { default uncorrected; bounded uncorrected; }\n")
    smooth = {"solver": "smoothSolver", "smoother": "symGaussSeidel", "relTol": 0, "minIter": 1}
    files["system/fvSolution"] = _header("dictionary", "fvSolution", "system") + _dict({
        "solvers": {
            '"alpha.*"': {"nAlphaCorr": 1, "nAlphaSubCycles": 2, "smoothLimiter": 0.1, "implicitPhasePressure": "yes",
                          **smooth, "tolerance": 1e-9},
            # the pressure residual stalls near 1e-6 (the gas is nearly incompressible at this density):
            # 50 iterations give the same θ(t) to 9 digits as 1000 (measured on 16³), at 1/7 of the time
            "p_rgh": {"solver": "GAMG", "smoother": "GaussSeidel", "tolerance": 1e-6, "relTol": 0.01, "maxIter": 50},
            "p_rghFinal": {"solver": "GAMG", "smoother": "GaussSeidel", "tolerance": 1e-6, "relTol": 0, "maxIter": 50},
            '"U.*"': {**smooth, "tolerance": 1e-8},
            '"(h|e).*"': {**smooth, "tolerance": 1e-6, "maxIter": 2},  # T stays constant (HEAT_CAPACITY)
            '"Theta.*"': {**smooth, "tolerance": 1e-10},
        },
        "PIMPLE": {"nOuterCorrectors": 2, "nCorrectors": 1, "nNonOrthogonalCorrectors": 0, "pRefCell": 0,
                   "pRefValue": gas["p"]},
        "relaxationFactors": {"equations": {'".*"': 1}},
    })
    files["constant/g"] = (_header("uniformDimensionedVectorField", "g", "constant")
                           + "dimensions      [0 1 -2 0 0 0 0];\nvalue           (0 0 0);\n")
    files["constant/phaseProperties"] = _header("dictionary", "phaseProperties", "constant") + (
        "phases (particles air);\n\n"
        f"particles\n{{\n    diameterModel constant;\n    constantCoeffs {{ d {p['d']:.10g}; }}\n"
        "    alphaMax 0.64;\n    residualAlpha 1e-6;\n}\n\n"
        "air\n{\n    diameterModel constant;\n    constantCoeffs { d 1; }\n    residualAlpha 0;\n}\n\n"
        "blending { default { type none; continuousPhase air; } }\n\nsigma ( (particles and air) 0 );\n\n"
        "aspectRatio ();\n\n"
        f"drag\n(\n    (particles in air)\n    {{\n        type {gas['drag']};\n        residualRe 1e-3;\n"
        "        swarmCorrection { type none; }\n    }\n);\n\n"
        "virtualMass ();\n\nheatTransfer\n(\n    (particles in air) { type RanzMarshall; residualAlpha 1e-3; }\n);\n\n"
        "lift ();\n\nwallLubrication ();\n\nturbulentDispersion ();\n\nphaseTransfer ();\n\npMin 1e2;\n")
    files["constant/turbulenceProperties.particles"] = _hdr("constant/turbulenceProperties.particles") + _dict({
        "simulationType": "RAS",
        "RAS": {"RASModel": "kineticTheory", "turbulence": "on", "printCoeffs": "on", "kineticTheoryCoeffs": {
            "equilibrium": "off", "e": p["e"], "alphaMax": 0.64, "alphaMinFriction": 0.63, "residualAlpha": 1e-6,
            **GRANULAR,
            "SchaefferCoeffs": {"phi": 28.5},
        }},
    })
    files["constant/turbulenceProperties.air"] = _hdr("constant/turbulenceProperties.air") + "simulationType laminar;\n"
    for phase in ("particles", "air"):
        solid = phase == "particles"
        eos = {"equationOfState": "rhoConst"} if solid else {"equationOfState": "perfectGas"}
        mixture = {"specie": {"molWeight": 100 if solid else gas["molWeight"]}}
        if solid:
            mixture["equationOfState"] = {"rho": float(p["rho_s"])}
        mixture.update({"thermodynamics": {"Cp": HEAT_CAPACITY, "Hf": 0},
                        "transport": {"mu": 0.0 if solid else float(gas["mu"]), "Pr": 1}})
        rel = f"constant/thermophysicalProperties.{phase}"
        files[rel] = _hdr(rel) + _dict({
            "thermoType": {"type": "heRhoThermo", "mixture": "pureMixture", "transport": "const", "thermo": "hConst",
                           **eos, "specie": "specie", "energy": "sensibleInternalEnergy"},
            "mixture": mixture,
        })
    phi, u, theta = initial_fields(p["sim"])
    files["0/alpha.particles"] = _field("alpha.particles", "volScalarField", phi, "[0 0 0 0 0 0 0]")
    files["0/alpha.air"] = _field("alpha.air", "volScalarField", 1.0 - phi, "[0 0 0 0 0 0 0]")
    files["0/U.particles"] = _field("U.particles", "volVectorField", u, "[0 1 -1 0 0 0 0]")
    # the gas starts with the particles' velocity: no drag transient
    files["0/U.air"] = _field("U.air", "volVectorField", u, "[0 1 -1 0 0 0 0]")
    files["0/Theta.particles"] = _field("Theta.particles", "volScalarField", theta, "[0 2 -2 0 0 0 0]")
    for name, val, dims in (("p", gas["p"], "[1 -1 -2 0 0 0 0]"), ("p_rgh", gas["p"], "[1 -1 -2 0 0 0 0]"),
                            ("T.particles", gas["T"], "[0 0 0 1 0 0 0]"), ("T.air", gas["T"], "[0 0 0 1 0 0 0]"),
                            ("nut.particles", 0.0, "[0 2 -1 0 0 0 0]"), ("nut.air", 0.0, "[0 2 -1 0 0 0 0]"),
                            ("alphat.particles", 0.0, "[1 -1 -1 0 0 0 0]"), ("alphat.air", 0.0, "[1 -1 -1 0 0 0 0]")):
        files[f"0/{name}"] = _field(name, "volScalarField", val, dims)
    for rel, text in files.items():
        (root / rel).write_text(text)
    out = {k: v for k, v in p.items() if k != "sim"}
    out["density_variance0"] = float(np.mean((phi - phi.mean()) ** 2) / phi.mean() ** 2)
    out.update(gas=dict(gas), granular=dict(GRANULAR), max_co=max_co, **gas_effect(p, gas))
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description="write a twoPhaseEulerFoam case equivalent to a ktgf 3D cooling box")
    ap.add_argument("config", help="ktgf TOML config of a 3D cooling box")
    ap.add_argument("directory", help="case directory to write")
    ap.add_argument("--max-co", type=float, default=0.2, help="OpenFOAM maxCo (adjustable time step)")
    args = ap.parse_args(argv)
    import jax

    jax.config.update("jax_enable_x64", True)
    from ktgf.solver.config import load_config

    info = write_case(load_config(args.config), args.directory, max_co=args.max_co)
    print({k: v for k, v in info.items() if k != "output_times"}, file=sys.stderr)


if __name__ == "__main__":
    main()
