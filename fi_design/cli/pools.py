"""The executors the command line makes and passes into the library.

The library never creates pools or clusters (:func:`fi_design.design`,
:func:`fi_design.sweep` and the other workflows take an ``executor``); the
CLI makes them here, as context managers that close them again:

- :func:`confirmation_pool`: up to two forked worker processes that run a
  design's nonlinear confirmation and its robustness study while the calling
  process does the linear analysis;
- :func:`report_pool`: one forked worker that draws a PDF report's figures
  while the calling process lays the report out;
- :class:`StudyPool`: the executor of a parameter study, a local process pool
  or a dask.distributed client.

They start their worker processes at once, when entered, before the caller
starts a progress display's thread (fork and threads do not mix), with the
signals held (:func:`fi_design.interrupts.held`): a Ctrl-C while a pool
starts comes when it has started, and then stops it. The workers end with
their parent: they leave SIGINT to it, die on SIGTERM, and Linux sends them
SIGTERM when the parent dies, however it dies. When the work fails or is
interrupted, a pool stops its own workers at once (never any other child
process of the interpreter) instead of waiting for them.
"""

from __future__ import annotations

import contextlib
import functools
import multiprocessing
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

from .. import interrupts
from ..errors import ArgumentError, FiDesignError

__all__ = ["EXECUTORS", "confirmation_pool", "report_pool", "StudyPool"]

#: Kinds of study executor (``--executor``).
EXECUTORS = ("local", "dask")


def _fork_context() -> Any:
    """The fork start method where it exists (workers inherit the loaded modules), else None."""
    if "fork" in multiprocessing.get_all_start_methods() and sys.platform.startswith("linux"):
        return multiprocessing.get_context("fork")
    return None


def _worker_start(parent: int, then: Callable[[], None] | None = None) -> None:
    """Initializer of every worker: end with the parent, leave Ctrl-C to it, then ``then()``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C and ends us
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # not the parent's handler: just end
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        import ctypes

        try:  # PR_SET_PDEATHSIG: SIGTERM when the parent dies, even by SIGKILL
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM, 0, 0, 0)
        except (OSError, AttributeError):  # pragma: no cover - no prctl
            pass
    if os.getppid() != parent:  # the parent died before the line above
        os._exit(1)
    if then is not None:
        then()


def _process_pool(workers: int, ctx: Any, then: Callable[[], None] | None = None) -> tuple:
    """A started process pool and its own worker processes.

    All workers are forked here, from the calling thread (before a progress
    display's thread exists): with fork, a pool starts every worker at its
    first task, and this submits a trivial one and waits for it.
    """
    from concurrent.futures import ProcessPoolExecutor

    before = set(multiprocessing.active_children())
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                               initializer=functools.partial(_worker_start, os.getpid(), then))
    try:
        pool.submit(int).result()
    except BaseException:
        _stop(pool, [p for p in multiprocessing.active_children() if p not in before])
        raise
    return pool, [p for p in multiprocessing.active_children() if p not in before]


def _quiet_pool_threads() -> None:
    """From now on, an error of a process pool's own threads taken apart under them (its
    pipes closed while it waits on them: ``OSError``, ``ValueError``, ``EOFError``) is not
    printed: the run is ending on an interruption or a failure, which stays its outcome."""
    previous = threading.excepthook
    if getattr(previous, "quiets_pool_threads", False):  # installed already: once is enough
        return

    def hook(args: Any) -> None:
        pool_thread = type(args.thread).__module__.startswith("concurrent.futures") or \
            type(args.thread).__module__.startswith("multiprocessing")
        if pool_thread and issubclass(args.exc_type, (OSError, ValueError, EOFError)):
            return
        previous(args)

    hook.quiets_pool_threads = True  # type: ignore[attr-defined]
    threading.excepthook = hook


def _stop(pool: Any, workers: list) -> None:
    """Stop a pool at once: cancel what has not started, end its own workers (no others).

    Runs with the signals held (a second Ctrl-C does not leave workers behind) and on the
    way out of a failure or an interruption, which stays the outcome: the pool's manager
    thread takes the pool apart at the same time (its pipes closed, its workers reaped),
    and an error of that race (``OSError: [Errno 9] Bad file descriptor``) is not the
    run's.
    """
    with interrupts.held():
        _quiet_pool_threads()
        with contextlib.suppress(OSError, ValueError, RuntimeError):
            pool.shutdown(wait=False, cancel_futures=True)
        for worker in workers:
            with contextlib.suppress(OSError, ValueError):
                if worker.is_alive():
                    worker.terminate()
        for worker in workers:
            with contextlib.suppress(OSError, ValueError):
                worker.join(timeout=5)
                if worker.is_alive():  # busy in a signal handler or starved of CPU: no waiting
                    worker.kill()
                    worker.join(timeout=5)


@contextlib.contextmanager
def confirmation_pool(enabled: bool = True) -> Iterator[Any]:
    """Worker processes for a design's confirmation and robustness, or None (run here).

    Two workers where the machine has two cores or more (one otherwise): the
    confirmation's simulations and the robustness study then overlap each
    other and the linear analysis. The kernel and scipy.signal are loaded
    here first (:func:`fi_design.studies.warm_up`), so the forked workers
    start with them; the workers are started before this yields, so enter
    it before a progress display (a spinner's thread).
    When the work fails or is interrupted, the pool's own workers are
    stopped at once rather than waited for.

    Parameters
    ----------
    enabled : bool, optional
        False yields None (nothing to confirm).

    Yields
    ------
    concurrent.futures.ProcessPoolExecutor or None
        None where processes cannot be forked.
    """
    def load() -> None:
        from ..studies import warm_up

        # scipy.signal (the metric's peak finder; python-control needs it here anyway) is
        # the larger part of every import the work needs: loaded once before the fork, the
        # workers inherit it instead of each importing it again on two cores (measured in
        # BENCHMARKS.md)
        warm_up()

    with _forked_pool(enabled, min(2, os.cpu_count() or 1), load) as pool:
        yield pool


@contextlib.contextmanager
def report_pool(path: Any) -> Iterator[Any]:
    """One forked worker that draws a PDF report's figures while this process lays the
    report out, or an HTML report's beside this process (:func:`fi_design.report.render_report`),
    or None.

    Forked when entered, after the work the report shows: the worker inherits the loaded
    modules (matplotlib among them). Enter it before a progress display (a spinner's
    thread); stopped at once when the report fails or is interrupted.

    Parameters
    ----------
    path : pathlib.Path or None
        The report (``.pdf`` or ``.html``).

    Yields
    ------
    concurrent.futures.ProcessPoolExecutor or None
        None without a report or where processes cannot be forked.
    """
    with _forked_pool(path is not None, 1) as pool:
        yield pool


@contextlib.contextmanager
def _forked_pool(enabled: bool, workers: int,
                 load: Callable[[], None] | None = None) -> Iterator[Any]:
    """``workers`` forked worker processes, started when entered (after ``load()``), or None
    (not ``enabled``, or no fork); stopped at once on a failure or an interruption."""
    ctx = _fork_context() if enabled else None
    if ctx is None:
        yield None
        return
    started: list = []
    try:
        # held: an interruption inside the import of a compiled module or a fork is no
        # interruption but an ImportError or a half-started pool; it comes at the end
        with interrupts.held():
            if load is not None:
                load()
            started.extend(_process_pool(workers, ctx))
        yield started[0]
    except BaseException:
        if started:
            _stop(*started)
        raise
    started[0].shutdown(wait=True)


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
            self.__exit__(*sys.exc_info())
            raise

    def _start(self) -> Any:
        from ..studies import warm_up

        # held: an interruption inside the import of a compiled module or a fork is no
        # interruption but an ImportError or a half-started pool; it comes at the end
        # (__enter__ then closes what was started)
        with interrupts.held():
            warm_up()  # compile or load the kernel once here, before any worker starts
            if self.kind == "dask":
                return self._dask()
            if self.jobs == 1:
                return None
            # the workers start now, before the progress bar's thread exists (fork and
            # threads do not mix)
            pool, workers = _process_pool(self.jobs, _fork_context(), warm_up)
            self._closers.append(lambda failed: _stop(pool, workers) if failed else
                                 pool.shutdown(wait=True, cancel_futures=True))
            return pool

    def _dask(self) -> Any:
        import logging

        from ..studies import warm_up

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
                self._closers.append(lambda failed: cluster.close())
                client = Client(cluster)
        except (OSError, TimeoutError, ValueError) as exc:
            where = self.scheduler or "a local cluster"
            raise FiDesignError(f"cannot connect to the dask scheduler at {where}: {exc}") \
                from None
        self._closers.insert(0, lambda failed: client.close())
        client.run(warm_up)  # every worker loads the kernel before its first chunk
        return client

    def __exit__(self, *exc: Any) -> None:
        failed = exc[0] is not None
        for close in self._closers:
            try:
                close(failed)
            except Exception:  # noqa: BLE001 -- closing must not hide the real outcome
                pass
