"""Solver output: netCDF time series, checkpoints, VTK image files (.vti) and PNG slices.

The VTK writer is a small XML ImageData writer (VTK file format 1.0, base64 "binary" data
with a UInt64 byte-count header) that ParaView opens directly; fields are cell data.
Every file is written atomically (a unique temporary name, then ``os.replace``), so an
interrupted write never destroys the previous version and two writers never share a file.
Checkpoints are ``.npz`` files with a format version and a SHA-256 of their contents.
"""

from __future__ import annotations

import base64
import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..io import atomic_path
from .grid import Grid

_VTK_TYPES = {np.dtype("float64"): "Float64", np.dtype("float32"): "Float32"}


def _b64(arr: np.ndarray) -> str:
    raw = np.ascontiguousarray(arr).astype(arr.dtype.newbyteorder("<"), copy=False).tobytes()
    return base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")


def write_vti(path: str | Path, grid: Grid, fields: dict[str, np.ndarray], time: float | None = None) -> Path:
    """Write cell fields (scalars of shape ``cells``, vectors of shape ``(3, *cells)``) as a VTK .vti file."""
    path = Path(path)
    cells = tuple(grid.cells) + (1,) * (3 - grid.ndim)
    spacing = tuple(grid.spacing) + (grid.spacing[0],) * (3 - grid.ndim)
    extent = " ".join(f"0 {n}" for n in cells)
    arrays = []
    for name, f in fields.items():
        f = np.asarray(f)
        vtype = _VTK_TYPES.get(f.dtype, "Float64")
        f = f.astype(np.float64 if vtype == "Float64" else np.float32, copy=False)
        if f.shape == tuple(grid.cells):
            data, ncomp = f.reshape(cells).transpose(2, 1, 0), 1  # VTK: x fastest
        elif f.shape == (3, *grid.cells):
            data, ncomp = np.moveaxis(f.reshape((3, *cells)), 0, -1).transpose(2, 1, 0, 3), 3
        else:
            raise InputError(f"field {name!r} has shape {f.shape}; expected {grid.cells} or (3, *{grid.cells})")
        arrays.append(f'        <DataArray type="{vtype}" Name="{name}" NumberOfComponents="{ncomp}" format="binary">\n'
                      f"          {_b64(data)}\n        </DataArray>")
    field_data = "" if time is None else (
        '    <FieldData>\n      <DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="binary">'
        f"{_b64(np.array([time], dtype=np.float64))}</DataArray>\n    </FieldData>\n")
    xml = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'
        f'  <ImageData WholeExtent="{extent}" Origin="0 0 0" Spacing="{" ".join(repr(float(h)) for h in spacing)}">\n'
        f"{field_data}"
        f'    <Piece Extent="{extent}">\n      <CellData>\n' + "\n".join(arrays) + "\n      </CellData>\n"
        "    </Piece>\n  </ImageData>\n</VTKFile>\n"
    )
    try:
        with atomic_path(path) as tmp:
            tmp.write_text(xml, encoding="ascii")
    except OSError as exc:
        raise InputError(f"cannot write file {str(path)!r}: {exc.strerror or exc}") from exc
    return path


#: File name of a run's checkpoint in its output folder.
CHECKPOINT = "checkpoint.npz"
#: Version of the checkpoint layout; :func:`load_checkpoint` refuses any other.
CHECKPOINT_FORMAT = 2
_CHECKPOINT_KEYS = ("format", "hash", "U", "t", "steps", "output_index", "history", "config")


def _content_hash(U: np.ndarray, t: float, steps: int, output_index: int, history: str, config: str) -> str:
    """SHA-256 of everything a checkpoint holds (state bytes, shape, dtype, counters, history, config)."""
    head = {"format": CHECKPOINT_FORMAT, "shape": list(U.shape), "dtype": U.dtype.str, "t": float(t).hex(),
            "steps": int(steps), "output_index": int(output_index)}
    h = hashlib.sha256(json.dumps(head, sort_keys=True).encode())
    for part in (np.ascontiguousarray(U).tobytes(), history.encode(), config.encode()):
        h.update(part)
    return h.hexdigest()


def save_checkpoint(path: str | Path, U: np.ndarray, t: float, steps: int, output_index: int,
                    history: dict[str, list], config_json: str) -> Path:
    """Write a checkpoint atomically: state, time, counters, diagnostics so far, the config, a format
    version and a SHA-256 of all of it (checked by :func:`load_checkpoint`)."""
    path = Path(path)
    U = np.asarray(U)
    hist = json.dumps({k: np.asarray(v).tolist() for k, v in history.items()})
    digest = _content_hash(U, t, steps, output_index, hist, config_json)
    try:
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            np.savez(f, format=np.int64(CHECKPOINT_FORMAT), hash=digest, U=U, t=np.float64(t), steps=np.int64(steps),
                     output_index=np.int64(output_index), history=hist, config=config_json)
    except OSError as exc:
        raise InputError(f"cannot write checkpoint {str(path)!r}: {exc.strerror or exc}") from exc
    return path


def load_checkpoint(path: str | Path) -> dict[str, Any]:
    """Read a checkpoint written by :func:`save_checkpoint`, checking its format version and hash.

    Raises :class:`InputError` with one line naming what is wrong: a missing, unreadable or
    truncated file, a missing field, another format version or content that does not match its
    hash.  Whether the contents fit a run is checked by the run (:meth:`Simulation.run`).
    """
    path = Path(path)
    name = repr(str(path))
    if not path.is_file():
        raise InputError(f"checkpoint {name} does not exist" + (" (it is a directory)" if path.is_dir() else ""))
    try:
        with np.load(path, allow_pickle=False) as z:
            missing = [k for k in _CHECKPOINT_KEYS if k not in z.files]
            if missing == list(_CHECKPOINT_KEYS[:2]):
                raise InputError(f"checkpoint {name} has no format version or hash (written by an older ktgf?); "
                                 "start the run again with --overwrite")
            if missing:
                raise InputError(f"checkpoint {name} lacks the field(s) {', '.join(missing)}: not a ktgf checkpoint")
            if (fmt := int(z["format"])) != CHECKPOINT_FORMAT:
                raise InputError(f"checkpoint {name} has format version {fmt}; this ktgf reads version {CHECKPOINT_FORMAT}")
            raw = {k: z[k] for k in _CHECKPOINT_KEYS}
    except InputError:
        raise
    except Exception as exc:  # zip, CRC, npy header, decode errors: all mean "damaged"
        raise InputError(f"checkpoint {name} is unreadable (truncated or not a ktgf checkpoint: "
                         f"{type(exc).__name__}: {exc})".replace("\n", " ")) from None
    try:
        U, hist, config = raw["U"], str(raw["history"]), str(raw["config"])
        t, steps, k = float(raw["t"]), int(raw["steps"]), int(raw["output_index"])
        ok = _content_hash(U, t, steps, k, hist, config) == str(raw["hash"])
    except (TypeError, ValueError) as exc:
        raise InputError(f"checkpoint {name} has a field of the wrong type ({exc})") from None
    if not ok:
        raise InputError(f"checkpoint {name} is corrupt: its contents do not match their SHA-256 (file altered or damaged)")
    try:
        history = {key: list(v) for key, v in json.loads(hist).items()}
    except (ValueError, AttributeError, TypeError) as exc:
        raise InputError(f"checkpoint {name}: field history is not a JSON table ({exc})") from None
    return {"U": U, "t": t, "steps": steps, "output_index": k, "history": history, "config": config}


