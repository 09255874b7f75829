"""Exceptions of fi_design.

Every error the library raises on purpose derives from :class:`FiDesignError`.
The subclasses also inherit the matching builtin, so callers that catch
``ValueError`` or ``FileNotFoundError`` keep working. Spec errors carry the
dotted field path and, where known, the YAML line; data errors carry the
column and row. The command-line interface catches :class:`FiDesignError`
once and exits with code 2 and the message.
"""

from __future__ import annotations


class FiDesignError(Exception):
    """Base class of all errors raised by fi_design on bad input or bad use."""


class SpecError(FiDesignError, ValueError):
    """A spec value is missing, malformed, of the wrong dimension or unphysical.

    Parameters
    ----------
    message : str
        What is wrong, in words a user can act on.
    path : str, optional
        Dotted path of the offending field, e.g. ``"friction.static"`` or
        ``"motion.moves[1].distance"``.
    line : int, optional
        1-based line of the YAML file where the field is written.
    source : str, optional
        File name the spec was read from.
    """

    def __init__(self, message: str, path: str | None = None, line: int | None = None,
                 source: str | None = None) -> None:
        self.message = message
        self.path = path
        self.line = line
        self.source = source
        super().__init__(self._format())

    def _format(self) -> str:
        where = []
        if self.source:
            where.append(self.source + (f":{self.line}" if self.line else ""))
        elif self.line:
            where.append(f"line {self.line}")
        if self.path:
            where.append(self.path)
        prefix = ": ".join(where)
        return f"{prefix}: {self.message}" if prefix else self.message


class UnitError(SpecError):
    """A quantity cannot be parsed or has the wrong physical dimension."""


class SpecFileError(FiDesignError, OSError):
    """The spec file cannot be read: missing, a directory, not text."""


class DataError(FiDesignError, ValueError):
    """A measured-data file is malformed.

    Parameters
    ----------
    message : str
        What is wrong.
    column : str, optional
        The offending column header.
    row : int, optional
        1-based data row (the header is row 0).
    source : str, optional
        File name.
    """

    def __init__(self, message: str, column: str | None = None, row: int | None = None,
                 source: str | None = None) -> None:
        self.message = message
        self.column = column
        self.row = row
        self.source = source
        parts = [p for p in (source,
                             f"column '{column}'" if column else None,
                             f"row {row}" if row is not None else None) if p]
        super().__init__(": ".join(parts + [message]) if parts else message)


class ArgumentError(FiDesignError, ValueError):
    """A library function was called with an argument it refuses (a value outside the spec:
    a chunk size, a resolution, a method name)."""


class ReportError(FiDesignError, TypeError):
    """There is no report for this kind of result."""


class OutputError(FiDesignError, OSError):
    """An output path is refused (exists without --force, equals the spec, bad extension)."""


class CacheError(FiDesignError, OSError):
    """The result cache of the parameter studies cannot be opened, read or written."""


class SimulationError(FiDesignError, RuntimeError):
    """A simulation request cannot be run as asked (not an integration failure,
    which is reported inside the result)."""
