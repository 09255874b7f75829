"""The drive's filters: polynomials in s, and biquads by the prewarped Tustin rule.

Each :class:`~fi_design.results.controller.Filter` has unit DC gain, ``w = 2 pi
frequency``:

- notch: ``(s^2 + 2 zeta_zero w s + w^2) / (s^2 + 2 zeta_pole w s + w^2)``;
- low-pass, order 1: ``w / (s + w)``; order 2: ``w^2 / (s^2 + 2 zeta_pole w s + w^2)``.

Sampled with period T, a drive computes each filter as a biquad. The choice
here is the one drives make: the bilinear (Tustin) rule prewarped at the
filter's own frequency, ``s = K (z - 1)/(z + 1)`` with ``K = w / tan(w T / 2)``,
so that a notch's centre and a low-pass's corner stay where the spec puts
them (the plain Tustin rule, ``K = 2 / T``, moves them down by the
frequency warping ``tan``). This is python-control's ``c2d(sys, T,
"tustin", prewarp_frequency=w)``.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..results.controller import Filter

__all__ = ["filter_polynomials", "chain_polynomials", "bilinear", "tustin_biquad"]


def filter_polynomials(f: Filter) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of one filter in s.

    Parameters
    ----------
    f : Filter
        A notch or a low-pass.

    Returns
    -------
    num, den : numpy.ndarray
        Descending powers of s [rad/s]; unit DC gain.
    """
    w = 2.0 * math.pi * f.frequency
    if f.kind == "notch":
        return (np.array([1.0, 2.0 * f.zeta_zero * w, w * w]),
                np.array([1.0, 2.0 * f.zeta_pole * w, w * w]))
    if f.order == 1:
        return np.array([w]), np.array([1.0, w])
    return np.array([w * w]), np.array([1.0, 2.0 * f.zeta_pole * w, w * w])


def chain_polynomials(filters: Sequence[Filter]) -> tuple[np.ndarray, np.ndarray]:
    """The filter chain in series, as one numerator and denominator in s.

    Parameters
    ----------
    filters : sequence of Filter
        The chain (empty: 1).

    Returns
    -------
    num, den : numpy.ndarray
        Descending powers of s [rad/s].
    """
    num, den = np.array([1.0]), np.array([1.0])
    for f in filters:
        n, d = filter_polynomials(f)
        num, den = np.polymul(num, n), np.polymul(den, d)
    return num, den


def bilinear(num: Sequence[float], den: Sequence[float],
             K: float) -> tuple[np.ndarray, np.ndarray]:
    """A proper transfer function in s mapped by ``s = K (z - 1)/(z + 1)``.

    Parameters
    ----------
    num, den : array_like
        Descending powers of s, ``len(num) <= len(den)``.
    K : float
        The map's constant [rad/s]: ``2 / T`` (Tustin) or ``w / tan(w T / 2)``
        (prewarped at w).

    Returns
    -------
    b, a : numpy.ndarray
        Descending powers of z, equally long, ``a[0] == 1``: the coefficients
        of ``y_k = b0 x_k + b1 x_{k-1} + ... - a1 y_{k-1} - ...`` (as
        :func:`scipy.signal.lfilter` takes them).
    """
    num, den = np.atleast_1d(np.asarray(num, float)), np.atleast_1d(np.asarray(den, float))
    n = len(den) - 1

    def mapped(p: np.ndarray) -> np.ndarray:
        out = np.zeros(n + 1)
        deg = len(p) - 1
        for i, c in enumerate(p):  # c s^(deg - i)
            k = deg - i
            term = c * K ** k * np.polymul(np.poly(np.ones(k)) if k else [1.0],
                                           np.poly(-np.ones(n - k)) if n - k else [1.0])
            out += term
        return out

    b, a = mapped(num), mapped(den)
    return b / a[0], a / a[0]


def tustin_biquad(f: Filter, period: float) -> tuple[np.ndarray, np.ndarray]:
    """One filter sampled by the Tustin rule prewarped at its frequency.

    Parameters
    ----------
    f : Filter
        The filter; its frequency lies below the Nyquist frequency ``1 / (2 T)``.
    period : float
        Sample period T [s], > 0.

    Returns
    -------
    b, a : numpy.ndarray
        Descending powers of z (three each for a second-order filter, two for
        a first-order low-pass), ``a[0] == 1``.
    """
    w = 2.0 * math.pi * f.frequency
    return bilinear(*filter_polynomials(f), w / math.tan(0.5 * w * period))
