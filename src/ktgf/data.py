"""Where the optional DEM reference data live.

The project keeps particle-simulation data in ``../shared/data`` beside the repository (see
its README).  Every consumer (the Couette comparison, the report, the CLI) finds it here:
an explicit path, then ``$KTGF_DATA``, then ``shared/data`` beside the source tree.  The data are
optional: without them the comparisons are left out and the output says so.
"""

from __future__ import annotations

import os
from pathlib import Path

DATA_ENV = "KTGF_DATA"


def default_data_dirs() -> list[Path]:
    """Where the DEM data is looked for by default: ``shared/data`` beside the source tree or one of its parents.

    The project keeps it at ``../shared/data`` relative to the repository; a git worktree one
    level deeper (``wt/<topic>``) finds it one level further up.
    """
    repo = Path(__file__).resolve().parents[2]
    return [p / "shared" / "data" for p in list(repo.parents)[:2]]


def locate_data_dir(explicit: Path | None) -> tuple[Path | None, str]:
    """The DEM data folder to use, and a sentence saying where it came from (or why there is none).

    Order: the explicit option, ``$KTGF_DATA``, then :func:`default_data_dirs`.  A folder named
    explicitly (option or variable) that does not exist is reported, not an error: the data are optional.
    """
    if explicit is not None:
        src, path = "--data", Path(explicit)
    elif os.environ.get(DATA_ENV):
        src, path = f"${DATA_ENV}", Path(os.environ[DATA_ENV])
    else:
        for cand in default_data_dirs():
            if cand.is_dir():
                return cand.resolve(), f"DEM reference data from {cand.resolve()} (found beside the source tree)"
        return None, (
            "DEM reference data folder not found (looked in "
            + ", ".join(str(p) for p in default_data_dirs())
            + f"; set --data or ${DATA_ENV}): comparisons with particle simulations are left out"
        )
    if path.is_dir():
        return path.resolve(), f"DEM reference data from {path.resolve()} (given by {src})"
    return None, f"DEM reference data folder {path} (given by {src}) does not exist: comparisons with particle simulations are left out"
