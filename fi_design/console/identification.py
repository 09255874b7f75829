"""The identification's summary: the parameters with their errors, the fit, the notes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..display import number, unit_text

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console


def print_identification(console: "Console", result) -> None:
    """Print an :class:`~fi_design.identification.IdentificationResult`: table, fit, notes.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.identification.IdentificationResult
        The identification.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    m = result.measurement
    console.print(Text(f"Identification from {m.source or 'the record'}: {m.n} samples, "
                       f"{result.form.replace('_', '-')} form, {result.model.replace('_', ' ')} "
                       "model", style="bold"))
    t = Table(title="Parameters (SI; standard error one sigma)", title_justify="left",
              box=box.SIMPLE_HEAD, pad_edge=False)
    for col, just in (("Parameter", "left"), ("Value", "right"), ("Std. error", "right"),
                      ("Unit", "left"), ("Identifiable", "left")):
        t.add_column(col, justify=just, no_wrap=True)
    for name, p in result.parameters.items():
        t.add_row(Text(name), number(p.value, 6), number(p.std_error, 3), Text(unit_text(p.unit)),
                  Text("yes" if p.identifiable else "no",
                       style="green" if p.identifiable else "yellow"))
    console.print(t)
    f = result.fit
    console.print(Text(f"Fit: RMS force residual {number(f.force_rms_residual, 3)} N, relative "
                       f"error {number(f.relative_error, 3)}, condition number "
                       f"{number(f.condition_number, 3)}, {f.samples_used} samples used "
                       f"({number(f.effective_samples, 3)} effective)"))
    ms = result.masses
    console.print(Text(f"Masses: stage {number(ms.stage, 5)} kg, cart {number(ms.cart, 5)} kg "
                       f"({ms.source})"))
    for name in ("static", "stribeck_velocity", "bristle_stiffness"):
        p = result.parameters[name]  # how it was estimated, or why not
        console.print(Text(f"{name}: {p.note}", style=None if p.identifiable else "dim"))
    for note in result.notes:
        console.print(Text(f"note: {note}", style="dim"))
