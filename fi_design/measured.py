"""Measured traces from the real stage (the CSV layout: docs/interfaces.md).

A measurement is a CSV file with a header row; columns are found by their
header, in any order:

============== ====== ======== =====================================================
column         unit   required meaning
============== ====== ======== =====================================================
time_s         s      yes      sample time, strictly increasing (uniform or not)
reference_m    m      yes      the controller's reference r
position_m     m      yes      the measured stage position x1 (what the controller saw)
force_N        N      no       commanded actuator force u, before delay or saturation
deflection_m   m      no       joint deflection x1 - x2 (isolated stages)
disturbance_N  N      no       known force injected at the actuator by the experiment
============== ====== ======== =====================================================

``force_N`` is the total force command the actuator received, an injected
disturbance included; the controller's own output is ``force_N -
disturbance_N``. A record may start in motion: replays start from the state
in the first samples (:mod:`fi_design.simulation`).

Lines starting with ``#`` before the header are comments (e.g. how the trace
was recorded); other columns are ignored. Every value must be a plain number
in the unit of its header: a header with another unit (``position_mm``,
``time_ms``), a cell with a unit (``1.2 mm``), an empty cell, NaN or infinity,
a duplicate header, a time that does not increase, fewer than
:data:`MIN_SAMPLES` rows or an empty file are a :class:`~fi_design.errors.DataError`
that names the column and the 1-based data row (the header is row 0).

:func:`load_measurement` reads a file; :func:`measurement_from_arrays` applies
the same checks to arrays (scripts, tests).
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from .errors import DataError
from .results import dataclass_dict, frozen_array

#: Required columns, in the order of the layout.
REQUIRED = ("time_s", "reference_m", "position_m")
#: Optional columns.
OPTIONAL = ("force_N", "deflection_m", "disturbance_N")
#: Unit of every known column.
UNITS = {"time_s": "s", "reference_m": "m", "position_m": "m", "force_N": "N",
         "deflection_m": "m", "disturbance_N": "N"}
#: Fewest samples accepted.
MIN_SAMPLES = 20
#: Largest file accepted [bytes] (about 3 million rows of five columns).
MAX_BYTES = 300_000_000
#: Magnitudes above these are taken as a wrong unit (e.g. mm written into a _m column).
PLAUSIBLE = {"reference_m": 10.0, "position_m": 10.0, "deflection_m": 0.1, "force_N": 1e6,
             "disturbance_N": 1e6}

_BASES = {"time": "time_s", "t": "time_s", "reference": "reference_m", "ref": "reference_m",
          "position": "position_m", "pos": "position_m", "force": "force_N",
          "deflection": "deflection_m", "disturbance": "disturbance_N"}


@dataclass(frozen=True, eq=False)
class Measurement:
    """A measured trace, validated, SI.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times [s] as recorded, strictly increasing.
    reference : ndarray, shape (n,)
        Reference r [m].
    position : ndarray, shape (n,)
        Measured stage position x1 [m].
    force : ndarray, shape (n,), or None
        Commanded actuator force u [N], when recorded.
    deflection : ndarray, shape (n,), or None
        Joint deflection x1 - x2 [m], when recorded.
    disturbance : ndarray, shape (n,), or None
        Known force injected at the actuator by the experiment [N], when
        recorded; included in ``force``.
    source : str or None
        File the trace was read from.
    """

    time: np.ndarray
    reference: np.ndarray
    position: np.ndarray
    force: np.ndarray | None = None
    deflection: np.ndarray | None = None
    disturbance: np.ndarray | None = None
    source: str | None = None

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(len(self.time))

    @property
    def duration(self) -> float:
        """Recorded time span [s]."""
        return float(self.time[-1] - self.time[0])

    @property
    def sample_period(self) -> float:
        """Median time step [s]."""
        return float(np.median(np.diff(self.time)))

    @property
    def uniform(self) -> bool:
        """Whether the samples are evenly spaced (within 1e-6 of the median step)."""
        dt = np.diff(self.time)
        return bool(np.all(np.abs(dt - np.median(dt)) <= 1e-6 * np.median(dt) + 1e-12))

    @property
    def columns(self) -> tuple[str, ...]:
        """Columns present, in the layout's order."""
        out = list(REQUIRED)
        if self.force is not None:
            out.append("force_N")
        if self.deflection is not None:
            out.append("deflection_m")
        if self.disturbance is not None:
            out.append("disturbance_N")
        return tuple(out)

    def to_dict(self, traces: bool = False) -> dict:
        """Plain JSON data: source, columns, sampling; the traces only when asked."""
        d = {"source": self.source, "columns": list(self.columns), "n": self.n,
             "duration": self.duration, "sample_period": self.sample_period,
             "uniform": self.uniform}
        if traces:
            d.update({k: v for k, v in dataclass_dict(self).items() if isinstance(v, list)})
        return d


def measurement_from_arrays(time_s, reference_m, position_m, force_N=None, deflection_m=None,
                            disturbance_N=None, source: str | None = None) -> Measurement:
    """Build a :class:`Measurement` from arrays, with the checks of :func:`load_measurement`.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Sample times [s], strictly increasing.
    reference_m : array_like, shape (n,)
        Reference [m].
    position_m : array_like, shape (n,)
        Measured stage position [m].
    force_N : array_like, shape (n,), optional
        Commanded actuator force [N].
    deflection_m : array_like, shape (n,), optional
        Joint deflection [m].
    disturbance_N : array_like, shape (n,), optional
        Known force injected at the actuator [N] (part of ``force_N``).
    source : str, optional
        Where the data came from (used in error messages).

    Returns
    -------
    Measurement

    Raises
    ------
    DataError
        A column is missing, of the wrong length, not finite, implausibly large
        for its unit, too short, or the time does not increase.
    """
    cols = {"time_s": time_s, "reference_m": reference_m, "position_m": position_m,
            "force_N": force_N, "deflection_m": deflection_m, "disturbance_N": disturbance_N}
    arrays: dict[str, np.ndarray | None] = {}
    n = None
    for name, values in cols.items():
        if values is None:
            if name in REQUIRED:
                raise DataError("required column is missing", column=name, source=source)
            arrays[name] = None
            continue
        try:
            arr = np.asarray(values, dtype=float).ravel()
        except (TypeError, ValueError):
            raise DataError("values are not numbers", column=name, source=source) from None
        if n is None:
            n = len(arr)
        elif len(arr) != n:
            raise DataError(f"has {len(arr)} values, time_s has {n}", column=name, source=source)
        arrays[name] = arr
    return _checked(arrays, source)


def _checked(arrays: dict, source: str | None) -> Measurement:
    t = arrays["time_s"]
    n = len(t)
    if n < MIN_SAMPLES:
        raise DataError(f"too short: {n} sample(s), at least {MIN_SAMPLES} needed",
                        column="time_s", source=source)
    for name, arr in arrays.items():
        if arr is None:
            continue
        bad = np.nonzero(~np.isfinite(arr))[0]
        if len(bad):
            raise DataError(f"value {arr[bad[0]]!r} is not a finite number", column=name,
                            row=int(bad[0]) + 1, source=source)
        limit = PLAUSIBLE.get(name)
        if limit is not None:
            big = np.nonzero(np.abs(arr) > limit)[0]
            if len(big):
                raise DataError(f"value {arr[big[0]]:g} is implausibly large for {UNITS[name]}: "
                                f"the column must hold SI values (e.g. mm / 1000)", column=name,
                                row=int(big[0]) + 1, source=source)
    dt = np.diff(t)
    back = np.nonzero(dt <= 0)[0]
    if len(back):
        i = int(back[0]) + 1
        raise DataError(f"time does not increase: {t[i]:.9g} s after {t[i - 1]:.9g} s",
                        column="time_s", row=i + 1, source=source)
    return Measurement(time=frozen_array(t), reference=frozen_array(arrays["reference_m"]),
                       position=frozen_array(arrays["position_m"]),
                       force=None if arrays.get("force_N") is None else
                       frozen_array(arrays["force_N"]),
                       deflection=None if arrays.get("deflection_m") is None else
                       frozen_array(arrays["deflection_m"]),
                       disturbance=None if arrays.get("disturbance_N") is None else
                       frozen_array(arrays["disturbance_N"]),
                       source=source)


def load_measurement(path: str | os.PathLike) -> Measurement:
    """Read and check a measured trace (CSV, docs/interfaces.md).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file. Columns by header: ``time_s``, ``reference_m``,
        ``position_m`` required; ``force_N``, ``deflection_m`` and
        ``disturbance_N`` optional;
        other columns are ignored; ``#`` lines before the header are comments.

    Returns
    -------
    Measurement
        The trace in SI units.

    Raises
    ------
    DataError
        The file is missing, empty or unreadable, or a column or row is wrong
        (missing or duplicate column, a header with another unit, a cell that is
        not a plain number, NaN, a time that does not increase, too few rows);
        the message names the file, column and 1-based data row.

    Examples
    --------
    >>> from fi_design.measured import load_measurement
    >>> m = load_measurement("examples/measured_trace.csv")
    >>> m.columns
    ('time_s', 'reference_m', 'position_m', 'force_N', 'deflection_m')
    """
    p = Path(path)
    src = str(p)
    if not p.exists():
        raise DataError("no such file", source=src)
    if p.is_dir():
        raise DataError("is a directory, expected a CSV file", source=src)
    size = p.stat().st_size
    if size > MAX_BYTES:
        raise DataError(f"{size} bytes is too large (limit {MAX_BYTES})", source=src)
    try:
        text = p.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError:
        raise DataError("not a text file (expected UTF-8 CSV)", source=src) from None
    except OSError as exc:
        raise DataError(f"cannot read ({exc.strerror})", source=src) from None
    return _parse(text, src)


def _parse(text: str, source: str) -> Measurement:
    lines = text.splitlines()
    skip = 0
    while skip < len(lines) and (not lines[skip].strip() or lines[skip].lstrip().startswith("#")):
        skip += 1
    if skip >= len(lines):
        raise DataError("empty file: no header row", source=source)
    body = "\n".join(lines[skip:])
    sample = lines[skip]
    delimiter = ";" if sample.count(";") > sample.count(",") else ("\t" if "\t" in sample
                                                                    and "," not in sample else ",")
    reader = csv.reader(io.StringIO(body), delimiter=delimiter)
    header = [h.strip() for h in next(reader)]
    index = _columns(header, source)
    rows = [r for r in reader]
    while rows and not any(c.strip() for c in rows[-1]):
        rows.pop()  # trailing blank lines
    if not rows:
        raise DataError("no data rows after the header", source=source)
    arrays: dict[str, np.ndarray | None] = {name: None for name in REQUIRED + OPTIONAL}
    for name, col in index.items():
        arrays[name] = np.empty(len(rows))
    for i, row in enumerate(rows, start=1):
        if len(row) != len(header):
            if not any(c.strip() for c in row):
                raise DataError("empty row", row=i, source=source)
            raise DataError(f"has {len(row)} field(s), the header has {len(header)}", row=i,
                            source=source)
        for name, col in index.items():
            arrays[name][i - 1] = _number(row[col], name, i, source)
    return _checked(arrays, source)


def _columns(header: list[str], source: str) -> dict[str, int]:
    """Column index of every known column; headers match case-insensitively."""
    seen: dict[str, int] = {}
    for j, h in enumerate(header):
        if not h:
            continue
        key = h.lower()
        if key in seen:
            raise DataError(f"duplicate header (columns {seen[key] + 1} and {j + 1})", column=h,
                            source=source)
        seen[key] = j
    index = {name: seen[name.lower()] for name in REQUIRED + OPTIONAL if name.lower() in seen}
    for key, j in seen.items():
        base, _, unit = key.partition("_")
        want = _BASES.get(base)
        if want is not None and want not in index and key != want.lower():
            if unit:
                raise DataError(f"unit '{header[j].partition('_')[2]}' is not accepted: give the "
                                f"column as '{want}' in {UNITS[want]} (SI)", column=header[j],
                                source=source)
            raise DataError(f"no unit in the header: give the column as '{want}' in "
                            f"{UNITS[want]} (SI)", column=header[j], source=source)
    for name in REQUIRED:
        if name not in index:
            raise DataError("required column is missing; the header must name "
                            f"{', '.join(REQUIRED)} (found {', '.join(repr(h) for h in header)})",
                            column=name, source=source)
    return index


_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def _number(cell: str, column: str, row: int, source: str) -> float:
    text = cell.strip()
    if not text:
        raise DataError("empty cell", column=column, row=row, source=source)
    if not _NUMBER.match(text):
        if text.lower() in ("nan", "inf", "+inf", "-inf", "infinity", "-infinity"):
            raise DataError(f"value {text!r} is not a finite number", column=column, row=row,
                            source=source)
        if re.match(r"^[+-]?[\d.]+([eE][+-]?\d+)?\s*[A-Za-z]", text):
            raise DataError(f"value {text!r} carries a unit: write plain SI numbers "
                            f"({UNITS[column]})", column=column, row=row, source=source)
        raise DataError(f"value {text!r} is not a number", column=column, row=row, source=source)
    value = float(text)
    if not math.isfinite(value):
        raise DataError(f"value {text!r} is not a finite number", column=column, row=row,
                        source=source)
    return value


def to_csv_text(measurement: Measurement, comment: str | None = None) -> str:
    """The CSV text of a measurement in the layout of :func:`load_measurement`.

    Parameters
    ----------
    measurement : Measurement
        The trace.
    comment : str, optional
        Lines written before the header, each prefixed with ``# ``.
    """
    cols = {"time_s": measurement.time, "reference_m": measurement.reference,
            "position_m": measurement.position}
    if measurement.force is not None:
        cols["force_N"] = measurement.force
    if measurement.deflection is not None:
        cols["deflection_m"] = measurement.deflection
    if measurement.disturbance is not None:
        cols["disturbance_N"] = measurement.disturbance
    return columns_csv(cols, comment)


def columns_csv(columns: Mapping[str, np.ndarray], comment: str | None = None) -> str:
    """CSV text of equal-length columns in the measured-data layout, header first.

    Parameters
    ----------
    columns : mapping of str to ndarray
        Header (``time_s``, ``position_m``, ...) to values (SI), in order.
    comment : str, optional
        Lines written before the header, each prefixed with ``# ``.
    """
    out = io.StringIO()
    if comment:
        for line in comment.splitlines():
            out.write(f"# {line}\n")
    out.write(",".join(columns) + "\n")
    data = np.column_stack([np.asarray(v, dtype=float) for v in columns.values()])
    np.savetxt(out, data, delimiter=",", fmt="%.10g")
    return out.getvalue()