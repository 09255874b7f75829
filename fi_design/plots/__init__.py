"""Figures, built with matplotlib's object API (``matplotlib.figure.Figure``, never pyplot).

Every function returns a :class:`~matplotlib.figure.Figure` (or draws into a
given ``Axes``); :func:`figure_bytes` renders one to SVG or PNG bytes with
fixed metadata, so the same result gives the same file. Values arrive in SI;
axes show them in engineering units (mm, N/mm, ...) named in the label.

One module per result family, each reading a finished result:

- :mod:`.loop`: the design's linear analysis (Bode, Nyquist, sensitivity);
- :mod:`.confirmation`: the spec's own motion (position error, joint deflection);
- :mod:`.guide`: the isolator's leaf-spring guide drawn to scale;
- :mod:`.hunting`: hunting as a property of the stage (the move family, the
  cycles, the boundary on the crossover axis);
- :mod:`.studies`: sweeps, the paper's study (Figure 4), robustness;
- :mod:`.recommend`: the design space of a recommendation;
- :mod:`.reconciliation`: measured against modelled traces, candidate scores;
- :mod:`.identification`: the force-velocity map and the force residual;

and what they share: :mod:`.figure` (report style, margins, SVG and PNG
bytes) and :mod:`.labels` (axis names and display units of spec paths).
matplotlib is imported inside the functions, so importing this package is
light.
"""

from __future__ import annotations

from .confirmation import (PLANT_COLOURS, SETTLE_ZOOM, deflection_figure, error_figure,
                           motion_end, plant_names)
from .figure import (FIGURE_MARK, FIGURE_SCHEME, RASTER_DPI, REPORT_RC, REPORT_WIDTH,
                     DeferredFigures, cell_edges, decimate, deferred_figures, figure_bytes,
                     figure_from, figure_mark,
                     figure_markup, figure_svg, log_x, nice_ticks, plain_tick, png_img, png_size,
                     raster_dpi, raster_figures, report_figure, rgb_png, styled)
from .guide import guide_figure
from .hunting import MOVE_MARKS, boundary_figure, cycle_figure, moves_figure, positioning_figure
from .identification import force_velocity_figure, residual_figure
from .labels import QUANTITY_NAMES, axis_label, display_unit, quantity_name
from .loop import (BAND_FACTOR, CASE_COLOURS, CASE_STYLES, bode_figure, case_label, design_band,
                   nyquist_figure, out_of_band_crossovers, sensitivity_figure)
from .recommend import CANDIDATE_LOOK, recommend_figure
from .reconciliation import (GAP_COLOURS, GAP_ORDER, GAP_WIDTHS, candidate_scores_figure,
                             gap_overlay_figure, gap_residual_figure, structure_figure)
from .studies import (VERDICT_MARKS, design_map_figure, draw_sweep, robustness_figure,
                      study_figure, sweep_figure)

__all__ = [
    "BAND_FACTOR", "CANDIDATE_LOOK", "DeferredFigures", "FIGURE_SCHEME", "CASE_COLOURS", "CASE_STYLES", "GAP_COLOURS", "GAP_ORDER",
    "GAP_WIDTHS", "MOVE_MARKS", "PLANT_COLOURS", "QUANTITY_NAMES", "RASTER_DPI", "REPORT_RC",
    "REPORT_WIDTH",
    "SETTLE_ZOOM", "VERDICT_MARKS", "axis_label", "bode_figure", "boundary_figure",
    "candidate_scores_figure", "case_label", "cell_edges", "cycle_figure", "decimate",
    "deferred_figures", "deflection_figure", "figure_mark", "FIGURE_MARK", "design_band", "design_map_figure", "display_unit", "draw_sweep",
    "error_figure", "figure_bytes", "figure_from", "figure_markup", "figure_svg", "force_velocity_figure", "gap_overlay_figure",
    "gap_residual_figure", "guide_figure", "log_x", "motion_end", "moves_figure", "nice_ticks", "positioning_figure", "nyquist_figure",
    "out_of_band_crossovers", "plain_tick", "plant_names", "png_img", "raster_dpi",
    "raster_figures", "png_size", "rgb_png", "quantity_name", "recommend_figure",
    "report_figure", "residual_figure", "robustness_figure", "sensitivity_figure",
    "structure_figure", "study_figure", "styled", "sweep_figure",
]
