"""Console summaries of the command line: rich tables and progress displays.

Presentation only: each ``print_*`` function reads a finished result and
prints it; :class:`Status`, :class:`ProgressBar` and :class:`FractionBar` are
the progress callbacks the CLI passes into the library. rich is imported
inside the functions, so ``fi-design --help`` stays fast.

One module per result family:

- :mod:`.design`: the design (checks, gains, crossover, limit cases, verdict);
- :mod:`.confirmation`: the nonlinear confirmation and one simulation;
- :mod:`.studies`: sweeps, the paper's study, robustness;
- :mod:`.recommend`: the design search;
- :mod:`.reconciliation`: model against measurement;
- :mod:`.identification`: friction identified from a record;

and what they share: :mod:`.common` (the console, tables, status colours)
and :mod:`.progress` (the progress callbacks).
"""

from __future__ import annotations

from .common import heading, make_console, status_text, table
from .confirmation import MOVE_GLYPHS, moves_strips, print_simulation, simulation_table
from .design import (CASE_CAPTION, CASE_COLUMNS, cases_table, checks_table, print_design,
                     print_verdict)
from .identification import print_identification
from .progress import FractionBar, ProgressBar, Status
from .recommend import print_recommendation
from .reconciliation import print_reconcile
from .studies import (MAX_MAP_COLUMNS, grid_caption, print_robustness, print_study, print_sweep,
                      sweep_grid_table, sweep_grid_tables)

__all__ = [
    "CASE_CAPTION", "CASE_COLUMNS", "FractionBar", "MAX_MAP_COLUMNS",
    "MOVE_GLYPHS", "ProgressBar", "Status", "cases_table", "checks_table", "grid_caption",
    "heading", "make_console", "moves_strips", "print_design", "print_identification",
    "print_recommendation", "print_reconcile", "print_robustness", "print_simulation",
    "print_study", "print_sweep", "print_verdict", "simulation_table", "status_text",
    "sweep_grid_table", "sweep_grid_tables", "table",
]
