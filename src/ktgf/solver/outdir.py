"""An output folder belongs to one run: a lock file, and no silent mixing with an older run.

The lock ``.ktgf-run.lock`` holds the pid, host and start time of the run that owns the
folder.  It is created atomically (``os.link`` of a complete temporary file fails if the lock
exists), so two runs started together cannot both own the folder.  A lock left by a process
that no longer exists on this host (a crash, ``kill -9``) is taken over.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import socket
import tempfile
from pathlib import Path

from ..errors import InputError

LOCK = ".ktgf-run.lock"
#: Files a run writes into its folder, and every case's time series (``--overwrite`` deletes these only).
RUN_FILES = ("checkpoint.npz", "fields_*.vti", "slice_*.png", ".*.tmp*")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


class RunLock:
    """Exclusive ownership of an output folder for the lifetime of a run (a context manager)."""

    def __init__(self, directory: str | Path) -> None:
        self.directory = Path(directory)
        self.path = self.directory / LOCK
        self.owned = False

    def _holder(self) -> dict | None:
        try:
            return json.loads(self.path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return None
        except (OSError, ValueError):
            return {}  # unreadable: half-written by a process that died before the link

    def acquire(self) -> None:
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            info = {"pid": os.getpid(), "host": socket.gethostname(),
                    "started": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")}
            fd, tmp = tempfile.mkstemp(dir=self.directory, prefix=".lock.", suffix=".tmp")
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                json.dump(info, f)
        except OSError as exc:
            raise InputError(f"cannot write to output folder {str(self.directory)!r}: {exc.strerror or exc}") from None
        try:
            for _ in range(3):
                try:
                    os.link(tmp, self.path)
                    self.owned = True
                    return
                except FileExistsError:
                    holder = self._holder()
                    if holder is None:
                        continue  # released meanwhile
                    pid, host = holder.get("pid"), holder.get("host")
                    stale = not holder or (host == info["host"] and isinstance(pid, int) and not _alive(pid))
                    if not stale:
                        raise InputError(
                            f"output folder {str(self.directory)!r} is in use by another run (pid {pid} on {host}, "
                            f"started {holder.get('started', '?')}); wait for it, stop it, or choose another "
                            f"--output-dir (delete {str(self.path)!r} only if that run is gone)"
                        ) from None
                    self.path.unlink(missing_ok=True)  # stale: its process is gone
            raise InputError(f"could not lock output folder {str(self.directory)!r} (another run keeps taking it)")
        finally:
            Path(tmp).unlink(missing_ok=True)

    def release(self) -> None:
        if self.owned:
            holder = self._holder()
            if holder and holder.get("pid") == os.getpid():
                self.path.unlink(missing_ok=True)
            self.owned = False

    def __enter__(self) -> RunLock:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def run_files(directory: str | Path) -> list[Path]:
    """The files of a run found in ``directory`` (sorted)."""
    from .cases import CASES

    d = Path(directory)
    return sorted({p for pattern in (*RUN_FILES, *(c.timeseries for c in CASES.values())) for p in d.glob(pattern) if p.is_file() and p.name != LOCK})
