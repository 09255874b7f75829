"""Checks of the values a :class:`~fi_design.model.Model` is varied with, and the kernel's
fields of the drive's filter chain.

A value that does not fit is refused with a :class:`~fi_design.errors.SpecError` naming its
spec path, as the spec itself would refuse it.
"""

from __future__ import annotations

import math
from typing import Any

from .. import spec as _spec
from ..display import quantity, unit_text
from ..errors import SpecError
from ..results.controller import Filter

__all__ = ["finite", "positive", "filter_fields", "checked_filters", "checked_effects"]
def finite(value, path: str, unit: str) -> float:
    """``value`` as a finite float, else a SpecError naming ``path`` and ``unit``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SpecError(f"expected a number [{unit_text(unit)}], got {value!r}",
                        path=path) from None
    if not math.isfinite(x):
        raise SpecError(f"must be a finite number [{unit_text(unit)}], got {value!r}", path=path)
    return x


def positive(value, path: str, unit: str) -> float:
    """``value`` as a float above 0, else a SpecError naming ``path`` and ``unit``."""
    x = finite(value, path, unit)
    if not x > 0.0:
        raise SpecError(f"must be greater than 0 {unit}, got {value!r}", path=path)
    return x


def filter_fields(filters, period: float) -> dict[str, float]:
    """The kernel's fields of the drive's filter chain (:class:`~fi_design.kernel.layout.PlantParameters`).

    Each filter a section: its polynomials in s, ``(b0 s^2 + b1 s + b2) / (s^2 + a1 s + a2)``
    or ``(b0 s + b1) / (s + a1)``, and, for a sampled controller (``period`` [s] > 0), the
    biquad the drive computes (:func:`fi_design.controller.tustin_biquad`).
    """
    from ..controller import filter_polynomials, tustin_biquad
    from ..kernel.layout import MAX_FILTER_SECTIONS

    if len(filters) > MAX_FILTER_SECTIONS:
        raise SpecError(f"at most {MAX_FILTER_SECTIONS} filters, got {len(filters)}",
                        path="controller.filters")
    out: dict[str, float] = {"filter_states": float(sum(f.order for f in filters))}
    for i, f in enumerate(filters):
        num, den = filter_polynomials(f)
        num = [0.0] * (len(den) - len(num)) + [float(x) for x in num]
        if f.order == 2:
            b0, b1, b2 = num
            a1, a2 = float(den[1]), float(den[2])
        else:
            (b0, b1), b2, a1, a2 = num, 0.0, float(den[1]), 0.0
        out.update({f"f{i}_order": float(f.order), f"f{i}_b0": b0, f"f{i}_b1": b1,
                    f"f{i}_b2": b2, f"f{i}_a1": a1, f"f{i}_a2": a2})
        if period > 0.0:
            b, a = tustin_biquad(f, period)
            b = list(b) + [0.0] * (3 - len(b))
            a = list(a) + [0.0] * (3 - len(a))
            out.update({f"f{i}_z0": float(b[0]), f"f{i}_z1": float(b[1]), f"f{i}_z2": float(b[2]),
                        f"f{i}_p1": float(a[1]), f"f{i}_p2": float(a[2])})
    return out


def checked_filters(filters, period: float) -> tuple:
    """The drive's filters, each a :class:`Filter` below the Nyquist frequency of ``period`` [s]."""
    out = tuple(filters)
    for i, f in enumerate(out):
        if not isinstance(f, Filter):
            raise SpecError(f"expected a Filter, got {type(f).__name__}",
                            path=f"controller.filters[{i}]")
        if not (f.frequency > 0.0 and math.isfinite(f.frequency)):
            raise SpecError(f"frequency must be a positive number [Hz], got {f.frequency!r}",
                            path=f"controller.filters[{i}].frequency")
        if period > 0.0 and f.frequency >= 0.5 / period:
            raise SpecError(f"{quantity(f.frequency, 'Hz', 6)} lies at or above the Nyquist "
                            f"frequency {quantity(0.5 / period, 'Hz', 6)}",
                            path=f"controller.filters[{i}].frequency")
    return out


def checked_effects(entries, joint: Any) -> tuple:
    """Validated effect entries (``joint_damping`` only with an isolator: ``joint`` not None)."""
    out = tuple(entries)
    known = tuple(_spec.EFFECT_MODELS.values())
    for i, e in enumerate(out):
        if not isinstance(e, known):
            raise SpecError(f"expected a validated effect entry, got {type(e).__name__}",
                            path=f"effects[{i}]")
    if any(e.type == "joint_damping" for e in out) and joint is None:
        raise SpecError("effect joint_damping needs an isolator", path="effects")
    return out
