"""Running independent work in chunks on the executor the caller passes.

The library creates no pools: a workflow (:func:`fi_design.design`, the
parameter studies) takes any ``concurrent.futures``-style executor, described
by :class:`Executor`: a :class:`concurrent.futures.ProcessPoolExecutor`, a
``dask.distributed.Client``, ... or None to run in the calling process.
:func:`chunks` groups work items so that every chunk costs about the same;
:func:`run_chunks` submits them and hands each result back in the calling
thread as it completes.
"""

from __future__ import annotations

import math
import queue
from collections.abc import Callable, Sequence
from typing import Any, Protocol

__all__ = ["Executor", "Future", "chunks", "run_chunks"]


class Future(Protocol):
    """What :meth:`Executor.submit` returns (``concurrent.futures.Future``, a dask future)."""

    def result(self, timeout: float | None = None) -> Any:
        """The function's return value; re-raises its exception."""

    def cancel(self) -> bool:
        """Cancel the call if it has not started."""

    def add_done_callback(self, fn: Callable[[Any], None]) -> None:
        """Call ``fn(future)`` when the call completes."""


class Executor(Protocol):
    """Anything with ``submit(fn, *args)`` returning a :class:`Future`."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        """Schedule ``fn(*args, **kwargs)``."""


def chunks(n: int, size: int) -> list[list[int]]:
    """Interleaved chunks of the positions 0 .. n-1: chunk k holds k, k + K, k + 2K, ...

    Neighbouring items of a grid often cost alike; interleaving spreads the
    expensive corners of a map over all chunks.

    Parameters
    ----------
    n : int
        Number of items.
    size : int
        Items per chunk (at least 1).

    Returns
    -------
    list of list of int
        ``ceil(n / size)`` chunks; empty for ``n = 0``.
    """
    if n == 0:
        return []
    count = math.ceil(n / max(1, size))
    return [list(range(k, n, count)) for k in range(count)]


def run_chunks(executor: Executor, fn: Callable[..., Any], arguments: Sequence[tuple],
               done: Callable[[int, Any], None],
               failed: Callable[[int, Exception], Any]) -> None:
    """Submit ``fn(*arguments[k])`` for every chunk k, and handle the results as they come.

    ``done(k, result)`` is called in the calling thread, in the order the
    chunks complete; a chunk whose worker raised (a dead process, a lost
    connection) gets ``done(k, failed(k, exc))`` instead. An exception in the
    calling thread (Ctrl-C, an error in ``done``) cancels the chunks not yet
    started.

    Parameters
    ----------
    executor : Executor
        Where the chunks run.
    fn : callable
        The work of one chunk.
    arguments : sequence of tuple
        The arguments of each chunk.
    done : callable
        ``done(k, result)``.
    failed : callable
        ``failed(k, exception)`` returns the result to hand on for a chunk
        whose worker raised.
    """
    ready: queue.SimpleQueue = queue.SimpleQueue()
    futures: list[Any] = []
    try:
        for k, args in enumerate(arguments):
            fut = executor.submit(fn, *args)
            fut.add_done_callback(lambda _f, k=k: ready.put(k))
            futures.append(fut)
        for _ in range(len(futures)):
            while True:  # a timeout keeps Ctrl-C responsive while waiting
                try:
                    k = ready.get(timeout=0.2)
                    break
                except queue.Empty:
                    continue
            try:
                result = futures[k].result()
            except Exception as exc:  # noqa: BLE001 -- a dead worker fails its chunk only
                result = failed(k, exc)
            done(k, result)
    except BaseException:
        for fut in futures:
            fut.cancel()
        raise
