"""Reading LAMMPS output and the checks of a sheared state: blocks, drift, Q6, velocity profile."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np


def read_ave_time(path: Path) -> np.ndarray:
    """The rows of a ``fix ave/time`` file (comment lines start with #) as a float array."""
    rows = [[float(v) for v in ln.split()] for ln in Path(path).read_text().splitlines() if ln.strip() and not ln.startswith("#")]
    return np.array(rows, dtype=float)


def read_ave_chunk(path: Path) -> np.ndarray:
    """The last block of a ``fix ave/chunk`` file: rows (chunk, coordinate, count, values...)."""
    lines = [ln for ln in Path(path).read_text().splitlines() if ln.strip() and not ln.startswith("#")]
    blocks: list[list[list[float]]] = []
    for ln in lines:
        parts = ln.split()
        if len(parts) == 3:  # timestep, number of chunks, total count
            blocks.append([])
        elif blocks:
            blocks[-1].append([float(v) for v in parts])
    return np.array(blocks[-1], dtype=float)


def read_dump_frames(path: Path) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Frames of a custom dump with ``id x y z`` of a (possibly tilted) box: (lo, cell matrix H, positions).

    H has the cell vectors as columns, a = (Lx, 0, 0), b = (xy, Ly, 0), c = (xz, yz, Lz).
    """
    lines = Path(path).read_text().splitlines()
    frames = []
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: NUMBER OF ATOMS"):
            n = int(lines[i + 1])
            head = lines[i + 2]
            b = [[float(v) for v in lines[i + 3 + k].split()] for k in range(3)]
            if "xy" in head:
                xy, xz, yz = b[0][2], b[1][2], b[2][2]
            else:
                xy = xz = yz = 0.0
            xlo = b[0][0] - min(0.0, xy, xz, xy + xz)
            xhi = b[0][1] - max(0.0, xy, xz, xy + xz)
            ylo, yhi = b[1][0] - min(0.0, yz), b[1][1] - max(0.0, yz)
            zlo, zhi = b[2][0], b[2][1]
            H = np.array([[xhi - xlo, xy, xz], [0.0, yhi - ylo, yz], [0.0, 0.0, zhi - zlo]])
            start = i + 7
            table = np.array([[float(v) for v in ln.split()] for ln in lines[start:start + n]])
            table = table[np.argsort(table[:, 0])]
            frames.append((np.array([xlo, ylo, zlo]), H, table[:, 1:4]))
            i = start + n
        else:
            i += 1
    return frames


def q6_global(lo: np.ndarray, H: np.ndarray, x: np.ndarray, cutoff: float = 1.5) -> float:
    """Global bond-orientational order Q6 (Steinhardt, Nelson & Ronchetti, PRB 28, 784 (1983), Eq. (2.5)).

    Q6 = √(4π/13 Σ_m |⟨Y6m(r̂)⟩|²), the average over all bonds shorter than ``cutoff`` (1.5 d: the
    first minimum of g(r) of a dense liquid); ≈ 0.575 for fcc, ≈ N_bonds^(-1/2) for a liquid.
    """
    from scipy.special import sph_harm_y

    s = np.linalg.solve(H, (x - lo).T).T
    i, j = np.triu_indices(len(x), k=1)
    ds = s[i] - s[j]
    ds -= np.round(ds)
    dr = ds @ H.T
    r = np.linalg.norm(dr, axis=1)
    bond = (r < cutoff) & (r > 0)
    if not bond.any():
        return 0.0
    dr, r = dr[bond], r[bond]
    polar = np.arccos(np.clip(dr[:, 2] / r, -1.0, 1.0))
    azimuth = np.arctan2(dr[:, 1], dr[:, 0])
    q = sum(abs(np.mean(sph_harm_y(6, m, polar, azimuth))) ** 2 for m in range(-6, 7))
    return float(math.sqrt(4.0 * math.pi / 13.0 * q))


def profile_linearity(y: np.ndarray, ux: np.ndarray, count: np.ndarray, shear_rate: float, height: float) -> tuple[float, float]:
    """(fitted slope/γ̇, largest deviation from the fitted line over γ̇ L) of a binned velocity profile."""
    keep = count > 0
    slope, icpt = np.polyfit(y[keep], ux[keep], 1)
    dev = np.max(np.abs(ux[keep] - (slope * y[keep] + icpt)))
    return float(slope / shear_rate), float(dev / (shear_rate * height))


def block_means(t: np.ndarray, values: np.ndarray, start: float, stop: float, n_blocks: int) -> np.ndarray:
    """Means of ``values`` (rows at times ``t``) over ``n_blocks`` equal blocks of [start, stop]."""
    edges = np.linspace(start, stop, n_blocks + 1)
    out = []
    for a, b in itertools.pairwise(edges):
        sel = (t > a + 1e-9) & (t <= b + 1e-9)
        out.append(values[sel].mean(axis=0))
    return np.array(out)


def mean_and_error(blocks: np.ndarray) -> tuple[float, float]:
    """Mean of block values and its standard error (blocks taken as independent)."""
    blocks = np.asarray(blocks, dtype=float)
    if blocks.size < 2:
        return float(blocks.mean()), float("nan")
    return float(blocks.mean()), float(blocks.std(ddof=1) / math.sqrt(blocks.size))


def drift(first: np.ndarray, second: np.ndarray) -> tuple[float, float]:
    """(relative change of the mean from the first to the second half of the window, that change in standard errors)."""
    m1, s1 = mean_and_error(first)
    m2, s2 = mean_and_error(second)
    rel = (m2 - m1) / (0.5 * (m1 + m2)) if m1 + m2 != 0 else 0.0
    z = (m2 - m1) / math.hypot(s1, s2) if math.hypot(s1, s2) > 0 else 0.0
    return float(rel), float(z)
