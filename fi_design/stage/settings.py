"""How the stage-level runs are set and judged: the constants, the watch, the plant's traits.

The bottom of :mod:`fi_design.stage`: the tolerances and limits of the family
runs, the orbit and the fold search; the :class:`Watch` of a plant (settle
band, quiet time, horizon); and the predicates that say what a plant allows
(an integrator, a whole state vector, forces independent of position, mirror
symmetry), which decide how its runs may be continued and compared.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..kernel.layout import PlantParameters
from ..model import Model
from ..simulation.run import tolerances

__all__ = ["CROSSINGS", "REPEAT", "MATCH", "MATCH_SHARE", "MATCH_CAP", "ORBIT_RTOL", "PERTURBATION", "MULTIPLIER_AGREEMENT",
           "FOLD_RESOLUTION", "FOLD_RELATIVE", "FOLD_STEP", "H_MAX", "Watch", "watch_settings",
           "integrates", "restartable", "translation_invariant", "symmetric", "kernel_arrays"]

#: Room for section crossings per run (the crossings rule stops a run there).
CROSSINGS = 400
#: Repeat tolerance of the family runs: the section state repeats within this
#: fraction of the physical scales (1 mm, 1 cm/s, Fs / sigma0, Fs) [-].
REPEAT = 1e-3
#: Match tolerance of the family runs, its floor: a move whose section state comes within
#: this fraction of the physical scales of a cycle an earlier move of the same plant
#: repeated has entered that cycle (an attracting cycle draws it in, by the cycle's
#: multiplier, about 0.5, at every crossing; the repeat rule needs about five crossings
#: more) [-]. 0 turns the rule off.
MATCH = 1e-2
#: ... widened with the size of the known cycles: to this share of the smallest cycle's
#: peak-to-peak amplitude in the position scale (a 1.8 mm cycle: 0.54, capped) [-] ...
MATCH_SHARE = 0.3
#: ... and never beyond this [-].
MATCH_CAP = 0.3
#: Relative tolerance of the orbit computations (shooting, multipliers) [-].
ORBIT_RTOL = 1e-9
#: Finite-difference perturbation of the return map, in physical scales [-].
PERTURBATION = 1e-6
#: The Floquet multiplier at PERTURBATION and at ten times it must agree this closely, or
#: the multiplier is not reported (relative to the larger) [-].
MULTIPLIER_AGREEMENT = 0.1
#: Bisection of the fold: stop when the bracket is this narrow [Hz] ...
FOLD_RESOLUTION = 0.01
#: ... or this narrow relative to the crossover [-].
FOLD_RELATIVE = 1e-3
#: Step of the search for a crossover on the other side of the fold [-].
FOLD_STEP = 1.25
#: Largest step between the kernel's outputs and the h_max of the family runs [s].
H_MAX = 0.05


@dataclass(frozen=True)
class Watch:
    """How the runs of one plant are judged (all SI).

    Attributes
    ----------
    band : float
        Settle band on x1 - r [m] (``requirements.hunting.settle_band``).
    quiet : float
        Time the stage must rest within the band before the rest is judged
        [s]: ten integrator time constants kp / ki, at least 1 s.
    horizon : float
        Longest time after the motion [s] (``requirements.hunting.horizon``).
    rest_anywhere : bool
        A rest off the target ends a run too: a loop without integrator rests
        wherever friction holds it (its static error), and a saturated drive
        may not push harder than its force limit (stuck for good); an
        integrating loop with force to spare goes on.
    tolerance : float
        Relative tolerance of the family runs [-] (``simulation.tolerance``).
    max_steps : int
        Step budget per run (``simulation.max_steps``).
    """

    band: float
    quiet: float
    horizon: float
    rest_anywhere: bool
    tolerance: float
    max_steps: int


def watch_settings(model: Model, params: PlantParameters) -> Watch:
    """The :class:`Watch` of a model's plant.

    Parameters
    ----------
    model : Model
        The resolved model (its spec's hunting settings, tolerance, step budget).
    params : PlantParameters
        The plant (its controller's gains).

    Returns
    -------
    Watch
    """
    spec = model.spec
    h = spec.requirements.hunting
    if integrates(params):
        ki, kp = _gains(params)
        quiet = max(1.0, 10.0 * kp / ki) if kp > 0 else 1.0
    else:
        quiet = 1.0
    return Watch(band=h.settle_band, quiet=quiet, horizon=h.horizon,
                 rest_anywhere=not integrates(params) or math.isfinite(params.force_limit),
                 tolerance=spec.simulation.tolerance, max_steps=spec.simulation.max_steps)


def _gains(p: PlantParameters) -> tuple[float, float]:
    """Integral and proportional gain [N/(m s), N/m] of the continuous or sampled law."""
    if p.sample_period > 0.0:
        # trapezoidal integrator: dc = ki Ts / 2; dp = kp - dc
        ki = 2.0 * p.dc / p.sample_period
        return ki, p.dp + p.dc
    return p.ki, p.kp


def integrates(p: PlantParameters) -> bool:
    """Whether the plant's controller has an integrator (a positive integral gain).

    Parameters
    ----------
    p : PlantParameters
        The plant (continuous or sampled controller).

    Returns
    -------
    bool
    """
    return (p.dc if p.sample_period > 0.0 else p.ki) > 0.0


def restartable(p: PlantParameters) -> bool:
    """Whether the state vector holds the whole state (a continuous controller without delay).

    A run of such a plant can be continued exactly from where another stopped.

    Parameters
    ----------
    p : PlantParameters
        The plant.

    Returns
    -------
    bool
    """
    return p.sample_period == 0.0 and p.delay == 0.0


def translation_invariant(p: PlantParameters) -> bool:
    """Whether the plant's forces do not depend on where the stage is.

    A cycle about one target is then the same cycle about another, shifted:
    no position-dependent friction, force ripple, cable spring or quantization.

    Parameters
    ----------
    p : PlantParameters
        The plant.

    Returns
    -------
    bool
    """
    return (p.pdf_amplitude == 0.0 and p.ripple_amplitude == 0.0 and p.cable_stiffness == 0.0
            and p.quantization == 0.0)


def symmetric(p: PlantParameters) -> bool:
    """Whether a move and its mirror image behave alike (friction and loads odd in x).

    Parameters
    ----------
    p : PlantParameters
        The plant.

    Returns
    -------
    bool
    """
    return (p.value("Fc_neg") == p.Fc and p.value("sigma2_neg") == p.sigma2
            and p.offset == 0.0 and p.cable_preload == 0.0 and p.cable_stiffness == 0.0
            and p.ripple_amplitude == 0.0 and p.pdf_amplitude == 0.0
            and p.ff_coulomb == 0.0)


@functools.lru_cache(maxsize=64)
def kernel_arrays(params: PlantParameters, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's parameter array and absolute tolerances of a plant (made once per plant).

    Parameters
    ----------
    params : PlantParameters
        The plant.
    tol : float
        Relative tolerance [-].

    Returns
    -------
    (ndarray, ndarray)
        The parameter array, and the absolute tolerances per state (SI units of each state).
    """
    return params.to_array(), tolerances(params, tol)
