"""Run metadata and file output shared by every solver (netCDF via xarray).

Every Dataset ktgf writes carries, in ``attrs``: the package version, the creation time,
the model (name, parts, options, references) and the run parameters as JSON — enough to
regenerate a figure from its file and a run from its output.
"""

from __future__ import annotations

import datetime as _dt
import json
import platform
from pathlib import Path
from typing import Any

import numpy as np

from . import __version__
from .errors import InputError


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.generic,)):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, Path):
        return str(x)
    if hasattr(x, "model_dump"):  # pydantic models
        return _jsonable(x.model_dump())
    return x if isinstance(x, (str, int, float, bool)) or x is None else repr(x)


def run_metadata(model: Any = None, **parameters: Any) -> dict[str, str]:
    """netCDF-safe attributes: version, time, platform, model description and parameters (JSON)."""
    attrs = {
        "ktgf_version": __version__,
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "python": platform.python_version(),
        "parameters": json.dumps(_jsonable(parameters), sort_keys=True),
    }
    if model is not None:
        attrs.update(model.metadata())
    return attrs


#: The netCDF backend of every file ktgf writes and reads: netCDF4/HDF5 through h5py (a dependency),
#: chosen explicitly so that xarray never falls back silently to netCDF3 through SciPy.
NETCDF_ENGINE = "h5netcdf"
#: Metadata convention of every file (CF 1.8: ``units`` are UDUNITS strings, ``"1"`` for ratios).
CONVENTIONS = "CF-1.8"


def write_netcdf(ds: Any, path: str | Path) -> Path:
    """Write an xarray Dataset to ``path`` as netCDF4 (:data:`NETCDF_ENGINE`) with CF ``Conventions``.

    Parent folders are created; an unwritable path raises :class:`InputError` in one line.
    """
    path = Path(path)
    ds = ds.copy(deep=False)
    ds.attrs = {"Conventions": CONVENTIONS, **ds.attrs}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        ds.to_netcdf(path, engine=NETCDF_ENGINE, invalid_netcdf=False)
    except (PermissionError, OSError) as exc:
        raise InputError(f"cannot write output file {str(path)!r}: {exc.strerror or exc}") from exc
    return path


def open_netcdf(path: str | Path) -> Any:
    """Open a netCDF file written by :func:`write_netcdf` (lazily; use as a context manager)."""
    import xarray as xr

    return xr.open_dataset(path, engine=NETCDF_ENGINE)


def read_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML config file, raising :class:`InputError` if it is missing or not valid TOML."""
    import tomllib

    path = Path(path)
    try:
        return tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(f"config file {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"config file {str(path)!r} is not valid TOML: {exc}") from None
