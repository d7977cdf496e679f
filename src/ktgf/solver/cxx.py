"""Compiling the solver's C++ (:mod:`.flux_kernel`, :mod:`.cell_program`) into shared libraries, once per machine.

A library is built on first use with the C++ compiler ``$CXX`` (default ``g++``) into the cache folder
``$KTGF_CACHE_DIR`` (default ``~/.cache/ktgf``), under a name keyed by everything that changes the
binary: the source, the compiler flags (with the ``-D`` macros of a variant), the compiler's path,
JAX's version (the FFI headers) and the host (``-march=native``).  A build is compiled into a
temporary file and renamed into place, so a library in the cache is always whole; a file lock next to
it makes processes that need the same library at the same time (pytest-xdist workers, two runs) build
it once: the others wait, then load it.

Each build is announced on the ``ktgf`` logger at INFO (silent in library use; the ``ktgf`` command
shows it), with the seconds it took when done.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import platform
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Iterator, Sequence

try:
    import fcntl
except ImportError:  # pragma: no cover - no flock (Windows): concurrent builds each compile, os.replace keeps one
    fcntl = None

import jax

log = logging.getLogger(__name__)


def cache_dir() -> Path:
    """The folder of the compiled libraries: ``$KTGF_CACHE_DIR``, default ``~/.cache/ktgf``."""
    return Path(os.environ.get("KTGF_CACHE_DIR", Path.home() / ".cache" / "ktgf"))


def compiler() -> str:
    """Path of the C++ compiler ``$CXX`` (default ``g++``); raises RuntimeError if there is none."""
    name = os.environ.get("CXX", "g++")
    path = shutil.which(name)
    if path is None:
        raise RuntimeError(f"no C++ compiler ({name!r} not found)")
    return path


@contextlib.contextmanager
def _locked(path: Path, what: str) -> Iterator[None]:
    """Holds an exclusive lock on the file ``path`` (created if missing) while the block runs."""
    if fcntl is None:  # pragma: no cover
        yield
        return
    with open(path, "a") as f:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            log.info("waiting for another process compiling %s", what)
            fcntl.flock(f, fcntl.LOCK_EX)
        yield  # closing the file releases the lock


def shared_library(name: str, source: str | Path, flags: Sequence[str], what: str, about: str) -> Path:
    """The shared library compiled from ``source`` with ``flags``, from the cache or built now.

    Parameters
    ----------
    name
        File name prefix in the cache (the key follows it).
    source
        The C++ source text, or the path of a source file (compiled where it is, so that its own
        ``#include "..."`` resolve; its content is in the key).
    flags
        Compiler flags, ``-D`` macros and ``-I`` folders included (all of them are in the key).
    what, about
        What is compiled and how long it takes, for the INFO record of a build (e.g. ``"the CPU flux
        kernel for float64 vanleer/hll stage"``, ``"10 s"``).

    Returns
    -------
    Path
        The library in the cache folder.

    Raises
    ------
    RuntimeError
        No compiler, or the compilation failed (with the last line of its error output).
    """
    cxx = compiler()
    text = source.read_bytes() if isinstance(source, Path) else source.encode()
    key = hashlib.sha256(b"\0".join([text, " ".join(flags).encode(), cxx.encode(), jax.__version__.encode(),
                                     platform.node().encode()])).hexdigest()[:16]
    lib = cache_dir() / f"{name}-{key}.so"
    if lib.exists():
        return lib
    lib.parent.mkdir(parents=True, exist_ok=True)
    with _locked(lib.with_suffix(".lock"), what):
        if lib.exists():  # built by the process that held the lock
            return lib
        log.info("compiling %s (once per machine, about %s)", what, about)
        start = time.perf_counter()
        _compile(cxx, source, flags, lib, what)
        log.info("compiled %s in %.1f s", what, time.perf_counter() - start)
    return lib


def _compile(cxx: str, source: str | Path, flags: Sequence[str], lib: Path, what: str) -> None:
    """Compiles into a temporary file next to ``lib``, then renames it to ``lib`` (atomic: never half a library)."""
    temporary = []
    try:
        if not isinstance(source, Path):
            fd, src = tempfile.mkstemp(suffix=".cc", dir=lib.parent)
            temporary.append(src)
            with os.fdopen(fd, "w") as f:
                f.write(source)
            source = Path(src)
        fd, tmp = tempfile.mkstemp(suffix=".so", dir=lib.parent)
        os.close(fd)
        temporary.append(tmp)
        proc = subprocess.run([cxx, *flags, str(source), "-o", tmp], capture_output=True, text=True)
        if proc.returncode != 0:
            last = (proc.stderr.strip().splitlines() or ["?"])[-1]
            raise RuntimeError(f"compiling {what} failed: {last}")
        os.replace(tmp, lib)
    finally:
        for path in temporary:
            if os.path.exists(path):
                os.unlink(path)
