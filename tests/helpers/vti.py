"""Reading back the VTK image files of the solver (:func:`ktgf.solver.io.write_vti`) in the tests."""

from __future__ import annotations

import base64
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np


def read_vti(path: str | Path) -> dict[str, np.ndarray]:
    """Read back the arrays of a .vti file written by :func:`ktgf.solver.io.write_vti` (flat, VTK order)."""
    out = {}
    for da in ET.parse(path).getroot().iter("DataArray"):
        raw = base64.b64decode(da.text.strip())
        n = int(np.frombuffer(raw[:8], dtype="<u8")[0])
        dtype = "<f8" if da.get("type") == "Float64" else "<f4"
        out[da.get("Name")] = np.frombuffer(raw[8 : 8 + n], dtype=dtype)
    return out
