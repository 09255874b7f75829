"""The console summaries read at 80 columns as at 120: nothing cut to "…", lengths in the
unit that reads (1.37 mm, not 1.37e+03 um), every line within the terminal.

The commands run through typer's CliRunner with ``COLUMNS`` fixed, as a terminal of that
width would set it.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from rich.console import Console
from typer.testing import CliRunner

from fi_design import console as con
from fi_design.cli.app import app

from conftest import EXAMPLES, sharing_designs

runner = CliRunner()

#: What rich prints where it cuts a cell short.
ELLIPSIS = ("\u2026", "...")


def _run(args: list[str], width: int) -> str:
    r = runner.invoke(app, args, env={"COLUMNS": str(width), "FI_DESIGN_DEBUG": "1"})
    assert r.exit_code == 0, r.output
    return r.output


def _readable(text: str, width: int) -> None:
    for line in text.splitlines():
        assert len(line.rstrip()) <= width, f"wider than {width}: {line!r}"
        for mark in ELLIPSIS:
            assert mark not in line, f"cut short: {line!r}"
    assert not re.search(r"\d\.?\d*e[+-]0?\d+ [uµ]m", text), "a length in powers of ten of um"


#: The example whose design search (its recommendation) is printed, at 80 columns: the
#: paper setup's advice holds every row and sentence of the no-isolator example's (a guide
#: built from stock, the stroke, the crossover, what binds it) and the least change.
SEARCHED = "paper_setup"


@pytest.fixture(scope="module")
def design_outputs(industrial_quick):
    """The design summary of every example with a stage of its own, at 80 and 120 columns
    (the recommendation a failing spec adds is read at the narrow width only, for
    :data:`SEARCHED`); the industrial axis with conftest's ``INDUSTRIAL_ROBUSTNESS``, from
    the copy of the example in a folder of its own (run from there: a short path)."""
    folder = industrial_quick.parent
    specs = {"paper_setup": str(EXAMPLES / "paper_setup.yaml"),
             "no_isolator": str(EXAMPLES / "no_isolator.yaml"),
             "industrial_axis": "industrial_axis.yaml"}
    out = {}
    with sharing_designs(), pytest.MonkeyPatch.context() as patch:
        patch.chdir(folder)  # an example's design computed once, printed at both widths
        for name, spec in specs.items():
            for width in (80, 120):
                searched = width == 80 and name == SEARCHED
                out[name, width] = _run([spec] + ([] if searched else ["--no-recommend"]),
                                        width)
    return out


@pytest.mark.parametrize("name", ["paper_setup", "no_isolator", "industrial_axis"])
@pytest.mark.parametrize("width", [80, 120])
def test_design_summary_reads_at_the_terminal_width(design_outputs, name, width):
    text = design_outputs[name, width]
    _readable(text, width)
    for words in ("Checks", "Status", "Value", "Limit", "Unit", "Limit case", "PM [deg]",
                  "Nonlinear confirmation", "Verdict", "Hunting cycles in [10 s, 20 s)",
                  "Amplitude, peak to peak", "Final error", "No move hunts from", "Moves ending in",
                  "Conclusion"):
        assert words in text, (words, text)
    # the outcomes of both plants and of the cross-check are printed whole: the outcome with
    # the loop in mind (a loop without integrator at rest within its static error is not
    # "stuck", whatever the metric alone says)
    row = next(ln for ln in text.splitlines() if ln.strip().startswith("Spec's motion: outcome"))
    word = r"(settled|hunting|stuck|undetermined|static error)"
    assert re.search(rf"{word}\s+{word}\s*$", row), row
    assert "stuck" not in row or name != "industrial_axis", row


def test_hunting_amplitude_in_millimetres(design_outputs):
    for width in (80, 120):
        text = design_outputs["no_isolator", width]
        row = next(ln for ln in text.splitlines() if "Amplitude, peak to peak" in ln)
        assert re.search(r"\[mm\]\s.*\s1\.37\s*$", row), row   # 1370 um reads as 1.37 mm
        assert "1.37e+03" not in text
        cycles = next(ln for ln in text.splitlines() if "Hunting cycles in" in ln)
        assert re.search(r"\s0\s+5\s*$", cycles), cycles  # suggested isolator 0, without 5


def test_checks_show_scaled_values_with_the_requirement(design_outputs):
    text = design_outputs["paper_setup", 80]
    assert re.search(r"Flexure stress at full stroke\s+PASS\s+25\.52\s+≤ 300\s+MPa",
                     text), text
    assert re.search(r"PASS\s+6667\s+≤ 13333\s+N/m", text)


def test_every_check_label_and_message_is_whole_at_80_columns(design_outputs, paper_spec):
    import fi_design

    with sharing_designs():  # the paper setup's design the command printed (design_outputs)
        design = fi_design.design(paper_spec, recommend=False)
    rec = Console(width=80, record=True, color_system=None, legacy_windows=False)
    rec.print(con.checks_table(design.checks, cases={c.name: c for c in design.loop.cases}))
    flat = " ".join(rec.export_text().split())
    assert design.checks
    for check in design.checks:
        assert " ".join(check.message.split()) in flat, check.message


def test_study_summaries_read_at_80_columns(paper_spec_path, tmp_path):
    sweep = _run(["sweep", str(paper_spec_path), "--x", "controller.crossover=4 Hz:12 Hz:3",
                  "--y", "isolator.stroke=0.1 mm:0.3 mm:2", "-j", "1"], 80)
    _readable(sweep, 80)
    flat = " ".join(sweep.split())
    assert "columns: Crossover frequency [Hz], rows: Isolator stroke [mm]" in flat
    rob = _run(["robustness", str(paper_spec_path), "--samples", "2", "--scatter",
                "friction.static=10%", "-j", "1"], 80)
    _readable(rob, 80)
    for words in ("Probability of hunting", "95 % Wilson interval", "undetermined",
                  "with isolator", "without isolator"):
        assert words in rob, (words, rob)


def test_reconcile_and_identify_summaries_read_at_80_columns():
    rec = _run(["reconcile", str(EXAMPLES / "measured_stage.yaml"),
                str(EXAMPLES / "measured_trace.csv")], 80)
    _readable(rec, 80)
    assert "position_dependent_friction" in rec
    assert re.search(r"position_rms_move\s+µm\s", rec), "lengths of the gap table in µm"
    assert re.search(r"wavelength = 5\.0000\d+ ± 0\.0000\d+\s+mm", rec), "to the error's last digit"
    # no bare SI in the headline, the noise levels in reading units
    assert "SI" not in rec and "wavelength = 0.005" not in rec
    assert re.search(r"Noise: position [\d.]+\s+µm", rec), rec
    ident = _run(["identify", str(EXAMPLES / "measured_trace.csv"), "--spec",
                  str(EXAMPLES / "measured_stage.yaml")], 80)
    _readable(ident, 80)
    assert "Identifiable" in ident and "N·s/m" in ident




def test_a_wide_map_prints_whole_axis_values_in_blocks(paper_spec_path):
    """At 80 columns the sweep's axis labels read '6.…', '10…' (and '2.…' at 120)."""
    for width in (80, 120):
        sweep = _run(["sweep", str(paper_spec_path), "--x", "controller.crossover=2 Hz:20 Hz:20",
                      "--y", "isolator.stroke=0.1 mm:0.3 mm:2", "-j", "1"], width)
        _readable(sweep, width)
        headers = [ln for ln in sweep.splitlines() if ln.strip().startswith("[mm]")]
        values = [float(v) for ln in headers for v in ln.split()[1:]]
        assert values == pytest.approx([2 + 18 * i / 19 for i in range(20)], rel=6e-3), headers


def test_a_map_too_wide_to_print_names_its_file(paper_spec_path, tmp_path, monkeypatch):
    # a path relative to the working folder: a temporary folder's full path (longer under
    # pytest-xdist) is cut across lines at 80 columns
    monkeypatch.chdir(tmp_path)
    csv = Path("line.csv")
    out = _run(["sweep", str(paper_spec_path), "--x", "controller.crossover=2 Hz:20 Hz:70",
                "--csv", str(csv), "-j", "1"], 80)
    flat = " ".join(out.split())
    assert f"the map has 70 columns, too many to print here: see {csv}" in flat


def test_the_drive_stiffness_line_names_its_source_without_nested_parentheses(design_outputs):
    """It read 'chosen k = 6667 N/m (given in the spec (isolator.stiffness))'."""
    text = " ".join(design_outputs["paper_setup", 120].split())
    assert "chosen k = 6667 N/m, given in the spec (isolator.stiffness), flexure force" in text
    assert "(given in the spec (isolator.stiffness))" not in text
