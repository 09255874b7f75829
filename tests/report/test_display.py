"""fi_design.display: one home for numbers and units, so that every place reads alike."""

from __future__ import annotations

import ast
import doctest
import re
from pathlib import Path

import pytest

from fi_design import display
from fi_design.display import NBSP, number, quantities, quantity, scale, with_error

#: A length with its unit as the package prints it (µm or mm; lengths are never printed in m).
LENGTH = re.compile(r"(-?[\d.]+)[ \u00a0](µm|mm)\b")


def test_doctests():
    failures, tried = doctest.testmod(display)
    assert tried >= 8 and failures == 0


@pytest.mark.parametrize("value,text", [
    (13333.33, "13333"), (0.3, "0.3"), (2.0, "2"), (3.2e-8, f"3.2{NBSP}×{NBSP}10⁻⁸"),
    (1.37e6, f"1.37{NBSP}×{NBSP}10⁶"), (0.00134799, "0.001348"), (float("inf"), "∞"),
    (float("nan"), "n/a"), (5, "5"), (None, "–"), (True, "yes"), (999999.7, f"1{NBSP}×{NBSP}10⁶"),
    (33073.4, "33073"), (-0.6247, "-0.6247"),
])
def test_numbers(value, text):
    assert number(value) == text


@pytest.mark.parametrize("value,unit,text", [
    (1.366e-3, "m", "1.366 mm"), (2.52e-8, "m", "0.0252 µm"), (1.4e-12, "m", "< 0.001 µm"),
    (-6.25e-4, "m", "-0.625 mm"), (0.0, "m", "0 mm"), (None, "m", "–"),
    (3.155e7, "Pa", "31.55 MPa"), (3e-3, "m/s", "3 mm/s"), (2.5, "s", "2.5 s"),
    (100.5, "N*s/m", "100.5 N·s/m"), (47.31, "deg", "47.31°"),
])
def test_quantities(value, unit, text):
    assert quantity(value, unit) == text


def test_values_read_together_share_one_unit():
    assert scale("m", [22e-6, 278e-6, 300e-6]) == ("mm", 1e3)
    assert quantities([22e-6, 278e-6, 300e-6], "m", 3) == ["0.022 mm", "0.278 mm", "0.3 mm"]
    assert quantities([22e-6, 31e-6], "m") == ["22 µm", "31 µm"]
    # the value to the error's last digit, both plain: "5 ± 3.1 x 10^-5 mm" read as 5e-5 mm
    assert with_error(0.005, 3.1e-8, "m") == "5.000000 ± 0.000031 mm"
    assert with_error(0.800041, 1.2e-4, "rad") == "0.80004 ± 0.00012 rad"
    assert with_error(0.768, 21.9, "kg") == "1 ± 22 kg"  # the error swamps the decimals
    assert with_error(2.0e6, 3.0e3, "N/m") == f"2{NBSP}×{NBSP}10⁶ ± 3000 N/m"  # not plain


def test_an_effect_value_and_its_error_share_a_unit():
    """The gap report printed 'wavelength = 5 mm ± 0.031 µm': one value in two units."""
    from fi_design.report.gap import _params_text

    text = _params_text("position_dependent_friction", {"amplitude": 0.25, "wavelength": 0.005},
                        {"amplitude": 1.1e-5, "wavelength": 3.1e-8})
    wave = text.split("wavelength = ")[1]
    assert wave.count("mm") == 1 and "µm" not in wave, text
    assert wave.startswith("5.000000 ± 0.000031"), text  # to the error's last digit


def test_prose_and_tables_print_a_number_alike(paper_spec, capsys):
    """ki read 3.307e+04 in the conclusion and 33073 in the table; one form now."""
    from fi_design.console import make_console, print_design
    from fi_design.guideline.evaluate import evaluate as design
    from fi_design.spec.file import with_values

    spec = with_values(paper_spec, {"controller.crossover": "10 Hz"})
    result = design(spec, confirm=False)
    ki = result.pid.gains.ki
    assert ki > 1e4
    assert f"ki = {number(ki)} N/(m\u00b7s)" in result.conclusion, result.conclusion
    assert "e+0" not in result.conclusion
    print_design(make_console(), result)
    out = capsys.readouterr().out
    assert number(ki) in out and "e+0" not in out


def test_end_stop_figure_unit_matches_its_note(paper_confirmed_design):
    """The key figure said 22 µm beside a deflection of 0.278 mm."""
    from fi_design.report.checks import key_figures

    row = next(r for r in key_figures(paper_confirmed_design)
               if r["label"].startswith("End-stop clearance"))
    units = {u for _, u in LENGTH.findall(row["note"])}
    assert units == {row["unit"]}, row


def test_verdict_sentence_gives_its_lengths_in_one_unit(paper_confirmed_design):
    reason = next(r.text for r in paper_confirmed_design.verdict.reasons
                  if r.source == "end_stop_clearance")
    units = {u for _, u in LENGTH.findall(reason)}
    assert len(units) == 1 and " um" not in reason, reason


def test_sentences_of_the_metric_and_the_stage_give_lengths_in_micrometres_and_millimetres():
    """The hunting metric's reasons and the stage's sentences write µm, never "um"."""
    import numpy as np

    from fi_design.simulation.metrics import hunting_metrics
    from fi_design.results.stage import length_range, length_text

    t = np.linspace(0.0, 20.0, 2001)
    settled = hunting_metrics(t, 2e-6 * np.exp(-t), settle_band=1e-5)
    resting = hunting_metrics(t, np.full_like(t, 3e-5), settle_band=1e-5)
    for reason in (settled.reason, resting.reason):
        assert " um" not in reason and LENGTH.search(reason), reason
    assert "10 µm" in settled.reason and "30 µm" in resting.reason
    assert length_text(1.8026e-3) == "1.8 mm" and length_text(2.2e-5) == "22 µm"
    assert length_range(4e-4, 5e-2) == "0.4 to 50 mm"
    assert length_range(1e-5, 5e-5) == "10 to 50 µm"


# --------------------------------------------------------------------------- the one home
# Units are converted for readers in fi_design.display only: an f-string that scales a value
# by a power of ten, or prints a formatted value followed by a scaled unit, converts by hand.

_SCALES = {1e3, 1e6, 1e9, 1e-3, 1e-6, 1e-9}
_SCALED_UNIT = re.compile(
    r"^\s?(mm|\u00b5m|um|nm|ms|\u00b5s|mm/s|MPa|GPa|kPa|N/mm)(?![A-Za-z])")


def _scaled(node) -> bool:
    return any(isinstance(n, ast.BinOp) and isinstance(n.op, (ast.Mult, ast.Div))
               and any(isinstance(s, ast.Constant) and isinstance(s.value, (int, float))
                       and not isinstance(s.value, bool) and float(s.value) in _SCALES
                       for s in (n.left, n.right))
               for n in ast.walk(node))


def hand_conversions(source: str) -> list[str]:
    """Formatted values of f-strings that convert a unit by hand: ``{x * 1e3:.3g} mm``,
    ``{number(x * 1e3)} mm``, ``{band:g} µm`` (a value scaled before)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.JoinedStr):
            continue
        for i, part in enumerate(node.values):
            if not isinstance(part, ast.FormattedValue):
                continue
            after = node.values[i + 1] if i + 1 < len(node.values) else None
            unit_after = isinstance(after, ast.Constant) and _SCALED_UNIT.match(str(after.value))
            if _scaled(part.value) or unit_after:
                found.append(f"{part.lineno}: {ast.unparse(part.value)}")
    return found


def test_the_scan_finds_each_hand_conversion():
    planted = ('s = 3e-4\nprint(f"a {s * 1e3:.3g} mm stroke")\n'
               'print(f"{number(1e6 * s, 3)} um")\nband = s * 1e6\nprint(f"+-{band:g} \u00b5m")\n'
               'print(f"{s / 1e6:.4g} MPa")\n')
    assert [f.split(":")[0] for f in hand_conversions(planted)] == ["2", "3", "5", "6"]
    fine = ('print(f"a {quantity(s, \'m\', 3)} stroke, {100 * f:.3g} %, {k:.4g} N/m, '
            '{t:.3g} s")\n')
    assert hand_conversions(fine) == []


def test_units_are_converted_in_display_only():
    import fi_design

    package = Path(fi_design.__file__).parent
    offenders = [f"{p.relative_to(package)}:{hit}" for p in sorted(package.rglob("*.py"))
                 if p.name != "display.py"
                 for hit in hand_conversions(p.read_text(encoding="utf-8"))]
    assert not offenders, ("convert units with fi_design.display (quantity, quantities, "
                           "with_error): " + "; ".join(offenders))


# Numbers are formatted for readers in fi_design.display only: a format spec that presents a
# number (``{x:.3g}``, ``{f:.0%}``, ``"%.2f" % x``, ``format(x, "g")``, ``"{:.1f}".format(x)``)
# or a percentage made by hand (``{100 * f:.3g} %``, ``{number(100 * f)} %``) outside it
# formats by hand. Layout alone (``{name:<20}``) is not a number's format.

_NUMERIC_SPEC = re.compile(r"[.,_%eEfFgGdnxXbo+]|^#?0\d")
_PERCENT_STYLE = re.compile(r"%[-+ #0]*\d*(\.\d+)?[eEfFgGdixXo]")
_BRACE_SPEC = re.compile(r"\{[^{}]*:([^{}]*)\}")


def _spec_text(spec) -> str:
    return "".join(str(v.value) if isinstance(v, ast.Constant) else "{}" for v in spec.values)


def _numeric(spec: str) -> bool:
    layout = spec.lstrip("<>^=") if len(spec) < 2 or spec[1] not in "<>^=" else spec[2:]
    return bool(layout) and bool(_NUMERIC_SPEC.search(layout.replace("{}", "")))


def _by_hundred(node) -> bool:
    return any(isinstance(n, ast.BinOp) and isinstance(n.op, ast.Mult)
               and any(isinstance(s, ast.Constant) and s.value in (100, 100.0)
                       for s in (n.left, n.right)) for n in ast.walk(node))


def hand_formats(source: str) -> list[str]:
    """Numbers formatted outside fi_design.display: numeric format specs in f-strings,
    ``%``-formatting, ``str.format`` and ``format()`` with a numeric spec, hand percentages."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.JoinedStr):
            for i, part in enumerate(node.values):
                if not isinstance(part, ast.FormattedValue):
                    continue
                after = node.values[i + 1] if i + 1 < len(node.values) else None
                percent_after = isinstance(after, ast.Constant) and str(after.value).lstrip(
                    " \u00a0").startswith("%")
                if (part.format_spec is not None and _numeric(_spec_text(part.format_spec))) or (
                        percent_after and _by_hundred(part.value)):
                    found.append(f"{part.lineno}: {ast.unparse(part)}")
        elif (isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod)
              and isinstance(node.left, ast.Constant) and isinstance(node.left.value, str)
              and _PERCENT_STYLE.search(node.left.value)):
            found.append(f"{node.lineno}: {ast.unparse(node)}")
        elif isinstance(node, ast.Call) and (
                (isinstance(node.func, ast.Attribute) and node.func.attr == "format"
                 and isinstance(node.func.value, ast.Constant)
                 and isinstance(node.func.value.value, str)
                 and any(_numeric(s) for s in _BRACE_SPEC.findall(node.func.value.value)))
                or (isinstance(node.func, ast.Name) and node.func.id == "format"
                    and len(node.args) > 1)):
            found.append(f"{node.lineno}: {ast.unparse(node)}")
    return found


def test_the_scan_finds_each_hand_format():
    planted = ('print(f"{x:.3g} N")\nprint(f"{f:.0%}")\nprint("%.2f" % x)\n'
               'print(format(x, "g"))\nprint("{:.1f} dB".format(x))\n'
               'print(f"{100 * f:.3g} %")\nprint(f"{number(f * 100, 3)}%")\nprint(f"{n:,}")\n'
               'print(f"{x:{w}.{d}f}")\nprint(f"{n:04X}")\nprint(f"{x:8.2f}")\n')
    assert [f.split(":")[0] for f in hand_formats(planted)] == [str(i) for i in range(1, 12)]
    fine = ('print(f"{name:<20} {number(x, 3)} N {percent(f)} {fixed(g)} dB {plain(k)}")\n'
            'print(f"{label:>{width}}")\nprint("%s of %d" if a else "%")\n'
            'print(f"{100 * f} cases")\nprint("{} and {}".format(a, b))\n')
    assert hand_formats(fine) == []


def test_numbers_are_formatted_in_display_only():
    import fi_design

    package = Path(fi_design.__file__).parent
    offenders = [f"{p.relative_to(package)}:{hit}" for p in sorted(package.rglob("*.py"))
                 if p.name != "display.py"
                 for hit in hand_formats(p.read_text(encoding="utf-8"))]
    assert not offenders, (f"{len(offenders)} numbers formatted by hand; format them with "
                           "fi_design.display (number, quantity, percent, fixed, plain): "
                           + "; ".join(offenders))


def test_a_run_that_did_not_complete_shows_no_cycles_or_final_error(paper_confirmed_design):
    """Sampled at 1 Hz the loop diverges: the table read '0' cycles and a final error of
    2015 mm (the last finite sample of the diverging run). Such a run shows no values."""
    from dataclasses import replace

    from fi_design.report.design import _plant_rows

    sim = paper_confirmed_design.simulation
    failed = replace(sim, isolated=replace(sim.isolated, success=False))
    ok, bad = (next(r for r in _plant_rows(s) if r["plant"].startswith("with isolator"))
               for s in (sim, failed))
    assert ok["cycles"] == 0 and ok["final_error"] is not None
    assert bad["cycles"] is None and bad["final_error"] is None and bad["amplitude"] is None


# The damping unit and the integral gain's were written 'N s/m' and 'N/(m s)' in the checks,
# the conclusion, the console's gains table, the docs and errors, and 'N·s/m', 'N/(m·s)'
# (fi_design.display) in the report's tables: one spelling, display's, wherever it is written.
_OTHER_SPELLINGS = re.compile(r"N s/m|N/\(m s\)")


def test_the_damping_unit_reads_as_display_writes_it_in_report_and_console(
        paper_confirmed_design):
    from rich.console import Console

    from fi_design import report
    from fi_design.console import print_design

    assert display.unit_text("N*s/m") == "N\u00b7s/m"
    assert display.unit_text("N/(m*s)") == "N/(m\u00b7s)"
    html = report.render_html(report.build_context(paper_confirmed_design, date="2026-01-01",
                                                   figures=False))
    out = Console(width=200, record=True)
    print_design(out, paper_confirmed_design)
    console = out.export_text()
    ki = quantity(paper_confirmed_design.pid.controller.ki, "N/(m*s)")
    for name, text in (("report", html), ("console", console),
                       ("conclusion", paper_confirmed_design.conclusion)):
        assert not _OTHER_SPELLINGS.search(text), (name, _OTHER_SPELLINGS.findall(text))
        assert f"ki = {ki}" in text.replace(NBSP, " "), name
    assert "ki [N/(m\u00b7s)]" in console and "kd [N\u00b7s/m]" in console


def test_the_damping_unit_reads_as_display_writes_it_in_docs_and_errors(paper_spec):
    from fi_design.errors import SpecError
    from fi_design.model import resolve

    root = Path(__file__).resolve().parents[2]
    for page in [root / "README.md", *sorted((root / "docs").glob("*.md"))]:
        found = _OTHER_SPELLINGS.findall(page.read_text(encoding="utf-8"))
        assert not found, (page.name, found)
    with pytest.raises(SpecError) as info:
        resolve(paper_spec).at(damping=-1.0)
    assert "must be at least 0 N\u00b7s/m" in str(info.value)
