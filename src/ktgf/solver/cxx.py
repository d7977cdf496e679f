"""Compiling the solver's C++ (:mod:`.flux_kernel`, :mod:`.cell_program`) into shared libraries, once per machine.

The compiler (``$CXX``, else the first of :data:`DEFAULT_COMPILERS` on ``PATH``; ``CXX`` naming a program that
does not exist runs without one), the flags probed for it (:func:`toolchain`), the cache folder
``$KTGF_CACHE_DIR`` and what keys a library there (:func:`library_key`): docs/solver.md, "Compiler, flags and
cache".  A build is compiled into a temporary file and renamed into place, so a library in the cache is always
whole; a file lock next to it makes processes that need it at the same time build it once.  Each build is
announced on the ``ktgf`` logger at INFO; what runs slower than it could is said once at WARNING (:func:`warn_once`).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import logging
import os
import platform
import shlex
import shutil
import subprocess
import tempfile
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

try:
    import fcntl
except ImportError:  # pragma: no cover - no flock (Windows): concurrent builds each compile, os.replace keeps one
    fcntl = None

import jax

log = logging.getLogger(__name__)

#: Compilers tried in this order when ``$CXX`` is not set.
DEFAULT_COMPILERS = ("g++", "c++", "clang++")
#: Flags of every build (g++ and clang accept them all): no fused multiply-add contraction and no errno
#: from the maths functions, so the C++ rounds as XLA does.
COMMON_FLAGS = ("-O3", "-ffp-contract=off", "-fno-math-errno", "-shared", "-fPIC", "-std=c++17")
#: Instruction-set flags, the first the compiler accepts is used (none: code for the compiler's default target).
ARCH_FLAGS = (("-march=native",), ("-mcpu=native",))
_OPENMP_PROBE = ('#include <omp.h>\nextern "C" int ktgf_probe(int n) {\n  int s = 0;\n'
                 "#pragma omp parallel for reduction(+ : s)\n"
                 "  for (int i = 0; i < n; ++i) s += omp_get_num_threads();\n  return s;\n}\n")
_SIMD_PROBE = ('extern "C" void ktgf_probe(long n, double* x) {\n#pragma omp simd\n'
               "  for (long i = 0; i < n; ++i) x[i] *= 2;\n}\n")
_PLAIN_PROBE = 'extern "C" int ktgf_probe(int n) { return n + 1; }\n'
_said: set[str] = set()


def compiler() -> str:
    """Path of the C++ compiler (see the module docstring); raises RuntimeError if there is none."""
    name = os.environ.get("CXX")
    path = next(filter(None, map(shutil.which, (name,) if name else DEFAULT_COMPILERS)), None)
    if path is None:
        raise RuntimeError(f"no C++ compiler (CXX = {name!r} is not found)" if name else
                           f"no C++ compiler (none of {', '.join(DEFAULT_COMPILERS)} on PATH; set CXX)")
    return path


def warn_once(logger: logging.Logger, message: str, key: str | None = None) -> None:
    """``message`` at WARNING on ``logger``, the first time this process says it (or anything of the same ``key``)."""
    key = message if key is None else key
    if key not in _said:
        _said.add(key)
        logger.warning(message)


@dataclass(frozen=True)
class Toolchain:
    """A compiler and what it accepts (:func:`toolchain`).

    ``identity``: the first line of its version text and its target triple; ``arch``: the instruction-set flags it
    accepts (:data:`ARCH_FLAGS`, empty if none); ``openmp``: ``("-fopenmp",)`` if it builds and links an OpenMP program,
    else empty, and ``openmp_error`` why not; ``simd``: ``("-fopenmp-simd",)`` if it accepts that, else empty;
    ``target``: what the arch flags mean here — the compiler's own expansion of them (``-###``: the CPU model and
    its features) and the CPU's feature flags (``/proc/cpuinfo``; empty elsewhere)."""

    path: str
    identity: str
    arch: tuple[str, ...]
    openmp: tuple[str, ...]
    openmp_error: str
    simd: tuple[str, ...]
    target: str

    def flags(self, threads: bool) -> tuple[str, ...]:
        """The probed flags of a build: the arch flags, then OpenMP threads (``threads``, where accepted; else the
        ``simd`` pragmas only)."""
        return (*self.arch, *(self.openmp if threads and self.openmp else self.simd))


def _run(args: Sequence[str], cwd: str) -> subprocess.CompletedProcess:
    try:
        return subprocess.run(list(args), capture_output=True, text=True, cwd=cwd, timeout=120, check=False)
    except (OSError, subprocess.TimeoutExpired) as err:
        return subprocess.CompletedProcess(list(args), 1, "", str(err))


def _last_line(proc: subprocess.CompletedProcess) -> str:
    return (proc.stderr.strip().splitlines() or proc.stdout.strip().splitlines() or ["?"])[-1]


def _builds(cxx: str, flags: Sequence[str], source: str, folder: str) -> subprocess.CompletedProcess:
    """Compiles and links ``source`` as a shared library with ``flags`` (the probe of a flag)."""
    src = os.path.join(folder, "probe.cc")
    Path(src).write_text(source)
    return _run([cxx, *COMMON_FLAGS, *flags, src, "-o", os.path.join(folder, "probe.so")], folder)


def _expansion(cxx: str, flags: Sequence[str], folder: str) -> str:
    """What the compiler makes of ``flags`` (``-###``: the commands it would run, with ``-march=native`` expanded
    into the CPU model and its features), without paths (temporary names, the working folder)."""
    proc = _run([cxx, *flags, "-###", "-x", "c++", "-c", os.devnull, "-o", os.devnull], folder)
    words = []
    for line in proc.stderr.splitlines():
        try:
            tokens = shlex.split(line)
        except ValueError:
            tokens = line.split()
        words += [t for t in tokens if "/" not in t and os.sep not in t]
    return " ".join(words)


def cpu_features() -> str:
    """The CPU's feature flags (the ``flags`` or ``Features`` lines of ``/proc/cpuinfo``; the machine name
    elsewhere)."""
    found = set()
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            if key.strip() in ("flags", "Features"):
                found.add(" ".join(sorted(value.split())))
    return f"{platform.machine()}: {' | '.join(sorted(found))}"


@functools.cache
def toolchain(cxx: str) -> Toolchain:
    """Probes the compiler ``cxx`` (a path): its identity and the flags it accepts (once per process and compiler;
    a few small compilations, about a second)."""
    with tempfile.TemporaryDirectory(prefix="ktgf-probe-") as folder:
        version = _run([cxx, "--version"], folder)
        machine = _run([cxx, "-dumpmachine"], folder)
        identity = f"{(version.stdout.strip().splitlines() or ['?'])[0]} | target {machine.stdout.strip()}"
        arch = next((f for f in ARCH_FLAGS if _builds(cxx, f, _PLAIN_PROBE, folder).returncode == 0), ())
        omp = _builds(cxx, (*arch, "-fopenmp"), _OPENMP_PROBE, folder)
        simd = _builds(cxx, (*arch, "-fopenmp-simd"), _SIMD_PROBE, folder)
        target = _expansion(cxx, arch, folder) + (f" | {cpu_features()}" if arch else "")
    openmp = omp.returncode == 0
    result = Toolchain(cxx, identity, arch, ("-fopenmp",) if openmp else (), "" if openmp else _last_line(omp),
                       ("-fopenmp-simd",) if simd.returncode == 0 else (), target)
    log.debug("compiler %s: %s; flags %s", cxx, identity, result.flags(True))
    return result


def library_key(text: bytes, flags: Sequence[str], tc: Toolchain) -> str:
    """The cache key of a library: the source ``text``, the ``flags``, the compiler's identity and ``target``
    (:class:`Toolchain`), and JAX's and jaxlib's versions."""
    import jaxlib

    parts = [text, " ".join(flags).encode(), tc.identity.encode(), tc.target.encode(), jax.__version__.encode(),
             getattr(jaxlib, "__version__", "").encode()]
    return hashlib.sha256(b"\0".join(parts)).hexdigest()[:16]


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


def shared_library(name: str, source: str | Path, flags: Sequence[str], what: str, about: str,
                   threads: bool = False) -> Path:
    """The shared library compiled from ``source`` with ``flags``, from the cache or built now.

    Parameters
    ----------
    name
        File name prefix in the cache (the key follows it).
    source
        The C++ source text, or the path of a source file (compiled where it is, so that its own
        ``#include "..."`` resolve; its content is in the key).
    flags
        Compiler flags after :data:`COMMON_FLAGS` and the probed ones (:meth:`Toolchain.flags`): ``-D`` macros and
        ``-I`` folders (all of them are in the key).
    what, about
        What is compiled and how long it takes, for the INFO record of a build (e.g. ``"the CPU flux
        kernel for float64 vanleer/hll stage"``, ``"10 s"``).
    threads
        Build with OpenMP threads where the compiler takes them (else serial, said once at WARNING).

    Raises
    ------
    RuntimeError
        No compiler, or the compilation failed (with the last line of its error output).
    """
    tc = toolchain(compiler())
    if threads and not tc.openmp:
        warn_once(log, f"{Path(tc.path).name} does not build OpenMP programs ({tc.openmp_error}): the C++ kernel "
                       f"runs on one thread instead of {os.cpu_count()} (a compiler with OpenMP, e.g. g++ or clang "
                       "with libomp, set in CXX, restores them)")
    flags = (*COMMON_FLAGS, *tc.flags(threads), *flags)
    text = source.read_bytes() if isinstance(source, Path) else source.encode()
    folder = Path(os.environ.get("KTGF_CACHE_DIR", Path.home() / ".cache" / "ktgf"))  # module docstring
    lib = folder / f"{name}-{library_key(text, flags, tc)}.so"
    if lib.exists():
        return lib
    lib.parent.mkdir(parents=True, exist_ok=True)
    with _locked(lib.with_suffix(".lock"), what):
        if lib.exists():  # built by the process that held the lock
            return lib
        log.info("compiling %s (once per machine, about %s)", what, about)
        start = time.perf_counter()
        _compile(tc.path, source, flags, lib, what)
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
        proc = subprocess.run([cxx, *flags, str(source), "-o", tmp], capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise RuntimeError(f"compiling {what} failed: {_last_line(proc)}")
        os.replace(tmp, lib)
    finally:
        for path in temporary:
            Path(path).unlink(missing_ok=True)
