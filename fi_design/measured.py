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
in the first samples (:mod:`fi_design.simulation.run`).

Lines starting with ``#`` before the header are comments (e.g. how the trace
was recorded; one after the header is refused as such); blank lines are
skipped; other columns are ignored. Every value must be a plain number
in the unit of its header: a header with another unit (``position_mm``,
``time_ms``), a cell with a unit (``1.2 mm``), an empty cell, NaN or infinity,
a duplicate header, a time that does not increase, fewer than
:data:`MIN_SAMPLES` rows or an empty file are a :class:`~fi_design.errors.DataError`
that names the column and the 1-based data row (the header is row 0).

A file is read at numpy's speed into one array of its numbers (about 2 s and
16 bytes a value for a million rows of five columns); only a file numpy
refuses is read again cell by cell, to name the first bad cell.

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
from typing import IO, Mapping

import numpy as np

from .display import number, percent, plain, quantity
from .errors import ArgumentError, DataError
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
#: Spread of the time steps (a fraction of the median step) within which a record counts as
#: uniformly sampled with rounded time stamps (see Measurement.sample_period).
UNIFORM_JITTER = 0.01
#: Largest file accepted [bytes] (about 3 million rows of five columns).
MAX_BYTES = 300_000_000
#: A time step this many times the median step or more is a gap in the record (samples
#: missing), not jitter or a change of the logging rate (see :func:`check_time_steps`).
GAP_FACTOR = 5.0
#: A position step whose speed is this many times the fastest the record moves otherwise (at
#: the samples around it, and overall) is a jump, not motion (see :func:`check_position_steps`).
JUMP_FACTOR = 10.0
#: Samples on either side of a step that show how fast the record moves around it.
JUMP_WINDOW = 10
#: Share of the record's position steps slower than its typical fast motion (a quantile).
JUMP_QUANTILE = 0.99
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
        """Time step [s]: the mean step of a record whose steps agree within 1 %, else the median.

        The mean step, (last time - first time) / (samples - 1), is exact for a
        uniform record whatever the rounding of its time stamps: stamps in
        epoch seconds (1.7e9 s) carry 2.4e-7 s of float rounding, which moved
        the median step of a 10 kHz record by 0.1 %.
        """
        dt = np.diff(self.time)
        median = float(np.median(dt))
        if np.all(np.abs(dt - median) <= UNIFORM_JITTER * median):
            return float(self.time[-1] - self.time[0]) / (len(self.time) - 1)
        return median

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


def thinned(measurement: Measurement, step: int) -> Measurement:
    """Every ``step``-th sample of a record (the first kept), every column alike.

    Plain subsampling, no filter: every kept sample is a sample as
    recorded, with its sensor noise and its quantization (a low-pass would
    change both). For a record logged far faster than its dynamics.

    Parameters
    ----------
    measurement : Measurement
        The record.
    step : int
        Keep one sample in ``step`` (1: the record itself).

    Returns
    -------
    Measurement
    """
    if step == 1:
        return measurement
    cols = {name: getattr(measurement, attr)
            for name, attr in (("time_s", "time"), ("reference_m", "reference"),
                               ("position_m", "position"), ("force_N", "force"),
                               ("deflection_m", "deflection"), ("disturbance_N", "disturbance"))}
    return Measurement(**{attr: None if cols[name] is None else frozen_array(cols[name][::step])
                          for name, attr in (("time_s", "time"), ("reference_m", "reference"),
                                             ("position_m", "position"), ("force_N", "force"),
                                             ("deflection_m", "deflection"),
                                             ("disturbance_N", "disturbance"))},
                       source=measurement.source)


def check_time_steps(measured: Measurement, *, longest: float = 0.0, longest_is: str = "",
                     jitter: float | None = None, needs: str, parts: str) -> None:
    """Refuse a record with a gap in its time, or (with ``jitter``) one not sampled uniformly.

    One check for every command that reads a record: a replay (``fi-design simulate
    --record``, ``fi-design reconcile``) takes any sampling but not a gap, the
    identification needs uniform samples. A *gap* is a step of ``time_s`` of
    :data:`GAP_FACTOR` times the median step or more and longer than ``longest``:
    samples are missing there, and nothing is known of the stage in it.

    Parameters
    ----------
    measured : Measurement
        The record.
    longest : float
        A gap shorter than this [s] is accepted (0: every gap is refused).
    longest_is : str, optional
        What ``longest`` is, for the message (default its value).
    jitter : float, optional
        Refuse also a step that departs from the median step by more than this
        fraction of it (uniform sampling needed); None: any sampling but a gap.
    needs : str
        Why the caller cannot take the step, said in the message (a clause).
    parts : str
        What to do with each part either side of a gap (e.g. "replay each part on its
        own").

    Raises
    ------
    DataError
        The step, the rows either side of it, their times and the median step.
    """
    t = np.asarray(measured.time, dtype=float)
    dt = np.diff(t)
    med = float(np.median(dt))
    i = int(np.argmax(np.abs(dt - med)))
    step = float(dt[i])
    src = measured.source
    if step >= GAP_FACTOR * med and step > longest:
        beyond = (f" and longer than {longest_is or quantity(longest, 's', 3)}"
                  if longest > 0.0 else "")
        raise DataError(
            f"a gap in the record: no sample for {quantity(step, 's', 4)} between row {i + 1} "
            f"({quantity(t[i], 's', 9)}) and row {i + 2} ({quantity(t[i + 1], 's', 9)}), "
            f"{number(step / med, 3)} x the median step ({quantity(med, 's', 4)}){beyond}; "
            f"{needs}: do not interpolate across the gap; split the record at row {i + 2} "
            f"and {parts}", column="time_s", row=i + 2, source=src)
    if jitter is not None and abs(step - med) > jitter * med:
        raise DataError(
            f"non-uniform sampling: the step between rows {i + 1} and {i + 2} is "
            f"{quantity(step, 's', 6)}, the median step {quantity(med, 's', 6)} (at most "
            f"{percent(jitter, 2)} jitter is taken as uniform); {needs}: resample every "
            f"column onto a uniform grid first (e.g. numpy.interp onto t0 + k * "
            f"{plain(med, 6)} s, or scipy.signal.resample_poly for a rational rate change)",
            column="time_s", row=i + 2, source=src)


def check_position_steps(measured: Measurement) -> None:
    """Refuse a record whose position jumps: a step no motion of the record explains.

    An encoder that wraps, a counter re-zeroed in the record or a glitch moves
    ``position_m`` by a step in one sample that the stage did not make. A
    step counts as a jump when its speed (the step over its time step) is
    :data:`JUMP_FACTOR` times the fastest the record moves otherwise: the
    position's steps within :data:`JUMP_WINDOW` samples around it (the two
    steps beside it left out: a glitch of one sample steps back at once), the
    reference's steps there and anywhere in the record (the commanded motion:
    a stage that follows a step of its reference steps too), and the
    :data:`JUMP_QUANTILE` quantile of the position's speed over the whole
    record (its typical fast motion) and the median of its speeds that are not
    zero (a quantized record at rest steps by one count now and then). A motion
    that lasts three samples or more is never a jump, however fast: the record
    shows it.

    Parameters
    ----------
    measured : Measurement
        The record.

    Raises
    ------
    DataError
        The first jump: its rows and times, the step and the speed it would take
        beside the fastest the record moves otherwise.
    """
    from scipy.ndimage import maximum_filter1d

    t = np.asarray(measured.time, dtype=float)
    dt = np.diff(t)
    step = np.diff(np.asarray(measured.position, dtype=float))
    speed = np.abs(step) / dt
    ref = np.abs(np.diff(np.asarray(measured.reference, dtype=float))) / dt
    n, w = len(speed), JUMP_WINDOW
    side = w - 1  # the steps i - w .. i - 2 and i + 2 .. i + w
    before, after = np.zeros(n), np.zeros(n)
    if n > 2:
        ahead = maximum_filter1d(speed, side, mode="constant", cval=0.0, origin=(side - 1) // 2)
        before[2:] = ahead[:-2]  # ahead[j]: the largest of speed[j - side + 1 .. j]
        behind = maximum_filter1d(speed, side, mode="constant", cval=0.0, origin=-(side // 2))
        after[:-2] = behind[2:]  # behind[j]: the largest of speed[j .. j + side - 1]
    moving = speed[speed > 0.0]
    overall = max(float(np.max(ref)), float(np.quantile(speed, JUMP_QUANTILE)),
                  float(np.median(moving)) if len(moving) else 0.0)
    fastest = np.maximum.reduce([before, after, np.full(n, overall),
                                 maximum_filter1d(ref, 2 * w + 1, mode="constant", cval=0.0)])
    jumps = np.nonzero(speed > JUMP_FACTOR * fastest)[0]
    if len(jumps):
        i = int(jumps[0])
        raise DataError(
            f"a jump of the position: position_m steps by {quantity(step[i], 'm', 4)} between "
            f"row {i + 1} ({quantity(t[i], 's', 9)}) and row {i + 2} "
            f"({quantity(t[i + 1], 's', 9)}), a speed of {quantity(speed[i], 'm/s', 3)}, "
            f"{number(speed[i] / fastest[i], 3)} x the fastest the record moves otherwise "
            f"({quantity(fastest[i], 'm/s', 3)}): the stage did not make that step. An encoder "
            "that wraps, a counter re-zeroed during the record or a glitch gives such a step; "
            "remove it from position_m (unwrap the counter, or subtract the step from the rows "
            "after it) or use the record up to it", column="position_m", row=i + 2, source=
            measured.source)


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
            raise DataError(f"value {float(arr[bad[0]])!r} is not a finite number", column=name,
                            row=int(bad[0]) + 1, source=source)
        limit = PLAUSIBLE.get(name)
        if limit is not None:
            big = np.nonzero(np.abs(arr) > limit)[0]
            if len(big):
                raise DataError(f"value {number(arr[big[0]], 6)} is implausibly large for "
                                f"{UNITS[name]}: the column must hold SI values (e.g. mm / "
                                "1000)", column=name, row=int(big[0]) + 1, source=source)
    dt = np.diff(t)
    back = np.nonzero(dt <= 0)[0]
    if len(back):
        i = int(back[0]) + 1
        raise DataError(f"time does not increase: {quantity(t[i], 's', 9)} after "
                        f"{quantity(t[i - 1], 's', 9)}",
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
    ArgumentError
        ``path`` is no path (None, a number, bytes, a table), or is the CSV
        text itself rather than a path to it.

    Examples
    --------
    >>> from fi_design.measured import load_measurement
    >>> m = load_measurement("examples/measured_trace.csv")
    >>> m.columns
    ('time_s', 'reference_m', 'position_m', 'force_N', 'deflection_m')
    """
    if not isinstance(path, (str, os.PathLike)):
        raise ArgumentError("path must be the path of a CSV file (a str or os.PathLike), got "
                            + type(path).__name__ + _FROM_ARRAYS)
    if isinstance(path, str) and ("\n" in path or "\r" in path):
        first = path.strip().splitlines()[0] if path.strip() else ""
        shown = first if len(first) <= 40 else first[:37] + "..."
        raise ArgumentError(f"path looks like CSV text ({shown!r}), not a path: load_measurement "
                            "takes the path of a CSV file; write the text to a file"
                            + _FROM_ARRAYS)
    p = Path(path)
    src = str(p)
    try:
        exists = p.exists()
    except OSError as exc:  # a name too long for the file system
        raise DataError(f"cannot read ({exc.strerror})", source=src) from None
    if not exists:
        raise DataError("no such file", source=src)
    if p.is_dir():
        raise DataError("is a directory, expected a CSV file", source=src)
    size = p.stat().st_size
    if size > MAX_BYTES:
        raise DataError(f"{size} bytes is too large (limit {MAX_BYTES})", source=src)
    try:
        with open(p, encoding="utf-8-sig", newline="") as fh:
            header, delimiter = _header(fh, src)
            index = _columns(header, src)
            arrays = _read_fast(fh, header, index, delimiter)
            if arrays is None:  # a cell or row numpy refuses: find it, and say which
                fh.seek(0)
                _header(fh, src)
                arrays = _read_exact(fh, header, index, delimiter, src)
    except UnicodeDecodeError:
        raise _not_utf8(p, src) from None
    except OSError as exc:
        raise DataError(f"cannot read ({exc.strerror})", source=src) from None
    return _checked(arrays, src)


#: How a record held in arrays becomes a Measurement, for the messages of load_measurement.
_FROM_ARRAYS = (" (a record held in arrays: fi_design.measured.measurement_from_arrays(time_s, "
                "reference_m, position_m, ...))")


def _not_utf8(path: Path, source: str) -> DataError:
    """What a file that is not UTF-8 is: binary (a NUL byte in its first 64 kB), else text in
    another encoding, with the first line that is not UTF-8."""
    with open(path, "rb") as fh:
        if b"\x00" in fh.read(65536):
            return DataError("not a text file (expected UTF-8 CSV)", source=source)
        fh.seek(0)
        for n, line in enumerate(fh, start=1):
            try:
                line.decode("utf-8")
            except UnicodeDecodeError as exc:
                byte = line[exc.start]
                return DataError(f"line {n}: text in another encoding than UTF-8 (byte "
                                 f"{hex(byte)}; Latin-1 or Windows-1252, as some loggers and "
                                 "spreadsheets write, perhaps): save the file as UTF-8",
                                 source=source)
    return DataError("not a text file (expected UTF-8 CSV)", source=source)


def _header(fh: IO[str], source: str) -> tuple[list[str], str]:
    """Skip the comment lines, read the header row; the file is left at the first data row."""
    for line in iter(fh.readline, ""):
        if line.strip() and not line.lstrip().startswith("#"):
            break
    else:
        raise DataError("empty file: no header row", source=source)
    delimiter = ";" if line.count(";") > line.count(",") else ("\t" if "\t" in line
                                                                and "," not in line else ",")
    header = [h.strip() for h in next(csv.reader([line], delimiter=delimiter))]
    if len(header) == 1 and len(header[0].split()) > 1:
        raise DataError(f"the header {header[0]!r} is one field: columns separated by spaces "
                        "are not read; separate them by commas, ';' or tabs", row=0,
                        source=source)
    return header, delimiter


def _read_fast(fh: IO[str], header: list[str], index: dict[str, int],
               delimiter: str) -> dict | None:
    """Every column at numpy's speed, about 16 bytes a value; None where a cell is not a plain
    number or a row has another number of fields (then :func:`_read_exact` says which)."""
    import warnings

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "input contained no data"
            data = np.loadtxt(fh, delimiter=delimiter, ndmin=2, dtype=float, comments=None,
                              quotechar='"')
    except ValueError:
        return None
    if data.shape[0] == 0 or data.shape[1] != len(header):
        return None
    arrays: dict[str, np.ndarray | None] = {name: None for name in REQUIRED + OPTIONAL}
    for name, col in index.items():
        arrays[name] = np.ascontiguousarray(data[:, col])
    return arrays


def _read_exact(fh: IO[str], header: list[str], index: dict[str, int], delimiter: str,
                source: str) -> dict:
    """Row by row, cell by cell (slow), naming the first bad cell's column and row.

    Streams: it keeps the numbers of the known columns, never the text.
    """
    from array import array

    columns = {name: array("d") for name in index}
    n = 0
    for row in csv.reader(fh, delimiter=delimiter):
        if not any(c.strip() for c in row):
            continue  # blank lines are skipped, as by the fast reader
        n += 1
        if row[0].lstrip().startswith("#"):
            raise DataError("a comment line after the header: '#' lines are comments only before "
                            "the header row; move it above the header or delete it", row=n,
                            source=source)
        if len(row) != len(header):
            raise DataError(f"has {len(row)} field(s), the header has {len(header)}", row=n,
                            source=source)
        for name, col in index.items():
            columns[name].append(_number(row[col], name, n, source))
    if n == 0:
        raise DataError("no data rows after the header", source=source)
    arrays: dict[str, np.ndarray | None] = {name: None for name in REQUIRED + OPTIONAL}
    for name, values in columns.items():
        arrays[name] = np.frombuffer(values, dtype=float).copy()
    return arrays


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
    for j in seen.values():
        _neighbour(header[j], index, source)
    for name in REQUIRED:
        if name not in index:
            hint = ("; this is a YAML file (a spec?), not a measured record, which is CSV"
                    if Path(source).suffix.lower() in (".yaml", ".yml") else "")
            raise DataError("required column is missing; the header must name "
                            f"{', '.join(REQUIRED)} (found {', '.join(repr(h) for h in header)})"
                            + hint, column=name, source=source)
    return index


#: A header with its unit in brackets or parentheses: ``time [s]``, ``position_m (m)``.
_BRACKETED = re.compile(r"^(.*?)\s*[\[(]\s*([^\])]*?)\s*[\])]$")


def _neighbour(text: str, index: dict[str, int], source: str) -> None:
    """Refuse a header that names a column of the layout in another form (``position_mm``,
    ``pos_m``, ``time [s]``), saying the name to give; other headers are other columns."""
    bracket = _BRACKETED.match(text)
    name, shown = (bracket.group(1), bracket.group(2)) if bracket else (text, None)
    key = name.lower()
    base, _, unit = key.partition("_")
    want = _BASES.get(base) or next((c for c in UNITS if c.lower() == key), None)
    if want is None or want in index:
        return
    si = UNITS[want]
    if shown is not None:  # the unit in brackets: the layout has it in the name
        if shown.lower() in (si.lower(), unit) or not shown:
            raise DataError(f"the unit goes into the name, after an underscore: give the column "
                            f"as '{want}' (in {si}, SI) without '{text[len(name):].strip()}'",
                            column=text, source=source)
        raise DataError(f"unit '{shown}' is not accepted: give the column as '{want}' in {si} "
                        f"(SI)", column=text, source=source)
    if key == want.lower():
        return
    if unit == si.lower():  # the unit is right, the name is not the layout's
        raise DataError(f"not a column name of the layout: give the column as '{want}' (the "
                        f"layout's names: {', '.join(REQUIRED + OPTIONAL)})", column=text,
                        source=source)
    if unit:
        raise DataError(f"unit '{text.partition('_')[2]}' is not accepted: give the column as "
                        f"'{want}' in {si} (SI)", column=text, source=source)
    raise DataError(f"no unit in the header: give the column as '{want}' in {si} (SI)",
                    column=text, source=source)


_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def _number(cell: str, column: str, row: int, source: str) -> float:
    text = cell.strip()
    if not text:
        raise DataError("empty cell", column=column, row=row, source=source)
    if not _NUMBER.match(text):
        if text.lower() in ("nan", "inf", "+inf", "-inf", "infinity", "-infinity"):
            raise DataError(f"value {text!r} is not a finite number", column=column, row=row,
                            source=source)
        if re.match(r"^[+-]?[\d.]+([eE][+-]?\d+)?\s*[A-Za-zµ](?:[^\d^]|\^-?\d)*$", text):  # not 0x10
            raise DataError(f"value {text!r} carries a unit: write plain SI numbers "
                            f"({UNITS[column]})", column=column, row=row, source=source)
        if re.match(r"^[+-]?\d*,\d+([eE][+-]?\d+)?$", text):
            raise DataError(f"value {text!r} has a decimal comma: write {text.replace(',', '.')!r} "
                            "(the file's separator may be ';' or a tab, the decimal sign is a "
                            "point)", column=column, row=row, source=source)
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
    write_columns_csv(out, columns, comment)
    return out.getvalue()


#: Rows written at a time by :func:`write_columns_csv`.
CHUNK_ROWS = 65_536


def write_columns_csv(fh: IO[str], columns: Mapping[str, np.ndarray],
                      comment: str | None = None) -> None:
    """Write :func:`columns_csv`'s text to an open file, a chunk of rows at a time.

    Memory stays at one chunk of text (a record of millions of rows is not
    held as one string).

    Parameters
    ----------
    fh : text file
        Where to write.
    columns : mapping of str to ndarray
        Header to values (SI), in order, of equal length.
    comment : str, optional
        Lines written before the header, each prefixed with ``# ``.
    """
    if comment:
        for line in comment.splitlines():
            fh.write(f"# {line}\n")
    fh.write(",".join(columns) + "\n")
    values = [np.asarray(v, dtype=float) for v in columns.values()]
    n = len(values[0]) if values else 0
    for start in range(0, n, CHUNK_ROWS):
        block = np.column_stack([v[start:start + CHUNK_ROWS] for v in values])
        np.savetxt(fh, block, delimiter=",", fmt="%.10g")