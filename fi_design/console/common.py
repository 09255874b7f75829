"""What every console summary shares: the console, compact tables, status colours, headings.

rich is imported inside the functions, so ``fi-design --help`` stays fast.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console

#: Style of each check status in the tables.
_STYLES = {"PASS": "bold green", "FAIL": "bold red", "WARN": "bold yellow", "INFO": "cyan"}


def make_console(stderr: bool = False) -> "Console":
    """A rich console; wide enough for the tables when output is not a terminal.

    Parameters
    ----------
    stderr : bool, optional
        Print to standard error (progress displays) instead of standard output.

    Returns
    -------
    rich.console.Console
    """
    from rich.console import Console

    console = Console(stderr=stderr, highlight=False)
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = Console(stderr=stderr, highlight=False, width=120)
    return console


def table(title: str | None = None, **options: Any):
    """A compact rich table: simple head rule, one space between columns, title on the left."""
    from rich import box
    from rich.table import Table

    return Table(title=title, title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False,
                 collapse_padding=True, **options)


def status_text(status: Any):
    """A check's status (``PASS``, ``FAIL``, ``WARN``, ``INFO``) as coloured rich text."""
    from rich.text import Text

    name = getattr(status, "value", status)
    name = str(name) if name is not None else "INFO"
    return Text(name, style=_STYLES.get(name, ""))


def heading(console: "Console", text: str, spec_path: Optional[Path]) -> None:
    """A summary's bold first line, with the spec file dimmed beside it."""
    from rich.text import Text

    head = Text(text, style="bold")
    if spec_path is not None:
        head.append(f"  ({spec_path})", style="dim")
    console.print(head)
