"""Progress displays: the callbacks the CLI passes into the library (spinner, bars).

:class:`Status` is a ``progress(text)`` callback, :class:`ProgressBar` a
``progress(done, total)`` one, :class:`FractionBar` a ``progress(message,
fraction)`` one; all on stderr and silent when it is not a terminal.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Optional

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console


class Status:
    """A spinner with a changing message on a terminal; silent otherwise.

    Used as ``with Status(console, text) as update: update("next step")``; ``update``
    is the ``progress(text)`` callback of :func:`fi_design.design` and
    :func:`fi_design.render_report`.
    """

    def __init__(self, console: "Console", text: str) -> None:
        self._console = console
        self._text = text
        self._live = None

    def __enter__(self):
        if self._console.is_terminal:
            self._live = self._console.status(self._text, spinner="dots")
            self._live.__enter__()
        return self.update

    def update(self, text: str) -> None:
        if self._live is not None:
            self._live.update(text)

    def __exit__(self, *exc) -> None:
        if self._live is not None:
            self._live.__exit__(*exc)


class ProgressBar:
    """A rich progress bar with ETA on stderr, fed by the library's ``progress(done, total)``."""

    def __init__(self, console: "Console", text: str) -> None:
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                                   TimeElapsedColumn, TimeRemainingColumn)

        self._progress = Progress(TextColumn("[progress.description]{task.description}"),
                                  BarColumn(), MofNCompleteColumn(), TextColumn("points"),
                                  TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                                  console=console, transient=False,
                                  disable=not console.is_terminal)
        self._task = self._progress.add_task(text, total=None)
        self._first: Optional[int] = None

    def __enter__(self) -> "ProgressBar":
        self._progress.__enter__()
        return self

    def __call__(self, done: int, total: int) -> None:
        if self._first is None:  # cached points arrive at once; the ETA counts the rest
            self._first = done
            self._progress.reset(self._task, total=total, completed=done)
            return
        self._progress.update(self._task, total=total, completed=done)

    def __exit__(self, *exc) -> None:
        self._progress.__exit__(*exc)


class FractionBar:
    """A rich progress bar on stderr fed by ``progress(message, fraction)``."""

    def __init__(self, console: "Console", text: str) -> None:
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        self._progress = Progress(TextColumn("{task.description}"), BarColumn(),
                                  TimeElapsedColumn(), console=console, transient=True,
                                  disable=not console.is_terminal)
        self._text = text
        self._task = self._progress.add_task(text, total=1.0)

    def __enter__(self) -> "FractionBar":
        self._progress.__enter__()
        return self

    def __call__(self, message: str, fraction: float) -> None:
        self._progress.update(self._task, completed=fraction,
                              description=f"{self._text}: {message}")

    def __exit__(self, *exc) -> None:
        self._progress.__exit__(*exc)
