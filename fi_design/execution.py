"""Running independent work in chunks on the executor the caller passes.

The library creates no pools: a workflow (:func:`fi_design.design`, the
parameter studies) takes any ``concurrent.futures``-style executor, described
by :class:`Executor`: a :class:`concurrent.futures.ProcessPoolExecutor`, a
``dask.distributed.Client``, ... or None to run in the calling process.
:func:`chunks` groups work items so that every chunk costs about the same;
:func:`run_chunks` submits them and hands each result back in the calling
thread as it completes; :class:`Background` runs such a submitting call in a
thread of its own, so that the calling thread goes on while the executor works.
"""

from __future__ import annotations

import math
import queue
import threading
from collections.abc import Callable, Sequence
from typing import Any, Protocol

__all__ = ["Executor", "Future", "chunks", "run_chunks", "Background", "check_executor"]


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


def check_executor(executor: Any) -> None:
    """Refuse an ``executor`` argument that is neither None nor an :class:`Executor`.

    Parameters
    ----------
    executor : Executor or None
        What the caller passed.

    Raises
    ------
    fi_design.errors.ArgumentError
        ``executor`` has no callable ``submit``.
    """
    if executor is not None and not callable(getattr(executor, "submit", None)):
        from .errors import ArgumentError

        raise ArgumentError("executor must be None or a concurrent.futures-style executor (a "
                            "ProcessPoolExecutor, a dask.distributed Client: submit(fn, *args) "
                            f"returning a future), got {type(executor).__name__} {executor!r}")


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


class Background:
    """A call run in a daemon thread of this process; :meth:`result` waits for it.

    For a call that mostly waits on an executor (it submits chunks with
    :func:`run_chunks` and collects them): the chunks start at once, and the
    calling thread goes on with its own work meanwhile. A daemon thread: an
    interruption of the calling thread never waits for it.

    Parameters
    ----------
    fn : callable
        The call; ``fn(*args, **kwargs)``.
    *args, **kwargs
        Its arguments.

    Examples
    --------
    >>> job = Background(sum, [1, 2, 3])
    >>> job.result()
    6
    """

    def __init__(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> None:
        self._value: Any = None
        self._error: BaseException | None = None

        def body() -> None:
            try:
                self._value = fn(*args, **kwargs)
            except BaseException as exc:  # noqa: BLE001 -- handed to result()
                self._error = exc

        name = f"background {getattr(fn, '__name__', 'call')}"
        self._thread = threading.Thread(target=body, name=name, daemon=True)
        self._thread.start()

    def result(self) -> Any:
        """The call's return value, once it has returned; re-raises its exception.

        Waits in short slices, so that Ctrl-C in the calling thread is not held up.
        """
        while self._thread.is_alive():
            self._thread.join(0.2)
        if self._error is not None:
            raise self._error
        return self._value
