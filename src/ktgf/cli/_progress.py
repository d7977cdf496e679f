"""A progress callback for sweeps that draws a rich bar only once the sweep has run for a while."""

from __future__ import annotations

import time
from typing import Any, Callable


class DelayedProgress:
    """``progress(done, total)`` callback for :func:`ktgf.sweep.map_tasks` and the sweeps built on it.

    Nothing is drawn for sweeps that finish within ``delay`` seconds (the common case of a
    vectorised map); after that a rich progress bar (on stderr) shows the tasks done.
    Use as a context manager so that the bar is closed however the sweep ends.
    """

    def __init__(self, description: str, *, delay: float = 1.0, clock: Callable[[], float] = time.monotonic,
                 console: Any = None) -> None:
        self.description = description
        self.delay = delay
        self.clock = clock
        self.console = console
        self.start = clock()
        self.bar: Any = None
        self._task: Any = None

    @property
    def shown(self) -> bool:
        """True once the bar has been drawn."""
        return self.bar is not None

    def __call__(self, done: int, total: int) -> None:
        if self.bar is None:
            if done >= total or self.clock() - self.start < self.delay:
                return
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

            self.bar = Progress(
                TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                console=self.console or Console(stderr=True), transient=False,
            )
            self.bar.start()
            self._task = self.bar.add_task(self.description, total=total)
        self.bar.update(self._task, completed=done, total=total)

    def close(self) -> None:
        """Stop the bar (if drawn)."""
        if self.bar is not None:
            self.bar.stop()

    def __enter__(self) -> DelayedProgress:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
