"""Where the simulated stage stands for the hardware: the loop step 2 finds stable.

The nonlinear simulation carries the two masses, friction, the joint and the
controller (its sampling, delay and filters), not the parasitic modes. Where a
limit case of step 2, which holds them, is unstable at the design crossover,
what the simulation shows does not hold for the hardware:
:func:`linear_loop_note` says why, and :func:`beyond_the_linear_loop` turns the
simulated stage's passing checks into warnings that say it (the verdict's
reasons likewise, :func:`fi_design.guideline.verdict.judge`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from ..results import Check, Status
from ..results.design import CrossoverResult

__all__ = ["linear_loop_note", "beyond_the_linear_loop"]

#: Checks that state what the simulated stage does (names, or their prefixes).
_SIMULATED = ("simulation_", "spec_move_", "min_crossover_", "isolator_needed", "landing_force",
              "end_stop_force", "actuator_force", "friction_model_cross_check", "positioning",
              "robustness")


def linear_loop_note(xo: CrossoverResult) -> str | None:
    """Why the simulated stage does not stand for the hardware, or None where it does.

    The nonlinear simulation carries the two masses, friction, the joint and the
    controller, not the parasitic modes; where a limit case of step 2 (which holds
    them) is unstable at the design crossover, what the simulation shows does not
    hold for the hardware.

    Parameters
    ----------
    xo : CrossoverResult
        Step 2's result, its limit cases at the design crossover.

    Returns
    -------
    str or None
        A clause naming the unstable cases (to append to a sentence), or None
        when every case is stable.
    """
    from ..loop.linear import CASE_NUMBERS

    unstable = [c for c in xo.cases if not c.stable]
    if not unstable:
        return None
    cases = ", ".join(f"case {CASE_NUMBERS.get(c.name, c.name)}" for c in unstable)
    return (f"not valid for the hardware at this crossover: step 2 finds the closed loop "
            f"unstable ({cases}) with the parasitic modes, which the simulation leaves out")


def beyond_the_linear_loop(checks: Sequence[Check], note: str | None) -> tuple[Check, ...]:
    """The checks of the simulated stage, where the loop is unstable, as warnings.

    Parameters
    ----------
    checks : sequence of Check
        The design's checks.
    note : str or None
        :func:`linear_loop_note`; None returns the checks as they are.

    Returns
    -------
    tuple of Check
        The checks that state what the simulated stage does and do not fail keep
        their values and texts, the note appended, and neither pass nor fail:
        each is a warning.
    """
    if note is None:
        return tuple(checks)
    return tuple(replace(c, passed=None, status=Status.WARN, message=f"{c.message}; {note}")
                 if c.name.startswith(_SIMULATED) and c.passed is not False else c
                 for c in checks)
