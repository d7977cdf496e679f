"""Run metadata and file output shared by every solver (netCDF via xarray).

Every Dataset ktgf writes carries, in ``attrs``: the package version, the creation time,
the model (name, parts, options, references) and the run parameters as JSON — enough to
regenerate a figure from its file and a run from its output.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ._version import __version__
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


def plain(x: Any) -> Any:
    """Config data from Python callers made TOML-like (NumPy scalars → Python, tuples → lists),
    so that strict validation only refuses what a TOML file could not hold either."""
    if isinstance(x, dict):
        return {k: plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    return x


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


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_UMASK = _umask()


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a unique temporary name beside ``path``; on success it replaces ``path`` atomically.

    Readers (and a resumed run) therefore see either the old file or the complete new one,
    and two writers never share a temporary file.  The temporary name keeps the suffix of
    ``path`` (writers that pick the format from it, like matplotlib, still work).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp" + path.suffix)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes 0600; give the file the usual permissions
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    finally:
        Path(tmp).unlink(missing_ok=True)


def write_netcdf(ds: Any, path: str | Path) -> Path:
    """Write an xarray Dataset to ``path`` as netCDF4 (:data:`NETCDF_ENGINE`) with CF ``Conventions``, atomically.

    Parent folders are created; readers see the old file or the complete new one; an unwritable
    path raises :class:`InputError` in one line.
    """
    path = Path(path)
    ds = ds.copy(deep=False)
    ds.attrs = {"Conventions": CONVENTIONS, **ds.attrs}
    try:
        with atomic_path(path) as tmp:
            ds.to_netcdf(tmp, engine=NETCDF_ENGINE, invalid_netcdf=False)
    except (PermissionError, OSError) as exc:
        raise InputError(f"cannot write output file {str(path)!r}: {exc.strerror or exc}") from exc
    return path


def open_netcdf(path: str | Path) -> Any:
    """Open a netCDF file written by :func:`write_netcdf` (lazily; use as a context manager)."""
    import xarray as xr

    return xr.open_dataset(path, engine=NETCDF_ENGINE)


def read_dataset(path: str | Path, needs: tuple[str, ...] = (), what: str = "netCDF file") -> Any:
    """Load a netCDF file into memory, checking it holds the variables ``needs``.

    Raises :class:`InputError` (one line) for a missing file, a file that is not netCDF and a
    netCDF file of another kind (e.g. a Couette profile given to ``ktgf plot run``).
    """
    import xarray as xr

    path = Path(path)
    if not path.is_file():
        raise InputError(f"{what} {str(path)!r}: no such file" + (" (it is a directory)" if path.is_dir() else ""))
    try:
        ds = xr.load_dataset(path, engine=NETCDF_ENGINE)
    except Exception as exc:  # engines raise ValueError, OSError, KeyError, ... for foreign files
        text = str(exc).strip()
        first = text.splitlines()[0].split(". ")[0][:160] if text else type(exc).__name__
        raise InputError(f"{what} {str(path)!r} is not a readable netCDF file ({first})") from None
    return require(ds, path, needs, what)


def require(ds: Any, path: str | Path, needs: tuple[str, ...], what: str = "netCDF file") -> Any:
    """Return ``ds`` if it holds the variables ``needs``, else raise a one-line :class:`InputError`."""
    missing = [v for v in needs if v not in ds.variables]
    if missing:
        raise InputError(f"{str(Path(path))!r} is not a {what}: it lacks {', '.join(missing)}")
    return ds


def read_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML config file, raising :class:`InputError` if it is missing or not valid TOML."""
    import tomllib

    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise InputError(f"config file {str(path)!r} does not exist") from None
    except IsADirectoryError:
        raise InputError(f"config file {str(path)!r} is a directory, not a TOML file") from None
    except OSError as exc:
        raise InputError(f"config file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"config file {str(path)!r} is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
            "save it as UTF-8"
        ) from None
    try:
        return tomllib.loads(text.removeprefix("\ufeff"))
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"config file {str(path)!r} is not valid TOML: {exc}") from None
