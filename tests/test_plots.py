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
    yield "scan", plots.scan_figure(sim, design.spec)
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
    assert len(seen) == 14


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
    assert plots.axis_label("controller.crossover", "Hz") == "controller.crossover [Hz]"
    assert plots.axis_label("stage.mass", "kg") == "stage.mass [kg]"
    assert plots.nice_ticks(0.05, 1.0) == [0.05, 0.1, 0.2, 0.5, 1.0]
    assert plots.plain_tick(0.001) == "0.001" and plots.plain_tick(1000.0) == "1000"


def test_plots_never_use_pyplot():
    """The module imports no pyplot, and drawing a figure does not load it.

    (python-control imports pyplot itself, so the check draws a study's figures, which need
    no python-control.)
    """
    source = (ROOT / "fi_design" / "plots.py").read_text(encoding="utf-8")
    assert not re.search(r"^\s*(import|from)\s+matplotlib(\.pyplot|\s+import\s+pyplot)|plt\.",
                         source, flags=re.MULTILINE)
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
