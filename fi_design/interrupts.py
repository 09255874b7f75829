"""Interrupts (SIGINT, SIGTERM, SIGHUP) as exceptions, held where they must wait, never lost.

Python raises ``KeyboardInterrupt`` at whatever bytecode the main thread runs
when Ctrl-C arrives: inside the import of a compiled module (which turns it
into ``ImportError: initialization failed``), in the middle of forking a
worker pool, inside a garbage collector's finalizer or a C library's
callback (which print it and carry on: the run then finishes as if nothing
had happened), or while a temporary file is made. Three tools keep an
interruption what it is:

- :func:`signals_to_exceptions` (the command line, around every command):
  the three signals raise an exception in the main thread (``make(signum)``)
  and are *remembered*;
- :func:`held`: a block that must not be cut in two (starting a worker
  pool, making or removing a temporary file) gets a signal at its end;
- :func:`raise_received`: before a result is moved into place, a signal
  whose exception was swallowed is raised again, so an interrupted run never
  writes its output.

Holding works by the handler, not by the thread's signal mask: the kernel
delivers a signal the main thread blocks to any other thread (a pool's
manager thread, a progress bar), whose handler then still raises in the
main thread, inside the block. Outside :func:`signals_to_exceptions` (a
script using the library) :func:`held` swaps in a recording handler for the
block and hands the signal to the previous handler after it.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["SIGNALS", "held", "raise_received", "received", "signals_to_exceptions"]

#: The signals handled: Ctrl-C, termination, a closed terminal.
SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP")
                if hasattr(signal, name))


class _State:
    """The main thread's signal handling (signal handlers are global to the process)."""

    def __init__(self) -> None:
        self.make: Callable[[int], BaseException] | None = None
        self.received: list[int] = []  # every signal since signals_to_exceptions began
        self.depth = 0  # nesting of held blocks
        self.pending: list[int] = []  # signals that came during a held block


_STATE = _State()


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


#: Delay after which a signal that came inside the import machinery is delivered again [s].
REDELIVERY_DELAY = 0.01


def _on_signal(signum: int, frame: Any) -> None:
    _STATE.received.append(signum)
    if _STATE.depth:
        _STATE.pending.append(signum)
        return
    if _in_import_machinery(frame):
        _deliver_again(signum)
        return
    raise _STATE.make(signum)  # type: ignore[misc]


def _in_import_machinery(frame: Any) -> bool:
    """Whether the main thread runs importlib's own bootstrap code (not a module's code).

    An exception raised there can leave the interpreter's import lock held: the weakref
    callback that drops a module's lock takes the global import lock, and a signal's
    exception raised as that call returns, before its ``try``, never releases it. Every
    other thread's import then waits for ever (a design run with an HTML report hung after a
    Ctrl-C printed "Exception ignored in: <function _get_module_lock.<locals>.cb>").
    """
    code = getattr(frame, "f_code", None)
    return code is not None and code.co_filename.startswith("<frozen importlib")


def _deliver_again(signum: int) -> None:
    """Send ``signum`` to the main thread again shortly, when it has left the import
    machinery (or not: then again, until it has)."""
    main = threading.main_thread().ident
    timer = threading.Timer(REDELIVERY_DELAY, signal.pthread_kill, (main, signum))
    timer.daemon = True
    timer.start()


@contextlib.contextmanager
def signals_to_exceptions(make: Callable[[int], BaseException]) -> Iterator[None]:
    """Raise ``make(signum)`` in the main thread for SIGINT, SIGTERM and SIGHUP, and remember it.

    The default action of SIGTERM and SIGHUP ends the process at once (a
    temporary file stays, worker processes are orphaned); as exceptions,
    every ``finally`` runs. A signal received in the block is also
    remembered: :func:`raise_received` raises it again where a result
    would be written, and when the block ends without an exception, it
    raises it then (the run was interrupted, whatever swallowed the first
    exception). A block that ends by ``SystemExit`` with a success code (0 or
    None: a command line's normal end) raises it too. A block inside another
    starts with the signals the outer one has received (one swallowed while
    the arguments were parsed still stops the command that follows), and hands
    none back: the inner block ends by its own. Outside the main thread the
    block runs unchanged.

    Parameters
    ----------
    make : callable
        ``make(signum)`` returns the exception to raise (``KeyboardInterrupt``
        for SIGINT, say).

    Raises
    ------
    BaseException
        ``make(signum)`` of a signal received in the block (or before it, in
        an outer one), at its end, when the block itself did not raise or
        ended by ``SystemExit`` with a success code.
    """
    if not _main_thread():
        yield
        return
    saved = (_STATE.make, _STATE.received, _STATE.depth, _STATE.pending)
    previous = {s: signal.getsignal(s) for s in SIGNALS}
    _STATE.make, _STATE.received, _STATE.depth, _STATE.pending = make, list(saved[1]), 0, []
    try:
        for s in SIGNALS:
            signal.signal(s, _on_signal)
        try:
            yield
        except SystemExit as exc:
            if _STATE.received and exc.code in (0, None):  # a run that ends as if not stopped
                raise make(_STATE.received[0]) from None
            raise
        if _STATE.received:
            raise make(_STATE.received[0])
    finally:
        try:
            # SIGINT last: its restored handler raises at a Ctrl-C, which must find the
            # others restored already, and the state below restored all the same
            for s, handler in reversed(previous.items()):
                signal.signal(s, handler if handler is not None else signal.SIG_DFL)
        finally:
            _STATE.make, _STATE.received, _STATE.depth, _STATE.pending = saved


@contextlib.contextmanager
def held() -> Iterator[None]:
    """Hold SIGINT, SIGTERM and SIGHUP for a block: a signal then comes at its end.

    For steps that must not be cut in two: a worker pool's start (fork, the
    first imports of compiled modules), making or removing a temporary file.
    Under :func:`signals_to_exceptions` the held signal's exception is
    raised when the block ends (replacing an exception of the block, which
    becomes its context); otherwise the previous handler gets the signal
    then. Outside the main thread the block runs unchanged.
    """
    if not _main_thread():
        yield
        return
    if _STATE.make is not None:
        _STATE.depth += 1
        try:
            yield
        finally:
            _STATE.depth -= 1
            if _STATE.depth == 0 and _STATE.pending:
                signum = _STATE.pending[0]
                _STATE.pending = []
                raise _STATE.make(signum)
        return
    came: list[int] = []
    previous = {}
    try:  # a signal's exception while the handlers are swapped still restores them
        for s in SIGNALS:
            handler = signal.getsignal(s)
            if handler not in (signal.SIG_IGN, None):
                previous[s] = signal.signal(s, lambda signum, frame: came.append(signum))
        yield
    finally:
        for s, handler in reversed(previous.items()):  # SIGINT last, as above
            signal.signal(s, handler)
        if came:
            signal.raise_signal(came[0])  # the handler restored above acts on it now


def received() -> tuple[int, ...]:
    """The signals received since :func:`signals_to_exceptions` began (main thread).

    Returns
    -------
    tuple of int
        Signal numbers, in the order they came; empty outside it.
    """
    return tuple(_STATE.received) if _main_thread() else ()


def raise_received() -> None:
    """Raise the exception of a signal received earlier, if any (under
    :func:`signals_to_exceptions`, in the main thread).

    Called before a result is moved into place: a signal's first exception
    may have been swallowed (raised inside a finalizer or a C library's
    callback, which print it and go on), and the run must not then finish as
    if it had not been interrupted.

    Raises
    ------
    BaseException
        ``make(signum)`` of the first signal received.
    """
    if _main_thread() and _STATE.make is not None and _STATE.received:
        raise _STATE.make(_STATE.received[0])
