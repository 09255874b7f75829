"""The terms a design summary prints, defined once for the console and the report.

A reviewer meets "fold", "Floquet multiplier", "limit case" and "landing" in
the checks and tables; :data:`GLOSSARY` says what each means, and
:func:`glossary` picks the ones a given text uses, in the order of the list.
"""

from __future__ import annotations

import re

__all__ = ["GLOSSARY", "glossary"]

#: (term, definition, pattern that finds the term in a text).
GLOSSARY = (
    ("hunting", "a sustained cycle around the target after a move: the integrator pushes the "
                "cart through stiction, it slips past the target, sticks, and the cycle repeats",
     r"\bhunt"),
    ("limit case", "one of the linear models the loop switches between near standstill (paper "
                   "Figure 2): the cart sliding or stuck on its bristles, the joint free or on "
                   "its end stop; the loop must keep its margins in each",
     r"limit case"),
    ("settle band", "the error band |x1 \u2212 r| within which a move counts as at rest at its "
                    "target (requirements.hunting.settle_band)",
     r"settle band"),
    ("static error", "the error a loop without integrator rests at: static friction holds the "
                     "cart while kp e plus the load offset stays below it",
     r"static error"),
    ("Poincar\u00e9 section", "the instants the error x1 \u2212 r crosses zero upwards; a "
                              "cycle returns to the same state there every period",
     r"Poincar"),
    ("Floquet multiplier", "how much a small disturbance of the cycle grows per period (the "
                           "largest eigenvalue of the Jacobian of the return map at the "
                           "Poincar\u00e9 section): below 1 the cycle attracts the motion, "
                           "above 1 it repels it",
     r"Floquet"),
    ("fold", "the crossover at which the hunting cycle meets its unstable twin and vanishes: "
             "above the fold no move of the family can end in that cycle, so it is the lowest "
             "crossover from which no move hunts",
     r"\bfolds?\b"),
    ("landing", "where the cart comes to rest after a move: the joint deflection d at rest, and "
                "the flexure force k min(|d|, s) the resting cart holds against static friction",
     r"\blands?\b|landing"),
    ("end stop", "the stroke limiter: beyond the stroke the joint is a stiff contact spring, the "
                 "cart and stage move as one and the controller feels the friction again",
     r"end stop|limiter"),
    ("k_max", "the stiffness at which the flexure pushes the cart with its static friction at "
              "full stroke, Fs / (safety \u00d7 stroke) (step 3): stiffer, it drags the cart",
     r"k_max"),
)


def glossary(text: str) -> list[dict]:
    """The terms of :data:`GLOSSARY` that ``text`` uses.

    Parameters
    ----------
    text : str
        What a summary or report prints.

    Returns
    -------
    list of dict
        ``term`` and ``definition``, in the order of :data:`GLOSSARY`.
    """
    return [{"term": t, "definition": d} for t, d, pattern in GLOSSARY
            if re.search(pattern, text, flags=re.IGNORECASE)]
