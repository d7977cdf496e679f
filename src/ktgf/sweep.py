"""Parameter sweeps through ``concurrent.futures`` executors.

Any object with the :class:`concurrent.futures.Executor` interface (``submit``) runs a
sweep: ``None`` runs it in-process, a ``ProcessPoolExecutor`` on local cores, and a Dask
``distributed.Client`` (whose ``get_executor()`` returns an Executor) on a cluster — the
engine for sweeps that outgrow one machine.  Work is split into chunks so that each task
is large enough to amortise scheduling.
"""

from __future__ import annotations

from concurrent.futures import Executor
from contextlib import contextmanager
from typing import Any, Callable, Iterable, Iterator, Sequence


def as_executor(executor: Any) -> Executor | None:
    """Accept an Executor, a Dask ``Client`` (converted with ``get_executor()``) or None."""
    if executor is None or isinstance(executor, Executor):
        return executor
    if hasattr(executor, "get_executor"):
        return executor.get_executor()
    if hasattr(executor, "submit"):
        return executor
    raise TypeError(f"executor must be a concurrent.futures.Executor or a dask Client, not {type(executor).__name__}")


def map_tasks(
    fn: Callable[..., Any],
    tasks: Sequence[Any] | Iterable[Any],
    *,
    executor: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[Any]:
    """Apply ``fn`` to every task (in order) on ``executor``; call ``progress(done, total)`` as results arrive.

    ``fn`` and its arguments must be picklable for process pools and Dask (a module-level
    function and plain data: model names rather than Model objects with user callables).
    """
    tasks = list(tasks)
    total = len(tasks)
    ex = as_executor(executor)
    results: list[Any] = [None] * total
    if ex is None:
        for i, t in enumerate(tasks):
            results[i] = fn(t)
            if progress:
                progress(i + 1, total)
        return results
    futures = {ex.submit(fn, t): i for i, t in enumerate(tasks)}
    from concurrent.futures import as_completed

    try:
        done = 0
        for fut in as_completed(futures):
            results[futures[fut]] = fut.result()
            done += 1
            if progress:
                progress(done, total)
    except BaseException:
        for fut in futures:
            fut.cancel()
        raise
    return results


def process_pool(workers: int) -> Executor:
    """A local process pool whose workers are spawned, not forked.

    Forking a process that has imported JAX (multithreaded) can deadlock, so ktgf never forks.
    """
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))


@contextmanager
def open_executor(workers: int = 0, scheduler: str | None = None) -> Iterator[Any]:
    """The executor a command-line option pair asks for, closed on exit.

    ``scheduler`` (a Dask scheduler address) wins over ``workers`` (a local spawned process
    pool); neither gives ``None``, i.e. in-process.
    """
    if scheduler:
        from distributed import Client

        from .errors import InputError

        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            raise InputError(f"Dask scheduler {scheduler!r} is unreachable: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
        try:
            yield client
        finally:
            client.close()
    elif workers > 0:
        pool = process_pool(workers)
        try:
            yield pool
        finally:
            pool.shutdown()
    else:
        yield None
