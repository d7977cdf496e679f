"""``ktgf run`` from the first instant: Ctrl-C during the start-up imports exits cleanly.

Python's default SIGINT handler raises KeyboardInterrupt wherever the interpreter is — inside
an import, or inside a garbage-collection callback of XLA where it is swallowed and the run
carries on.  Before the run loop installs its flag (:mod:`ktgf.solver.interrupt`) nothing has
been written, so quitting at once with exit code 128 + signal (130 for Ctrl-C) loses nothing;
after the run the same holds, since every file is complete.  Only ``ktgf run`` gets this
handler (other commands keep Python's KeyboardInterrupt).
"""

from __future__ import annotations

import os
import signal
import sys
import threading


def _quit(signum: int, frame: object) -> None:
    os.write(2, b"\nInterrupted: quitting (the files written so far are complete)\n")
    os._exit(128 + signum)


def _is_ktgf_run(argv: list[str]) -> bool:
    if len(argv) >= 3 and argv[1] == "-m" and argv[2] == "ktgf":
        rest = argv[3:]
    elif len(argv) >= 2 and os.path.basename(argv[1]) == "ktgf":
        rest = argv[2:]
    elif argv and os.path.basename(argv[0]) == "ktgf":  # a frozen or directly executed entry point
        rest = argv[1:]
    else:
        return False
    return bool(rest) and rest[0] == "run"


def quit_on_interrupt_outside_the_run_loop() -> None:
    """Install :func:`_quit` for SIGINT/SIGTERM if this process is ``ktgf run``."""
    if threading.current_thread() is threading.main_thread() and _is_ktgf_run(list(getattr(sys, "orig_argv", []))):
        for s in (signal.SIGINT, signal.SIGTERM):
            signal.signal(s, _quit)
