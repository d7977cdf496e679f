"""Building the solver's C++ anywhere (:mod:`ktgf.solver.cxx`): flags probed from the compiler, the library cache
keyed by what changes the binary, and the fallbacks said once.

Oracles: a stand-in compiler (a shell script) that answers the probes as told — refusing ``-march=native`` as
clang does on some ARM machines, ``-fopenmp`` as Apple's clang does — and records what it is asked to compile;
the present compiler (g++ or clang), whose probed flags must build a library that loads and runs; and the JAX path
itself, which a run without a compiler must be, bit for bit.
"""

from __future__ import annotations

import ctypes
import dataclasses
import logging
import os
import platform
import re
import socket
import subprocess
import sys
import textwrap

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ktgf.closures import get_model
from ktgf.solver import cell_program, cxx, flux_kernel, fluxes
from ktgf.solver.cases import get_case
from ktgf.solver.grid import Grid
from ktgf.solver.initial import random_velocity
from ktgf.solver.physics import Physics
from ktgf.solver.stepping import Numerics, advance

D, RHO_S = 1e-3, 2500.0

#: The stand-in compiler: ``--version`` and ``-dumpmachine`` from $FAKE_VERSION and $FAKE_MACHINE, ``-###`` names
#: the CPU $FAKE_CPU (and a temporary file whose name changes every call), any flag in $FAKE_REJECT is an error;
#: every command goes to $FAKE_LOG, and a compilation writes an empty output file.
FAKE_CXX = r"""#!/bin/sh
echo "$*" >> "$FAKE_LOG"
for a; do
  case "$a" in
    --version) echo "fakecxx $FAKE_VERSION"; echo "second line"; exit 0;;
    -dumpmachine) echo "$FAKE_MACHINE"; exit 0;;
  esac
  for r in $FAKE_REJECT; do
    if [ "$a" = "$r" ]; then echo "fakecxx: error: unsupported option '$a'" >&2; exit 1; fi
  done
done
for a; do
  if [ "$a" = "-###" ]; then echo " \"/usr/lib/fake/cc1plus\" \"-target-cpu\" \"$FAKE_CPU\" \"/tmp/cc$$.s\"" >&2; exit 0; fi
done
out=""; prev=""
for a; do if [ "$prev" = "-o" ]; then out="$a"; fi; prev="$a"; done
if [ -n "$out" ]; then : > "$out"; fi
"""

pytestmark = pytest.mark.contract


@pytest.fixture
def fake(monkeypatch, tmp_path):
    """The stand-in compiler as $CXX, a fresh cache folder, and nothing probed or said yet in this process."""
    path = tmp_path / "fakecxx"
    path.write_text(FAKE_CXX)
    path.chmod(0o755)
    log = tmp_path / "commands.log"
    for name, value in {"CXX": str(path), "KTGF_CACHE_DIR": str(tmp_path / "cache"), "FAKE_LOG": str(log),
                        "FAKE_VERSION": "1.0", "FAKE_MACHINE": "x86_64-linux-gnu", "FAKE_CPU": "cpu-a",
                        "FAKE_REJECT": ""}.items():
        monkeypatch.setenv(name, value)
    monkeypatch.setattr(cxx, "_said", set())
    cxx.toolchain.cache_clear()
    yield log
    cxx.toolchain.cache_clear()


def _build(name: str = "probe", flags: tuple = (), threads: bool = False):
    return cxx.shared_library(name, "int f() { return 1; }\n", flags, "a test library", "0 s", threads=threads)


def _compilations(log) -> list[list[str]]:
    """The commands that compiled a library into the cache (not the probes)."""
    return [line.split() for line in log.read_text().splitlines() if "/cache/" in line]


def test_the_cache_key_follows_compiler_flags_cpu_and_jax_not_the_host_name(monkeypatch) -> None:
    tc = cxx.Toolchain("/usr/bin/c++", "c++ 12.2 | target x86_64-linux-gnu", ("-march=native",), ("-fopenmp",), "",
                       ("-fopenmp-simd",), "-target-cpu icelake | x86_64: avx2 avx512f")
    flags = ("-O3", "-DKTGF_REAL=double")
    key = cxx.library_key(b"source", flags, tc)
    others = {
        "source": cxx.library_key(b"source 2", flags, tc),
        "compiler": cxx.library_key(b"source", flags, dataclasses.replace(tc, identity="c++ 13.1 | target x86_64")),
        "flags": cxx.library_key(b"source", ("-O3", "-DKTGF_REAL=float"), tc),
        "cpu": cxx.library_key(b"source", flags, dataclasses.replace(tc, target="-target-cpu icelake | x86_64: avx2")),
    }
    monkeypatch.setattr(jax, "__version__", "0.0.1")
    others["jax"] = cxx.library_key(b"source", flags, tc)
    assert len({key, *others.values()}) == 1 + len(others), others
    monkeypatch.undo()
    monkeypatch.setattr(socket, "gethostname", lambda: "another-host")
    monkeypatch.setattr(platform, "node", lambda: "another-host")
    assert cxx.library_key(b"source", flags, tc) == key


def test_a_library_is_rebuilt_for_another_compiler_version_or_cpu_only(fake, monkeypatch) -> None:
    """Through the stand-in compiler: the library's name changes with its version and the CPU its ``-###``
    names (probed again, as a new process would), not with the host name or the temporary names in ``-###``."""
    first = _build()
    cxx.toolchain.cache_clear()
    monkeypatch.setattr(socket, "gethostname", lambda: "another-host")
    monkeypatch.setattr(platform, "node", lambda: "another-host")
    assert _build() == first  # same compiler and CPU, another host (and another pid in the -### output)
    for name, value in (("FAKE_VERSION", "2.0"), ("FAKE_CPU", "cpu-b")):
        with monkeypatch.context() as m:
            m.setenv(name, value)
            cxx.toolchain.cache_clear()
            assert _build() != first, name
    assert len(_compilations(fake)) == 3


@pytest.mark.parametrize(("reject", "arch", "threads"), [
    ("", "-march=native", "-fopenmp"),  # g++, or clang with libomp
    ("-march=native", "-mcpu=native", "-fopenmp"),  # clang on ARM before -march=native
    ("-fopenmp", "-march=native", "-fopenmp-simd"),  # Apple's clang
    ("-march=native -mcpu=native -fopenmp -fopenmp-simd", None, None),  # neither
])
def test_flags_are_those_the_compiler_accepts(fake, monkeypatch, caplog, reject: str, arch, threads) -> None:
    monkeypatch.setenv("FAKE_REJECT", reject)
    with caplog.at_level(logging.WARNING, logger="ktgf"):
        _build(threads=True)
        _build("other", threads=True)
    command = _compilations(fake)[0]
    probed = {"-march=native", "-mcpu=native", "-fopenmp", "-fopenmp-simd"} & set(command)
    assert probed == {f for f in (arch, threads) if f}
    assert {"-O3", "-ffp-contract=off", "-fno-math-errno", "-shared", "-fPIC", "-std=c++17"} <= set(command)
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    if threads == "-fopenmp":
        assert warnings == []
    else:  # said once, in one line: why (the compiler's error) and what it costs
        assert len(warnings) == 1 and "\n" not in warnings[0], warnings
        assert re.search(r"fakecxx does not build OpenMP programs \(fakecxx: error: unsupported option '-fopenmp'\): "
                         r"the C\+\+ kernel runs on one thread", warnings[0]), warnings[0]


def _present() -> str | None:
    try:
        return cxx.compiler()
    except RuntimeError:
        return None


OPENMP_SOURCE = textwrap.dedent("""\
    #ifdef _OPENMP
    #include <omp.h>
    #endif
    extern "C" long ktgf_sum(long n) {
      long s = 0;
    #pragma omp parallel for reduction(+ : s)
      for (long i = 0; i < n; ++i) s += i;
      return s;
    }
    extern "C" int ktgf_openmp() {
    #ifdef _OPENMP
      return 1;
    #else
      return 0;
    #endif
    }
    """)


@pytest.mark.skipif(_present() is None, reason="no C++ compiler")
def test_flags_probed_from_the_present_compiler(monkeypatch, tmp_path) -> None:
    """The present compiler's probed flags build a library that loads and computes; g++ takes OpenMP; on x86 both
    g++ and clang take ``-march=native``, and what it means on this CPU (the compiler's expansion) is in the key."""
    monkeypatch.setenv("KTGF_CACHE_DIR", str(tmp_path))
    tc = cxx.toolchain(cxx.compiler())
    if platform.machine().lower() in ("x86_64", "amd64"):
        assert tc.arch == ("-march=native",)
    if tc.arch:  # the CPU the native flag stands for: g++'s -march=<cpu>, clang's -target-cpu <cpu>
        assert re.search(r"-march=(?!native)\w|-mcpu=(?!native)\w|-target-cpu \w", tc.target), tc.target
    if "clang" not in tc.identity.lower():
        assert tc.openmp == ("-fopenmp",), tc.openmp_error
    lib = ctypes.CDLL(str(cxx.shared_library("openmp_probe", OPENMP_SOURCE, (), "a test library", "1 s",
                                             threads=True)))
    lib.ktgf_sum.restype = ctypes.c_long
    lib.ktgf_sum.argtypes = (ctypes.c_long,)
    assert lib.ktgf_sum(100_001) == 100_000 * 100_001 // 2
    assert lib.ktgf_openmp() == (1 if tc.openmp else 0)


@pytest.fixture
def no_compiler(monkeypatch, tmp_path):
    """$CXX names a program that does not exist (as .ci/run's second test run does), nothing built or said yet."""
    monkeypatch.setenv("CXX", "no-such-compiler-ktgf")
    monkeypatch.setenv("KTGF_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(flux_kernel, "_loaded", {})
    monkeypatch.setattr(cxx, "_said", set())
    for cached in (cell_program._program, cell_program._compiled):
        cached.cache_clear()
    yield
    cell_program._program.cache_clear()  # its None results would outlive the missing compiler


def _warnings(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING and r.name.startswith("ktgf")]


def test_without_a_compiler_the_jax_path_runs_and_says_why_once(no_compiler, monkeypatch, caplog) -> None:
    grid = Grid((6, 8, 10), (6 * D, 8 * 1.3 * D, 10 * 0.8 * D))
    m = get_model("ret")
    phys = get_case("cooling").physics(Physics(m, 0.8, D, RHO_S, 0.99 * m.phi_max), grid)
    U = tuple(jnp.asarray(random_velocity(grid, phys, 0.3, 1e-4, 0.05, 4)))
    num = Numerics(scheme="ssprk3")
    builds = []
    build = flux_kernel.build
    monkeypatch.setattr(flux_kernel, "build", lambda v: builds.append(v) or build(v))
    monkeypatch.setattr(fluxes, "FLUX_KERNEL", True)
    with caplog.at_level(logging.WARNING, logger="ktgf"):
        assert not flux_kernel.applies(grid, jnp.float64, "stage", "vanleer", "hll")
        assert not flux_kernel.applies(grid, jnp.float32, "rhs", "minmod", "rusanov")  # decided once: not tried
        assert not flux_kernel.available()
        text = jax.jit(lambda U: advance.__wrapped__(U, 0.0, 1e30, 3, grid, phys, num)).lower(U).as_text()
        out = advance(U, 0.0, 1e30, 3, grid, phys, num)
    assert len(builds) == 1
    (message,) = _warnings(caplog)
    assert "\n" not in message
    why = "no C++ compiler (CXX = 'no-such-compiler-ktgf' is not found)"
    assert f"the C++ flux kernel is not available ({why})" in message
    assert f"the solver runs the JAX path instead, {flux_kernel.FALLBACK_COST}" in message
    assert flux_kernel.unavailable() == why
    assert not any(base in text for base in (flux_kernel.TARGET, flux_kernel.STAGE_TARGET, flux_kernel.CELLS_TARGET,
                                             flux_kernel.LIMITS_TARGET))
    # The JAX path, bit for bit: the same steps with the kernel switched off.
    monkeypatch.setattr(fluxes, "FLUX_KERNEL", False)
    ref = advance(U, 0.0, 1e30, 3, grid, phys, num)
    assert int(out[2]) == 3 and int(out[3]) == 0
    assert np.array_equal(np.asarray(out[0]), np.asarray(ref[0]))
    assert float(np.max(np.abs(np.asarray(out[0]) - np.asarray(U)))) > 0.0


def test_a_cell_program_that_cannot_be_built_is_said_once(no_compiler, caplog) -> None:
    m = get_model("ret")
    phys = get_case("cooling").physics(Physics(m, 0.8, D, RHO_S, 0.99 * m.phi_max), Grid((4, 4, 4), (4 * D,) * 3))
    with caplog.at_level(logging.WARNING, logger="ktgf"):
        assert cell_program.for_physics(phys, np.float64) is None
        assert cell_program.for_physics(phys, np.float32) is None
        assert cell_program.for_physics(phys, np.float64, limits="explicit") is None
    (message,) = _warnings(caplog)
    assert "\n" not in message
    assert message.startswith("the float64 cell program of ret could not be built (no C++ compiler")
    assert f"the fused stage evaluates the closures in an XLA pass instead, {cell_program.FALLBACK_COST}" in message


SERIAL_SCRIPT = """
import dataclasses, logging, sys
import jax, jax.numpy as jnp, numpy as np
jax.config.update("jax_enable_x64", True)
logging.basicConfig(level=logging.WARNING, format="%(message)s")
from ktgf.closures import get_model
from ktgf.solver import cxx, fluxes
from ktgf.solver.cases import get_case
from ktgf.solver.grid import Grid
from ktgf.solver.initial import random_velocity
from ktgf.solver.physics import Physics
from ktgf.solver.stepping import Numerics, advance
probed = cxx.toolchain
cxx.toolchain = lambda path: dataclasses.replace(probed(path), openmp=(), openmp_error="told so by the test")
m = get_model("ret")
grid = Grid((6, 8, 16), (6e-3, 8e-3, 16e-3))
phys = get_case("cooling").physics(Physics(m, 0.8, 1e-3, 2500.0, 0.99 * m.phi_max), grid)
U = tuple(jnp.asarray(random_velocity(grid, phys, 0.3, 1e-4, 0.2, 4)))
num = Numerics(scheme="ssprk3")
text = jax.jit(lambda U: advance.__wrapped__(U, 0.0, 1e30, 3, grid, phys, num)).lower(U).as_text()
assert "ktgf_ssprk_stage_cells__" in text, "the kernel runs"
serial = advance(U, 0.0, 1e30, 3, grid, phys, num)
fluxes.FLUX_KERNEL = False
ref = advance(U, 0.0, 1e30, 3, grid, phys, num)
assert int(serial[2]) == 3 and int(serial[3]) == 0
a, b = np.asarray(serial[0]), np.asarray(ref[0])
print(float(np.max(np.abs(a - b) / np.abs(b).reshape(5, -1).max(axis=1)[:, None, None, None])))
"""


@pytest.mark.slow
@pytest.mark.skipif(_present() is None, reason="no C++ compiler")
def test_a_compiler_without_openmp_builds_a_serial_kernel(tmp_path) -> None:
    """Where the compiler refuses ``-fopenmp`` (told so here), the kernel is built without it and its fused
    SSP-RK3 steps still match the JAX path (one build of the stage variant and cell programs: about 20 s)."""
    script = tmp_path / "serial.py"
    script.write_text(SERIAL_SCRIPT)
    env = {**os.environ, "KTGF_CACHE_DIR": str(tmp_path / "cache")}
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=600,
                         check=False)
    assert run.returncode == 0, run.stderr[-3000:]
    assert float(run.stdout.strip().splitlines()[-1]) < 1e-13
    said = [line for line in run.stderr.splitlines() if "does not build OpenMP programs" in line]
    assert len(said) == 1 and "told so by the test" in said[0] and "runs on one thread" in said[0], run.stderr[-3000:]
