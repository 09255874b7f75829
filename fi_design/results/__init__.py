"""The results layer: the values every workflow returns, and the one path to JSON.

Results are frozen dataclasses derived from :class:`Result`, with a docstring
per field (unit and shape). Array fields use ``eq=False`` dataclasses and are
copied and made read-only by :func:`frozen_array`. ``to_dict()`` turns a
result into plain JSON data (:func:`to_jsonable`: dataclasses to dicts, arrays
to lists, infinities and NaN to ``None``).

The result types live here, below the analyses that produce them, so that
presentation (report, plots, console) reads and dispatches on them without
importing an analysis: :mod:`.design` (the guideline and its confirmation),
:mod:`.simulation` (one simulation and its hunting metric) and :mod:`.studies`
(sweeps, the paper's maps, robustness). This module holds what they share:
:class:`Result`, :class:`Check` and the JSON helpers.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np


class Result:
    """Base of the result values: ``to_dict()`` is the one path to JSON.

    Subclasses are frozen dataclasses. ``to_dict()`` gives every field,
    converted by :func:`to_jsonable`, except those declared with
    ``field(repr=False)``: the spec and other inputs a result keeps, traces
    and cross-references that are not part of its JSON. A result whose JSON
    has another shape overrides ``to_dict``.
    """

    __slots__ = ()

    def to_dict(self) -> dict:
        """Plain JSON data (SI): every field shown in the repr.

        Returns
        -------
        dict
        """
        return dataclass_dict(self)


class Status(str, enum.Enum):
    """Outcome of a check."""

    PASS = "PASS"
    FAIL = "FAIL"
    WARN = "WARN"
    INFO = "INFO"


@dataclass(frozen=True)
class Check(Result):
    """One guideline check: data, not prose.

    Attributes
    ----------
    name : str
        Short identifier, e.g. ``"friction_gap"``.
    passed : bool or None
        True if the requirement holds, False if not, None for warnings and
        information that have no pass/fail meaning.
    value : float or None
        The computed quantity, in ``unit``.
    limit : float or None
        The requirement it is compared with, in ``unit``.
    unit : str
        Unit of ``value`` and ``limit`` (``"N"``, ``"Hz"``, ``"deg"``, ``"-"``).
    message : str
        One sentence a reviewer can read.
    step : str
        Where the check comes from: a guideline step or paper section.
    status : Status
        PASS, FAIL, WARN or INFO; derived from ``passed`` unless given.
    """

    name: str
    passed: bool | None
    value: float | None
    limit: float | None
    unit: str
    message: str
    step: str = ""
    status: Status | None = None

    def __post_init__(self) -> None:
        if self.status is None:
            st = Status.INFO if self.passed is None else (Status.PASS if self.passed else Status.FAIL)
            object.__setattr__(self, "status", st)


def frozen_array(values, dtype=float, copy: bool = True) -> np.ndarray:
    """Copy ``values`` into a new read-only array.

    ``copy=False`` hands over an array nobody else writes to (a trace the kernel
    has just filled): a read-only view of it, copied only to change its dtype.
    """
    if copy:
        arr = np.array(values, dtype=dtype, copy=True)
    elif type(values) is np.ndarray and values.dtype == dtype:  # asarray's layer skipped
        arr = values.view()
    else:
        arr = np.asarray(values, dtype).view()
    arr.flags.writeable = False
    return arr


def to_jsonable(obj: Any) -> Any:
    """Convert a result (dataclasses, arrays, enums, floats) to plain JSON data.

    Infinite and NaN floats become ``None`` (JSON has no infinity); numpy
    scalars become Python numbers; tuples become lists.
    """
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        if hasattr(obj, "to_dict"):
            return obj.to_dict()
        return dataclass_dict(obj)
    if isinstance(obj, enum.Enum):
        return obj.value
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [to_jsonable(v) for v in obj.tolist()]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else None
    if hasattr(obj, "model_dump"):  # pydantic spec sections
        return to_jsonable(obj.model_dump())
    return obj


def dataclass_dict(obj: Any, exclude: Callable[[Any], bool] | None = None) -> dict:
    """Field-by-field :func:`to_jsonable` of a dataclass.

    :meth:`Result.to_dict` is this; a result's own ``to_dict`` builds on it
    (calling :func:`to_jsonable` on itself would recurse). Fields declared
    with ``repr=False`` are left out.

    Parameters
    ----------
    obj : dataclass instance
        The result.
    exclude : callable, optional
        ``exclude(value)`` true leaves a field out *before* it is converted
        (a trace of millions of samples becomes millions of Python floats
        when converted: leave it out, do not convert it and drop it).

    Returns
    -------
    dict
    """
    out = {}
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if f.repr and not (exclude is not None and exclude(value)):
            out[f.name] = to_jsonable(value)
    return out
