"""Running independent work on the executor the caller passes.

The library creates no pools: a workflow (:func:`fi_design.design`, the
parameter studies) takes any ``concurrent.futures``-style executor, described
by :class:`Executor`: a :class:`concurrent.futures.ProcessPoolExecutor`, a
``dask.distributed.Client``, ... or None to run in the calling process.
"""

from __future__ import annotations

from typing import Any, Callable, Protocol

__all__ = ["Executor", "Future"]


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
