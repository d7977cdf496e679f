"""Ctrl-C (SIGINT) and SIGTERM as a flag that the run loop polls between compiled chunks.

Python's default SIGINT handler raises KeyboardInterrupt wherever the interpreter happens
to be — inside JAX tracing, inside a garbage-collection callback of XLA (where it is
swallowed) or half-way through writing an output — and an exit while XLA is still
compiling can crash the interpreter on shutdown.  Here the first signal only sets a flag;
the run loop finishes the chunk (or the compilation) under way, writes a checkpoint that
matches the files on disk and stops.  A second signal quits at once with ``os._exit``:
every file ktgf writes is replaced atomically, so the last checkpoint stays consistent.

``KTGF_TEST_INTERRUPT`` places a SIGINT deterministically for the fault-injection tests
(tests/solver/test_reliability_interrupt.py): ``compile`` (0.2 s after the first chunk starts, i.e.
during its compilation), ``chunk:N`` (after the N-th chunk), ``output:K`` (while output K
is being written) or ``checkpoint:K`` (just after the checkpoint of output K); a third part
``:KILL`` sends SIGKILL instead (a crash: nothing can be saved).
"""

from __future__ import annotations

import os
import signal
import threading
from typing import Any

_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class InterruptFlag:
    """Re-entrant context manager: while active (main thread only), SIGINT/SIGTERM set :attr:`signum`."""

    def __init__(self) -> None:
        self.signum: int | None = None
        self._depth = 0
        self._old: dict[int, Any] = {}

    def __enter__(self) -> InterruptFlag:
        if self._depth == 0 and threading.current_thread() is threading.main_thread():
            self._old = {s: signal.signal(s, self._handle) for s in _SIGNALS}
        self._depth += 1
        return self

    def __exit__(self, *exc: object) -> None:
        self._depth -= 1
        if self._depth == 0:
            for s, old in self._old.items():
                signal.signal(s, old)
            self._old = {}
            self.signum = None

    def _handle(self, signum: int, frame: Any) -> None:
        if self.signum is not None:
            os.write(2, b"\nSecond interrupt: quitting now; the last checkpoint on disk is kept.\n")
            os._exit(128 + signum)
        self.signum = signum
        os.write(2, b"\nInterrupt received: stopping after the current chunk (Ctrl-C again to quit at once)\n")

    @property
    def requested(self) -> bool:
        """True once a signal has arrived."""
        return self.signum is not None

    @property
    def exit_code(self) -> int:
        """Shell convention 128 + signal number (130 for Ctrl-C)."""
        return 128 + (self.signum or signal.SIGINT)


#: The process-wide flag (signal handlers are per process).
STOP = InterruptFlag()


class Interrupted(KeyboardInterrupt):
    """A run stopped by a signal after writing a consistent checkpoint (a KeyboardInterrupt, so
    notebooks and scripts see the usual exception)."""

    def __init__(self, message: str, checkpoint: Any = None, exit_code: int = 130) -> None:
        super().__init__(message)
        self.checkpoint, self.exit_code = checkpoint, exit_code


def fault_hook(point: str, n: int = 0) -> None:
    """Send this process a signal at the point named by ``KTGF_TEST_INTERRUPT`` (tests only)."""
    spec = os.environ.get("KTGF_TEST_INTERRUPT", "")  # unset: the name "" is no point
    name, num, sig = (spec.split(":") + ["0", "INT"])[:3]
    if name != point or int(num or 0) != n:
        return
    signum = signal.SIGKILL if sig == "KILL" else signal.SIGINT
    if point == "compile":
        threading.Timer(0.2, os.kill, (os.getpid(), signum)).start()
    else:
        os.kill(os.getpid(), signum)
