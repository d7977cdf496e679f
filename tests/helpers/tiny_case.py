"""The small 1D solver case (8 cells, RET, e = 0.8) that the reliability tests run, interrupt and resume."""

from __future__ import annotations


def tiny_case(*, end: float = 4.0, time: str = "", output: str = "") -> str:
    """TOML text of the case; ``time`` and ``output`` are extra lines for those tables."""
    return f"""
[model]
name = "ret"
restitution = 0.8
[initial]
solid_fraction = 0.25
temperature = 1e-4
amplitude = 0.05
seed = 2
[grid]
cells = [8]
relative_to = "transverse"
factor = 1.5
[time]
end = {end}
outputs = 4
{time}
[output]
png = false
{output}
"""
