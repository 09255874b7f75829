"""Figures: every one builds from a finished result, labels its axes with units, uses no pyplot."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from matplotlib.figure import Figure

from fi_design import plots

from conftest import ROOT

UNIT = re.compile(r"\[[^\]]+\]")


@pytest.fixture(scope="module")
def studies(paper_spec):
    from fi_design.studies import paper_study, robustness, Scatter, sweep

    return {
        "map": sweep(paper_spec, ("controller.crossover", [4.0, 8.0]),
                     ("isolator.stroke", [1e-4, 3e-4])),
        "line": sweep(paper_spec, ("controller.crossover", [4.0, 8.0, 12.0]), isolated=False),
        "study": paper_study(paper_spec, 2, maps="AD"),
        "robustness": robustness(paper_spec, [Scatter("friction.static", 0.1)], samples=3),
    }


@pytest.fixture(scope="module")
def reconciliation():
    from fi_design import load_measurement, load_spec, reconcile

    spec = load_spec(ROOT / "examples" / "measured_stage.yaml")
    data = load_measurement(ROOT / "examples" / "measured_trace.csv")
    return reconcile(spec, data, candidates=["cable_force"])


def _figures(design, studies, reconciliation):
    sim = design.simulation
    yield "bode", plots.bode_figure(design)
    yield "nyquist", plots.nyquist_figure(design)
    yield "sensitivity", plots.sensitivity_figure(design)
    yield "error", plots.error_figure(sim, design.spec)
    yield "deflection", plots.deflection_figure(sim, design.spec)
    yield "moves", plots.moves_figure(sim)
    yield "cycle", plots.cycle_figure(sim, design.spec)
    yield "boundary", plots.boundary_figure(sim)
    yield "sweep map", plots.sweep_figure(studies["map"])
    yield "sweep line", plots.sweep_figure(studies["line"])
    yield "design map", plots.design_map_figure(studies["map"])
    yield "study", plots.study_figure(studies["study"])
    yield "robustness", plots.robustness_figure(studies["robustness"])
    yield "gap overlay", plots.gap_overlay_figure(reconciliation)
    yield "gap residual", plots.gap_residual_figure(reconciliation)
    yield "candidate scores", plots.candidate_scores_figure(reconciliation)


def _categorical(axis) -> bool:
    """An axis whose tick labels are words (plants, effects), not numbers."""
    labels = [t.get_text() for t in axis.get_ticklabels() if t.get_text()]
    return bool(labels) and not any(re.fullmatch(r"[-\u2212+0-9.e ]+", t) for t in labels)


def _data_axes(fig: Figure):
    for ax in fig.axes:
        if ax.get_visible() and (ax.lines or ax.collections or ax.patches or ax.images) and \
                ax.get_label() != "<colorbar>":
            yield ax


def test_every_figure_builds_with_unit_labels(paper_confirmed_design, studies, reconciliation):
    seen = []
    for name, fig in _figures(paper_confirmed_design, studies, reconciliation):
        assert isinstance(fig, Figure), name
        seen.append(name)
        axes = list(_data_axes(fig))
        assert axes, name
        for ax in axes:
            ylabel = ax.get_ylabel()
            assert _categorical(ax.yaxis) or UNIT.search(ylabel), (name, ylabel)
            xlabel = ax.get_xlabel()
            shared = [o for o in ax.get_shared_x_axes().get_siblings(ax) if o.get_xlabel()]
            assert _categorical(ax.xaxis) or UNIT.search(xlabel) or \
                any(UNIT.search(o.get_xlabel()) for o in shared), (name, xlabel)
        svg = plots.figure_bytes(fig, "svg")
        assert svg.startswith(b"<?xml") and b"<svg" in svg
    assert len(seen) == 16


def test_figures_reproducible_and_inline_ids_prefixed(paper_confirmed_design):
    a = plots.figure_svg(plots.bode_figure(paper_confirmed_design), "bode")
    b = plots.figure_svg(plots.bode_figure(paper_confirmed_design), "bode")
    assert a == b and a.startswith("<svg")
    ids = re.findall(r'\sid="([^"]+)"', a)
    assert ids and all(i.startswith("bode-") for i in ids)
    assert "<text" in a  # figures keep their text as text (searchable)


def test_display_units_and_labels():
    assert plots.display_unit("m") == ("mm", 1e3)
    assert plots.display_unit("Hz") == ("Hz", 1.0)
    assert plots.axis_label("controller.crossover", "Hz") == "Crossover frequency [Hz]"
    assert plots.axis_label("isolator.stroke", "m") == "Isolator stroke [mm]"
    assert plots.axis_label("isolator.stiffness", "N/m") == "Drive stiffness [N/mm]"
    assert plots.axis_label("stage.mass", "kg") == "Stage mass [kg]"
    # a path without a name of its own takes the schema's description
    assert plots.axis_label("effects[type=time_delay].delay", "s") == "Extra loop delay [s]"
    assert plots.nice_ticks(0.05, 1.0) == [0.05, 0.1, 0.2, 0.5, 1.0]
    assert plots.plain_tick(0.001) == "0.001" and plots.plain_tick(1000.0) == "1000"


def test_a_swept_delay_reads_in_ms_and_names_its_path_once():
    # 'sweep --x "effects[0].delay=1 ms,2 ms"' printed 'effects[0].delay (effects[0].delay): 2
    # values 0.001 to 0.002 s': no name without the spec's entry type, and the values in SI
    from fi_design.console.studies import _axis_values_text
    from fi_design.report.study import _axis_text
    from fi_design.results.studies import Axis

    delay = Axis(path="effects[0].delay", values=[1e-3, 2e-3], unit="s")
    assert _axis_values_text(delay) == \
        "Extra loop delay (effects[0].delay): 2 values 1 to 2 ms (linear)"
    assert _axis_text(delay).endswith("values from 1\u00a0ms to 2\u00a0ms")
    assert plots.axis_label(delay.path, delay.unit, delay.values) == "Extra loop delay [ms]"
    assert plots.display_unit("s", [5.0, 20.0]) == ("s", 1.0)
    assert plots.quantity_name("effects[0].amplitude") == "Amplitude"  # two types' amplitudes


def test_plots_never_use_pyplot():
    """The module imports no pyplot, and drawing a figure does not load it.

    (python-control imports pyplot itself, so the check draws a study's figures, which need
    no python-control.)
    """
    modules = sorted((ROOT / "fi_design" / "plots").glob("*.py"))
    assert len(modules) > 1
    for module in modules:
        source = module.read_text(encoding="utf-8")
        assert not re.search(r"^\s*(import|from)\s+matplotlib(\.pyplot|\s+import\s+pyplot)|plt\.",
                             source, flags=re.MULTILINE), module.name
    code = ("import sys\n"
            "from fi_design import plots, load_spec\n"
            "from fi_design.studies import sweep\n"
            "r = sweep(load_spec('examples/paper_setup.yaml'), ('controller.crossover', [8.0]),\n"
            "          ('isolator.stroke', [3e-4]))\n"
            "plots.figure_bytes(plots.sweep_figure(r), 'png')\n"
            "plots.figure_bytes(plots.design_map_figure(r), 'svg')\n"
            "assert 'matplotlib' in sys.modules and 'control' not in sys.modules\n"
            "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot was imported'\n")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT, timeout=120)


# --------------------------------------------------------------------------- reading the figures


def _hand_made_map(paper_spec):
    """A 3 x 3 map near zero stroke and crossover, values made up (no simulation needed)."""
    import numpy as np

    from fi_design.results.studies import RunInfo, SweepResult
    from fi_design.studies import make_axis

    x = make_axis("controller.crossover", [1.0, 5.0, 9.0])
    y = make_axis("isolator.stroke", [0.05e-3, 0.3e-3, 0.55e-3])
    cycles = np.array([[3.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    verdict = np.where(cycles > 0, "hunting", "settled")
    return SweepResult(spec=paper_spec, x=x, y=y, isolated=True, points=(),
                       hunting_cycles=cycles, amplitude=np.zeros((3, 3)),
                       period=np.full((3, 3), np.nan), verdict=verdict,
                       design_point=(8.0, 0.3e-3), run=RunInfo(9, 9, 0, 1, "serial", 0.0))


@pytest.mark.parametrize("draw", ["sweep", "design map"])
def test_heatmap_axes_stay_physical_and_name_their_quantity(paper_spec, draw):
    result = _hand_made_map(paper_spec)
    fig = plots.sweep_figure(result) if draw == "sweep" else plots.design_map_figure(result)
    ax = next(_data_axes(fig))
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    # half a cell below 1 Hz and 0.05 mm would be -1 Hz and -0.075 mm: the cells stop at zero
    assert x0 == 0.0 and y0 == 0.0
    assert x1 == pytest.approx(11.0) and y1 == pytest.approx(0.675)
    mesh = ax.collections[0]
    assert mesh.get_coordinates()[..., 0].min() >= 0 and mesh.get_coordinates()[..., 1].min() >= 0
    assert ax.get_xlabel() == "Crossover frequency [Hz]"
    assert ax.get_ylabel() == "Isolator stroke [mm]"
    assert "controller.crossover" not in ax.get_title() + ax.get_xlabel() + ax.get_ylabel()


def test_line_sweep_starts_at_zero_not_below(paper_spec):
    import numpy as np

    from fi_design.results.studies import RunInfo, SweepResult
    from fi_design.studies import make_axis

    x = make_axis("isolator.stroke", [0.05e-3, 0.3e-3, 0.55e-3])
    line = SweepResult(spec=paper_spec, x=x, y=None, isolated=True, points=(),
                       hunting_cycles=np.array([2.0, 0.0, 0.0]), amplitude=np.zeros(3),
                       period=np.full(3, np.nan),
                       verdict=np.array(["hunting", "settled", "settled"]),
                       design_point=(0.3e-3,), run=RunInfo(3, 3, 0, 1, "serial", 0.0))
    ax = next(_data_axes(plots.sweep_figure(line)))
    assert ax.get_xlim()[0] == 0.0 and ax.get_xlabel() == "Isolator stroke [mm]"


def test_error_figure_shows_the_settling_at_the_band_scale(paper_confirmed_design):
    import matplotlib.colors as mcolors

    sim = paper_confirmed_design.simulation
    band = paper_confirmed_design.spec.requirements.hunting.settle_band
    fig = plots.error_figure(sim, paper_confirmed_design.spec)
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert len(axes) == 4  # per plant: the whole error (mm) and the settling (um)
    zooms = [ax for ax in axes if "\u00b5m" in ax.get_ylabel()]
    full = [ax for ax in axes if "[mm]" in ax.get_ylabel()]
    assert len(zooms) == 2 and len(full) == 2
    for ax in zooms:
        lo, hi = ax.get_ylim()
        # zoomed to a few settle bands, not to the millimetres of the hunting plant
        assert lo == pytest.approx(-plots.SETTLE_ZOOM * band * 1e6)
        assert hi == pytest.approx(plots.SETTLE_ZOOM * band * 1e6)
        assert "settle band" in ax.get_title(loc="left")
        bands = [p for p in ax.patches
                 if mcolors.to_hex(p.get_facecolor()) == "#dcefe0"]
        assert len(bands) == 1
        span = bands[0]  # a Rectangle (matplotlib >= 3.9) or a Polygon, y in data units
        y = [span.get_y(), span.get_y() + span.get_height()] if hasattr(span, "get_height") \
            else list(span.get_xy()[:, 1])
        assert min(y) == pytest.approx(-band * 1e6) and max(y) == pytest.approx(band * 1e6)
        assert ax.get_xlim()[0] > 0  # after the motion
    for ax in full:
        assert ax.get_ylim()[1] - ax.get_ylim()[0] > 1.0  # the hunting is visible in mm
    # the settled plant marks where it enters the band for good; the hunting one never does
    iso, non = zooms
    settle = sim.isolated.metrics.settling_time
    assert settle is not None
    texts = " ".join(t.get_text() for t in iso.texts)
    assert "in the band from" in texts
    assert "never stays in the band" in " ".join(t.get_text() for t in non.texts)


def test_bode_plot_spans_the_design_band(paper_confirmed_design):
    """It spanned 1e-4 to 1e3 Hz (case 4's millihertz crossover), the design band a third of
    the width; the band now fills the plot and the caption names what is left out."""
    import math

    from fi_design.report.design import _bode_caption

    d = paper_confirmed_design
    fc = d.crossover.desired
    for fig in (plots.bode_figure(d), plots.sensitivity_figure(d)):
        lo, hi = fig.axes[0].get_xlim()
        assert lo >= fc / 100
        band = math.log10(10 * fc / (fc / 10)) / math.log10(hi / lo)
        assert band >= 0.5, (lo, hi)
    caption = _bode_caption(d)
    assert "case 4 crosses 0 dB at 0.00135" in caption and "not drawn" in caption


def test_the_measured_trace_shows_under_the_corrected_one(reconciliation):
    """The corrected model, drawn on top with the measurement's width, hid it where the two
    agree: the measurement is now wide underneath, the models thin on top."""
    fig = plots.gap_overlay_figure(reconciliation)
    lines = {ln.get_label(): ln for ln in fig.axes[0].lines}
    measured = lines["measured"]
    for label, line in lines.items():
        if label != "measured" and not label.startswith("_"):
            assert line.get_linewidth() * 2 < measured.get_linewidth(), label
            assert line.get_zorder() > measured.get_zorder(), label


def test_captions_say_only_what_is_drawn(reconciliation, paper_confirmed_design):
    """The overlay's caption spoke of shading that was not drawn."""
    from types import SimpleNamespace

    from fi_design.report.design import _error_caption
    from fi_design.report.gap import _overlay_caption

    text = _overlay_caption(reconciliation)
    shaded = any(not s.coherent for s in reconciliation.segments)
    assert ("Shaded" in text) == shaded
    assert "failed" not in text and "cable_force" in text
    flat = SimpleNamespace(peak_times=(), settling_time=None)
    still = SimpleNamespace(suggested_isolator=False, isolated=SimpleNamespace(metrics=flat),
                            non_isolated=SimpleNamespace(metrics=flat))
    caption = _error_caption(still, paper_confirmed_design.spec)
    assert "circles" not in caption and "no peak counted" in caption
    assert "dotted" not in caption
    full = _error_caption(paper_confirmed_design.simulation, paper_confirmed_design.spec)
    assert "circles, the peaks the metric counts" in full and "dotted" in full


@pytest.mark.parametrize("orientation", ["standing", "hanging", "vertical_axis", "flat"])
def test_the_guide_s_labels_do_not_overlap(paper_confirmed_design, orientation):
    """The side view wrote 'centre of mass' to the left of its marker, across the actuator's
    arrow and over the word 'actuator' (the paper setup: sensor, actuator and centre of mass
    at one height); no two texts of the drawing overlap now, whichever way gravity acts."""
    import dataclasses

    mech = paper_confirmed_design.flexure.mechanics
    mech = dataclasses.replace(mech, guide=dataclasses.replace(mech.guide,
                                                               orientation=orientation))
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = plots.guide_figure(mech)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    for ax in fig.axes:
        boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in ax.texts
                 if t.get_text().strip()]
        for i, (a, box_a) in enumerate(boxes):
            for b, box_b in boxes[i + 1:]:
                assert not box_a.overlaps(box_b), (a, b)


def _drawn(fig):
    """Draw ``fig`` on an Agg canvas; its renderer (the extents of what it drew)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _cut_markers(ax):
    """Markers of ``ax`` inside its view but clipped by its frame: (label, x, y) in pixels."""
    import numpy as np

    frame = ax.bbox
    for line in ax.lines:
        if line.get_marker() in (None, "None", "", " ") or not line.get_clip_on():
            continue
        radius = line.get_markersize() * ax.figure.dpi / 72.0 / 2.0
        xy = np.column_stack([line.get_xdata(), line.get_ydata()]).astype(float)
        for x, y in ax.transData.transform(xy):
            inside = frame.x0 <= x <= frame.x1 and frame.y0 <= y <= frame.y1
            whole = frame.x0 <= x - radius and x + radius <= frame.x1 and \
                frame.y0 <= y - radius and y + radius <= frame.y1
            if inside and not whole:
                yield line.get_label(), x, y


_DESIGN_FIGURES = {
    "bode": lambda d: plots.bode_figure(d),
    "nyquist": lambda d: plots.nyquist_figure(d),
    "sensitivity": lambda d: plots.sensitivity_figure(d),
    "error": lambda d: plots.error_figure(d.simulation, d.spec),
    "deflection": lambda d: plots.deflection_figure(d.simulation, d.spec),
    "moves": lambda d: plots.moves_figure(d.simulation),
    "cycle": lambda d: plots.cycle_figure(d.simulation, d.spec),
    "boundary": lambda d: plots.boundary_figure(d.simulation),
    "guide": lambda d: plots.guide_figure(d.flexure.mechanics),
}


@pytest.mark.parametrize("name", list(_DESIGN_FIGURES))
def test_design_figures_draw_nothing_beyond_their_edges(paper_confirmed_design, name):
    """The sensitivity plot (Figure 4 of the paper setup's report) cut its '1000' tick label
    at the right edge, and the deflection plot drew the 'at rest' marker at the last instant,
    on the frame, half of it clipped. Everything a design figure draws (tick labels, axis
    labels, legends, texts) lies within the figure, and no marker within the view is clipped
    by its axes' frame."""
    fig = _DESIGN_FIGURES[name](paper_confirmed_design)
    renderer = _drawn(fig)
    edge = fig.bbox.padded(0.5)  # half a pixel for rounding
    for artist in [*fig.axes, *fig.legends, *fig.texts]:
        box = artist.get_tightbbox(renderer)
        if box is not None:
            assert edge.containsx(box.x0) and edge.containsx(box.x1) and \
                edge.containsy(box.y0) and edge.containsy(box.y1), (artist, box, fig.bbox)
    for ax in fig.axes:
        assert not list(_cut_markers(ax)), name


def _ink(artist, renderer):
    """What an error bar's ``artist`` covers [px]: its cap (a '_' marker, whose window extent
    is the marker's square) its horizontal stroke only, its bar (a LineCollection, which has
    no window extent of its own) its segments with their width."""
    import numpy as np
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D
    from matplotlib.transforms import Bbox

    scale = artist.figure.dpi / 72.0
    if isinstance(artist, LineCollection):
        xy = artist.get_transform().transform(np.concatenate(artist.get_segments()))
        pad = max(artist.get_linewidths()) * scale / 2
        return Bbox([xy.min(axis=0) - pad, xy.max(axis=0) + pad])
    if not (isinstance(artist, Line2D) and artist.get_marker() == "_"):
        return artist.get_window_extent(renderer)
    half_w, half_h = artist.get_markersize() * scale / 2, artist.get_markeredgewidth() * scale / 2
    (x, y), = artist.get_transform().transform([(artist.get_xdata()[0],
                                                  artist.get_ydata()[0])])
    return Bbox([[x - half_w, y - half_h], [x + half_w, y + half_h]])


def _all_hunt(p):
    """The plant's probability as if every valid sample hunted (a '30/30' bar at 100 %)."""
    import dataclasses

    from fi_design.studies.scatter import wilson_interval

    low, high = wilson_interval(p.valid, p.valid, p.confidence)
    return dataclasses.replace(p, hunting=p.valid, probability=1.0, low=low, high=high)


@pytest.mark.parametrize("rc", ["report", "default"])
@pytest.mark.parametrize("counts", ["as computed", "all hunt"])
def test_robustness_counts_stand_clear_of_the_error_bars(paper_confirmed_design, rc, counts):
    """The robustness bar chart wrote each bar's count ('30/30') with its baseline 2 % of the
    axis above the interval's top: its descent (the slash) sat on the error bar's cap, 1.6 pt
    from it for the paper setup's 96/100. The counts now stand at least 3 pt clear of every
    error bar and inside the axes, in the report's style and matplotlib's default (the study's
    own figure file)."""
    import contextlib
    import dataclasses

    import matplotlib

    study = paper_confirmed_design.robustness.study
    if counts == "all hunt":
        study = dataclasses.replace(study, isolated=_all_hunt(study.isolated),
                                    not_isolated=_all_hunt(study.not_isolated))
    style = matplotlib.rc_context(plots.REPORT_RC) if rc == "report" else \
        contextlib.nullcontext()
    with style:
        fig = plots.robustness_figure(study, title="" if rc == "report" else None)
    renderer = _drawn(fig)
    ax = fig.axes[0]
    labels = [t for t in ax.texts if "/" in t.get_text()]
    assert len(labels) == 2
    bars = [_ink(a, renderer) for c in ax.containers if hasattr(c, "has_xerr")
            for a in (*c.lines[1], *c.lines[2])]  # caps and bars (a bar has no marker)
    assert bars
    clear = 3.0 * fig.dpi / 72.0  # 3 pt of white between a count and any error bar
    for label in labels:
        box = label.get_window_extent(renderer)
        assert ax.bbox.containsy(box.y1), label.get_text()
        for bar in bars:
            assert not box.padded(clear).overlaps(bar), (label.get_text(), box, bar)
