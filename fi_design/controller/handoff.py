"""Step 4 handed over: the loop the design analysed, written as the spec's ``controller.gains``.

The rule tunes ``C(s) = (kp + ki/s + kd s) / (1 + s/wt)``, the roll-off on the
whole PID; ``controller.gains`` with ``controller.roll_off`` means
``kp + ki/s + kd s / (1 + s / (2 pi roll_off))``, the roll-off on the D term
only. The two are the same controller with other numbers
(:class:`fi_design.controller.pid.ControlLaw`); copying the first into the second moves
the crossover and takes gain margin. :func:`gains_spec_text` writes the
second: the input spec with ``controller.gains`` and ``controller.roll_off``
set (``derivative_on``, ``sample_rate``, ``delay`` and ``crossover`` are the
spec's own, so they stay), every digit kept, so that the design of the
written spec gives the same crossover, margins and simulation.
"""

from __future__ import annotations

from typing import Any

from ..display import number, quantity
from ..spec.edit import REMOVE, edited_spec_text, spec_quantity

__all__ = ["gains_values", "gains_spec_text"]


def gains_values(result: Any) -> dict[str, Any]:
    """The spec values of the design's loop, by dotted path, as the spec file takes them.

    Parameters
    ----------
    result : fi_design.results.design.DesignResult
        The design.

    Returns
    -------
    dict
        ``controller.gains`` (``kp``, ``ki``, ``kd`` with their units, every
        digit) and ``controller.roll_off`` (Hz; removed for an ideal D).
    """
    hand = result.pid.controller.hand_off()
    gains = {k: spec_quantity(f"controller.gains.{k}", hand[k]) for k in ("kp", "ki", "kd")}
    roll = REMOVE if hand["roll_off"] is None else spec_quantity("controller.roll_off",
                                                                  hand["roll_off"])
    return {"controller.gains": gains, "controller.roll_off": roll}


def gains_spec_text(result: Any) -> str:
    """YAML text of the design's spec with its loop written as ``controller.gains``.

    The input's text is edited (comments and layout kept,
    :func:`fi_design.spec.edit.edited_spec_text`). For a spec that tunes by
    the rule, these are the rule's gains at the design crossover in the form
    ``controller.gains`` takes; for a spec with the hardware's gains, its own
    gains again (with the roll-off explicit).

    Parameters
    ----------
    result : fi_design.results.design.DesignResult
        The design.

    Returns
    -------
    str
        YAML that ``load_spec`` reads back (checked).
    """
    law = result.pid.controller
    what = (f"the rule's gains at {number(law.crossover)} Hz on "
            f"{quantity(law.tuning_mass, 'kg')}" if law.source == "rule"
            else "the hardware's gains as the design used them")
    header = [f"controller.gains and controller.roll_off written by fi-design: {what}, in the "
              "form controller.gains takes (the roll-off filters the D term only), every "
              "digit kept;",
              "the design of this file gives the same crossover, margins and simulation."]
    comments = {"controller.gains": f"step 4: {what}",
                "controller.roll_off": "low-pass of the D term only"}
    values = gains_values(result)
    if values["controller.roll_off"] is REMOVE:
        comments.pop("controller.roll_off")
    return edited_spec_text(result.spec, values, comments=comments, header=header,
                            source="<spec with the step 4 gains>")
