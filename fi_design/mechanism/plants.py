"""The rigid limit cases' plants and the loop's 0 dB crossings, without python-control.

The guide is sized before the loop is analysed (its modes are what step 2
judges), yet its modes must lie ``requirements.parasitic_separation`` times
above the loop's actual crossover: the highest 0 dB crossing of the limit
cases in the loop's band, which with the cart stuck and the joint free lies
well above the crossover the PID is tuned for (the joint's resonance lifts
|L|). This module gives that crossing from the rigid limit cases alone, with
numpy: the plants' polynomials (which :mod:`fi_design.loop.linear` builds its
models from, parasitic modes added) and the crossings of |C(jw) P(jw)| = 1.
A loop delay's Pade model is an all-pass (|D(jw)| = 1): it moves no gain
crossing, so it is left out here.
"""

from __future__ import annotations

import math

import numpy as np

from ..controller.polynomials import controller_polynomials

__all__ = ["BAND_FACTOR", "rigid_plant", "two_mass_plant", "case_arguments", "case_plants", "gain_crossings",
           "rigid_loop_crossover", "scaled", "balanced_scale"]

#: A gain crossover more than this factor below the controller's crossover lies outside the
#: loop's band [-].
BAND_FACTOR = 10.0


def rigid_plant(mass: float, damping: float, stiffness: float) -> tuple[list, list]:
    """x/u of a mass on a spring and damper: ``1 / (m s^2 + c s + k)`` [m/N], s in rad/s."""
    return [1.0], [mass, damping, stiffness]


def two_mass_plant(m1: float, m2: float, k: float, c: float, cart_stiffness: float,
                   cart_damping: float) -> tuple[list, list]:
    """x1/u of stage m1 on the joint (k, c) to cart m2, the cart on (cart_stiffness,
    cart_damping), the force on m1 [m/N], s in rad/s.

    ``P = (m2 s^2 + (c + cd) s + k + kc) / det``, expanded by hand so that the
    cancelling terms (k^2, 2 c k) never meet in floating point.
    """
    kc, cd = cart_stiffness, cart_damping
    num = [m2, c + cd, k + kc]
    den = [m1 * m2, m1 * (c + cd) + m2 * c, m1 * (k + kc) + m2 * k + c * cd,
           c * kc + k * cd, k * kc]
    return num, den


def case_arguments(model) -> dict:
    """The limit cases of a model by name, each ``(plant, arguments)``: :func:`rigid_plant`
    or :func:`two_mass_plant` and what it takes.

    Four for an isolated stage (the cart sliding or stuck on its bristles, the joint
    free or on its limiter), two without isolator (sliding, stuck).

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model: masses, friction, the joint's stiffness and damping.
    """
    f = model.friction
    m1, m2, M = model.m1, model.m2, model.total_mass
    s0, s1 = f.sigma0, f.sigma1
    s2 = min(f.viscous(1), f.viscous(-1))
    if model.joint is None:
        return {"sliding": (rigid_plant, (M, s2, 0.0)),
                "stuck": (rigid_plant, (M, s1 + s2, s0))}
    k, c = model.joint.stiffness, model.joint.damping
    return {
        "sliding_free": (two_mass_plant, (m1, m2, k, c, 0.0, s2)),
        "stuck_free": (two_mass_plant, (m1, m2, k, c, s0, s1 + s2)),
        "sliding_limited": (rigid_plant, (M, s2, 0.0)),
        "stuck_limited": (rigid_plant, (M, s1 + s2, s0)),
    }


def case_plants(model) -> dict[str, tuple[list, list]]:
    """The rigid limit cases of a model by name, each ``(num, den)`` of x1/u
    (:func:`case_arguments`)."""
    return {name: plant(*args) for name, (plant, args) in case_arguments(model).items()}


def scaled(p, w0: float) -> np.ndarray:
    """Coefficients of p(w0 s') in s' (descending powers)."""
    n = len(p) - 1
    return np.asarray(p, float) * w0 ** np.arange(n, -1, -1, dtype=float)


def balanced_scale(den) -> float:
    """The geometric mean of the magnitudes of the nonzero roots of ``den`` [rad/s] (1 without).

    Scaling s by it makes the polynomial's leading and trailing coefficients alike, which
    keeps the squared polynomials of a margin search finite when the loop holds both a
    millihertz integrator and kilohertz filters."""
    d = np.trim_zeros(np.asarray(den, float), "f")
    d = np.trim_zeros(d, "b")
    if d.size < 2:
        return 1.0
    lead, tail = abs(d[0]), abs(d[-1])
    return float((tail / lead) ** (1.0 / (d.size - 1)))


def _on_axis(p: np.ndarray) -> np.ndarray:
    """Coefficients in w of |p(jw)|^2 (descending powers; real)."""
    n = len(p) - 1
    pj = p * (1j) ** np.arange(n, -1, -1)
    return np.real(np.polymul(pj, np.conj(pj)))


def gain_crossings(num, den) -> np.ndarray:
    """Frequencies where |num(jw) / den(jw)| = 1, increasing [rad/s].

    The positive real roots of |num(jw)|^2 - |den(jw)|^2, found with s scaled by
    :func:`balanced_scale` and each kept where |L| is 1 to within 1e-6.
    """
    w0 = balanced_scale(den)
    ns, ds = scaled(num, w0), scaled(den, w0)
    lead = ds[np.nonzero(ds)[0][0]]
    ns, ds = ns / lead, ds / lead
    q = np.polysub(_on_axis(ns), _on_axis(ds))
    nz = np.nonzero(np.abs(q) > 0.0)[0]
    if nz.size == 0:
        return np.empty(0)
    roots = np.roots(q[nz[0]:])
    real = roots[(np.abs(roots.imag) <= 1e-7 * np.abs(roots)) & (roots.real > 0.0)].real
    out = []
    for w in np.sort(real):
        gain = abs(np.polyval(ns, 1j * w) / np.polyval(ds, 1j * w))
        if abs(gain - 1.0) <= 1e-6 and (not out or w > out[-1] * (1.0 + 1e-9)):
            out.append(w)
    return np.asarray(out) * w0


def rigid_loop_crossover(model) -> float | None:
    """The loop's crossover of the rigid limit cases: their highest 0 dB crossing in the
    loop's band (at or above the controller's crossover / :data:`BAND_FACTOR`) [Hz].

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model: the controller law (its filters included) and the plants.

    Returns
    -------
    float or None
        None when no case crosses 0 dB in the band.
    """
    law = model.law
    cn, cd = controller_polynomials(law)
    low = law.crossover / BAND_FACTOR
    best = None
    for num, den in case_plants(model).values():
        w = gain_crossings(np.polymul(cn, num), np.polymul(cd, den))
        hz = w / (2.0 * math.pi)
        hz = hz[hz >= low]
        if hz.size and (best is None or hz[-1] > best):
            best = float(hz[-1])
    return best
