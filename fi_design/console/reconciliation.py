"""The reconciliation's summary: the effect, the causes, the candidates, the gap.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..display import number, percent, quantity, scale
from ..effects import values_text as _effects_text
from .common import table

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console


def print_reconcile(console: "Console", result) -> None:
    """Print the readable summary of a :class:`~fi_design.results.reconciliation.ReconcileResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.
    """
    from rich.text import Text

    head = Text("Effect: ", style="bold")
    head.append(Text(result.effect, style="bold green" if result.effect != "none" else "bold"))
    console.print(head)
    console.print(Text(result.conclusion))
    if result.diagnosis.mismatch and result.diagnosis.causes:
        d = table("Likely causes of the structural gap")
        for col, just in (("Cause", "left"), ("Share", "right"), ("What was measured", "left")):
            d.add_column(col, justify=just, no_wrap=col == "Share",
                         ratio=1 if col == "What was measured" else None)
        for c in result.diagnosis.causes:
            d.add_row(Text(c.name.replace("_", " ")), percent(c.share, 2), Text(c.detail))
        console.print(d)
    if len(result.steps) > 1:
        s = table("Effects in order")
        for col in ("Effect", "Misfit before", "Misfit after"):
            s.add_column(col, justify="left" if col == "Effect" else "right", no_wrap=True)
        for st in result.steps:
            s.add_row(Text(st.name), number(st.misfit_before), number(st.misfit_after))
        console.print(s)
    if result.candidates:  # none when nothing was fitted (the conclusion says why)
        t = table("Candidates (best first)")
        longest = max(len(c.name) for c in result.candidates)
        for col, just in (("Effect", "left"), ("Score", "right"), ("Explained", "right"),
                          ("Fitted parameters", "left")):
            t.add_column(col, justify=just, no_wrap=col != "Fitted parameters",
                         min_width=longest if col == "Effect" else None,
                         ratio=1 if col == "Fitted parameters" else None)
        for c in result.candidates:
            params = _effects_text(c.name, c.parameters, c.uncertainty)
            t.add_row(Text(c.name), number(c.score), percent(c.explained, 3), Text(params))
        console.print(t)
    for c in result.candidates:
        if c.name not in result.effects and c.reasons:
            console.print(Text(f"{c.name} not named: {c.reasons[0]}", style="dim"))
    if result.gaps:  # none when the nominal model did not run (the conclusion says why)
        g = table("Gap before and after")
        for col in ("Metric", "Unit", "Before", "After", "Noise"):
            g.add_column(col, justify="left" if col in ("Metric", "Unit") else "right",
                         no_wrap=True)
        for m in result.gaps:
            unit, factor = scale(m.unit, (m.before, m.after, m.noise))
            g.add_row(Text(m.name), Text(unit or "-"),
                      *[number(None if v is None else v * factor)
                        for v in (m.before, m.after, m.noise)])
        console.print(g)
    else:
        console.print(Text("No gap table: the nominal model did not run through the record, so "
                           "there is no gap to measure (the conclusion above says what "
                           "failed).", style="dim"))
    nz = result.noise
    parts = [f"position {quantity(nz.position, 'm', 3)} ({nz.source.get('position')})"]
    if nz.force is not None:
        parts.append(f"force {quantity(nz.force, 'N', 3)} ({nz.source.get('force')})")
    if nz.deflection is not None:
        parts.append(f"deflection {quantity(nz.deflection, 'm', 3)} "
                     f"({nz.source.get('deflection')})")
    console.print(Text("Noise: " + ", ".join(parts)))
    console.print(Text("Position lattice: " + result.lattice.detail))
    for name, why in result.skipped.items():
        console.print(Text(f"skipped {name}: {why}", style="dim"))
