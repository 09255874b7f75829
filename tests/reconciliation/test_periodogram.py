"""The reconciliation's periodogram against SciPy's Lomb-Scargle and a sine's analytic answer."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lombscargle

from fi_design.reconciliation.periodogram import SUB, lomb_scargle
from fi_design.reconciliation.signatures import spatial_periods


@pytest.mark.parametrize("n, f", [(60, 1), (100, 7), (100, SUB + 1), (400, 3 * SUB + 5),
                                  (1500, 2000)])
@pytest.mark.parametrize("uniform", [True, False])
def test_the_power_is_scipys_lomb_scargle(n, f, uniform):
    """Uneven positions over 0.5 m, a ripple of 10 mm in noise; wavenumbers of 2e-4 to 0.05 m."""
    rng = np.random.default_rng(n + f)
    x = np.sort(rng.uniform(0.0, 0.5, n))
    y = 0.3 * np.sin(2 * np.pi * x / 0.01) + rng.normal(size=n)
    lo, hi = 2 * np.pi / 0.05, 2 * np.pi / 2e-4
    k = np.linspace(lo, hi, f) if uniform else np.sort(rng.uniform(lo, hi, f))
    ours, scipys = lomb_scargle(x, y, k), np.atleast_1d(lombscargle(x, y, k))
    assert ours.shape == scipys.shape
    np.testing.assert_allclose(ours, scipys, rtol=0, atol=1e-10 * scipys.max())


def test_a_sine_gives_its_wavelength_and_amplitude():
    """y = A sin(2 pi x / L) at 3000 uneven positions over 0.4 m: the strongest period is L, A."""
    rng = np.random.default_rng(7)
    x = np.sort(rng.uniform(0.0, 0.4, 3000))
    amplitude, wavelength = 0.25, 7.3e-3  # N, m
    y = amplitude * np.sin(2 * np.pi * x / wavelength + 0.4) + 0.01 * rng.normal(size=x.size)
    (top, *_) = spatial_periods(x, y, 2e-4, 0.05, n_peaks=3)
    assert top.wavelength == pytest.approx(wavelength, rel=2e-3)
    assert top.amplitude == pytest.approx(amplitude, rel=0.03)
    assert top.ratio > 100
