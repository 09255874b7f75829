"""The executors the command line makes and passes into the library.

The library never creates pools or clusters (:func:`fi_design.design`,
:func:`fi_design.sweep` and the other workflows take an ``executor``); the
CLI makes them here, as context managers that close them again:

- :func:`confirmation_pool`: up to two forked worker processes that run a
  design's nonlinear confirmation and its robustness study while the calling
  process does the linear analysis;
- :class:`StudyPool`: the executor of a parameter study, a local process pool
  or a dask.distributed client.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import sys
from collections.abc import Iterator
from typing import Any

from .errors import ArgumentError, FiDesignError

__all__ = ["EXECUTORS", "confirmation_pool", "StudyPool"]

#: Kinds of study executor (``--executor``).
EXECUTORS = ("local", "dask")


def _fork_context() -> Any:
    """The fork start method where it exists (workers inherit the loaded modules), else None."""
    if "fork" in multiprocessing.get_all_start_methods() and sys.platform.startswith("linux"):
        return multiprocessing.get_context("fork")
    return None


@contextlib.contextmanager
def confirmation_pool(enabled: bool = True) -> Iterator[Any]:
    """Worker processes for a design's confirmation and robustness, or None (run here).

    Two workers where the machine has two cores or more (one otherwise): the
    confirmation's simulations and the robustness study then overlap each
    other and the linear analysis. The kernel and scipy.signal are loaded
    here first (:func:`fi_design.studies.warm_up`), so the forked workers
    start with them.
    When the work fails or is interrupted, the worker is stopped at once
    rather than waited for.

    Parameters
    ----------
    enabled : bool, optional
        False yields None (nothing to confirm).

    Yields
    ------
    concurrent.futures.ProcessPoolExecutor or None
        None where processes cannot be forked.
    """
    ctx = _fork_context() if enabled else None
    if ctx is None:
        yield None
        return
    from concurrent.futures import ProcessPoolExecutor

    from .studies import warm_up

    # scipy.signal (the metric's peak finder; python-control needs it here anyway) is the
    # larger part of every import the work needs: loaded once before the fork, the workers
    # inherit it instead of each importing it again on two cores (measured in BENCHMARKS.md)
    warm_up()

    pool = ProcessPoolExecutor(max_workers=min(2, os.cpu_count() or 1), mp_context=ctx)
    try:
        yield pool
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        for child in multiprocessing.active_children():  # the pool's worker
            child.terminate()
        raise
    pool.shutdown(wait=True)


class StudyPool:
    """The executor of a study command, as a context manager (None: serial).

    Creates a process pool (fork start method where available, after the
    kernel is loaded in this process, so that workers inherit it), or a
    dask.distributed client on a given scheduler or a local cluster.

    Parameters
    ----------
    kind : {"local", "dask"}
        Where the points run.
    jobs : int
        Worker processes or local dask workers; 0: all cores; 1 with
        ``local``: serially in this process.
    scheduler : str, optional
        Address of a running dask scheduler (with ``dask``); None starts a
        local cluster.
    """

    def __init__(self, kind: str, jobs: int, scheduler: str | None = None) -> None:
        if kind not in EXECUTORS:
            raise ArgumentError(f"executor kind must be one of {EXECUTORS}, got {kind!r}")
        self.kind = kind
        self.jobs = jobs or (os.cpu_count() or 1)
        self.scheduler = scheduler
        self._closers: list = []

    def describe(self) -> str:
        """How the points run, in words (for the summary's last line).

        Returns
        -------
        str
        """
        if self.kind == "dask":
            return f"dask cluster at {self.scheduler}" if self.scheduler else \
                f"local dask cluster, {self.jobs} worker(s)"
        return "serial" if self.jobs == 1 else f"{self.jobs} worker processes"

    def __enter__(self) -> Any:
        try:
            return self._start()
        except BaseException:
            self.__exit__(None, None, None)
            raise

    def _start(self) -> Any:
        from .studies import warm_up

        warm_up()  # compile or load the kernel once here, before any worker starts
        if self.kind == "dask":
            return self._dask()
        if self.jobs == 1:
            return None
        from concurrent.futures import ProcessPoolExecutor

        pool = ProcessPoolExecutor(max_workers=self.jobs, mp_context=_fork_context(),
                                   initializer=warm_up)
        self._closers.append(lambda: pool.shutdown(wait=True, cancel_futures=True))
        # start the workers now, before the progress bar's thread exists (fork and threads
        # do not mix); with fork all workers start at the first submit
        pool.submit(int).result()
        return pool

    def _dask(self) -> Any:
        import logging

        from .studies import warm_up

        try:
            from distributed import Client, LocalCluster
        except ImportError:  # pragma: no cover - a dependency
            raise FiDesignError("--executor dask needs the 'distributed' package "
                                "(pip install 'dask[distributed]')") from None
        logging.getLogger("distributed").setLevel(logging.ERROR)
        try:
            if self.scheduler:
                client = Client(self.scheduler, timeout="10s")
            else:
                cluster = LocalCluster(n_workers=self.jobs, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
                self._closers.append(cluster.close)
                client = Client(cluster)
        except (OSError, TimeoutError, ValueError) as exc:
            where = self.scheduler or "a local cluster"
            raise FiDesignError(f"cannot connect to the dask scheduler at {where}: {exc}") \
                from None
        self._closers.insert(0, client.close)
        client.run(warm_up)  # every worker loads the kernel before its first chunk
        return client

    def __exit__(self, *exc: Any) -> None:
        for close in self._closers:
            try:
                close()
            except Exception:  # noqa: BLE001 -- closing must not hide the real outcome
                pass
