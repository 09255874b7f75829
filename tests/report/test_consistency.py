"""The design report says one thing once: a quantity quoted in two sections (the verdict box,
the checks table, the step sections, the guide, the captions) is the same number in both.

Each test reads the context of the paper setup's report (computed once per session by
``paper_confirmed_design``, figures off) and compares what two of its parts state.
"""

from __future__ import annotations

import math
import re

import pytest

from fi_design import report

DATE = "2026-01-01"


@pytest.fixture(scope="module")
def ctx(paper_confirmed_design) -> dict:
    return report.build_context(paper_confirmed_design, date=DATE, figures=False)


def _check(ctx: dict, name: str) -> dict:
    return next(r for g in ctx["verdict"]["groups"] for r in g["rows"] if r["name"] == name)


def _step_row(ctx: dict, number: int, start: str) -> dict:
    step = next(s for s in ctx["steps"] if s["number"] == number)
    return next(r for r in step["results"] if r["quantity"].startswith(start))


def test_one_required_parasitic_frequency(ctx):
    """Step 2, step 3, the flexure check and the guide's mode table ask the same frequency of
    a parasitic mode (step 3 quoted the sizing's 46.11 Hz and the guide 3 x 8 = 24 Hz while
    step 2 and the check ask 3 x 15.43 = 46.28 Hz)."""
    limit = _check(ctx, "flexure.modes")["limit"]
    assert _step_row(ctx, 2, "lowest allowed parasitic frequency")["value"] == limit
    assert _step_row(ctx, 3, "required parasitic frequency")["value"] == limit
    required = {m["required"] for m in ctx["guide"]["modes"] if m["required"] is not None}
    assert required == {limit}
    assert ctx["guide"]["required"] == limit


def test_the_guide_names_the_stiffness_the_analysis_uses(ctx, paper_confirmed_design):
    """The guide section said the guide's net 6627 N/m is 'the joint the loop and the simulation
    see', the step 3 check that the analysis simulates the joint's given 6667 N/m."""
    joint = paper_confirmed_design.model.joint.stiffness
    net = paper_confirmed_design.flexure.mechanics.net_drive_stiffness
    assert joint != net
    words = ctx["guide"]["gravity"]
    assert "the joint the loop and the simulation see" not in words
    assert f"use the joint's {report.filters.qty(joint, 'N/m')}" in words
    assert "the joint's 6667 N/m that the analysis simulates" in _check(ctx, "flexure.joint")[
        "message"]


def test_the_bode_caption_says_also_only_beside_a_drawn_crossover(ctx):
    """Case 4 crosses 0 dB once, at 0.00135 Hz (the linear table: 1 crossing; the verdict's
    note: 'only at'), but the Bode caption said it 'also crosses 0 dB' there."""
    case4 = next(c for c in ctx["linear"]["cases"] if c["number"] == 4)
    assert case4["crossovers"] == 1
    caption = ctx["linear"]["bode"]["caption"]
    assert "case 4 crosses 0 dB at 0.00135\u00a0Hz" in caption
    assert "also" not in caption


def test_the_forces_table_says_it_lists_only_some_moves(ctx, paper_confirmed_design):
    """'17 of 25 moves run the joint onto its end stop' above a table of 13 moves, 9 of them on
    the stop, without saying the table left moves out."""
    forces = ctx["nonlinear"]["forces"]
    n = len(paper_confirmed_design.simulation.forces.moves)
    assert len(forces["rows"]) < n
    assert f"The table lists {len(forces['rows'])} of the {n} moves" in forces["intro"]


def _robustness_reason(ctx: dict) -> str:
    return next(r["text"] for r in ctx["verdict"]["reasons"]
                if r["text"].startswith("Under friction scatter"))


def _robustness_assumption(ctx: dict) -> str:
    return next(t for t in ctx["assumptions"]["model"] if t.startswith("Robustness:"))


def test_the_scatter_on_k_is_stated_alike_in_the_verdict_and_the_assumptions(ctx):
    """The verdict's reason and the assumptions name the same spread of k (6 %, the stock's
    thickness tolerance on t = 0.5 mm), with the same sign as the other reasons (±)."""
    assert "\u00b16 % on k" in _robustness_reason(ctx)
    assert "+-" not in _robustness_reason(ctx)
    assert "the drive stiffness (6" in _robustness_assumption(ctx)
    assert "the flexure's stock tolerance" in _robustness_assumption(ctx)


def test_without_the_isolator_k_does_not_scatter_on_the_stage_as_specified(
        paper_confirmed_design):
    """A stage without isolator was said to scatter '+-5 % on k' (only the comparison's isolator
    has a k), and the assumptions called that 5 % 'the flexure's stock tolerance' for specs
    without a flexure."""
    import dataclasses

    r = paper_confirmed_design.robustness
    plain = dataclasses.replace(r, plant="non_isolated", scatter={**r.scatter,
                                                                  "isolator.stiffness": 0.05})
    result = dataclasses.replace(paper_confirmed_design, robustness=plain, flexure=None)
    from fi_design.guideline.verdict import _scatter_words
    from fi_design.report.assumptions import _robustness

    assert " on k" not in _scatter_words(plain)
    words = _robustness(result)
    assert "stock tolerance" not in words
    assert ("the drive stiffness (5 %, the default without a sized flexure, of the isolator "
            "simulated for comparison only)") in words


def test_a_phase_margin_outside_the_band_is_not_denied_beside_its_value(ctx):
    """The checks table showed case 4's phase margin, 90.12°, in its value column beside a
    message saying the case has 'no phase margin'; the table of every crossing gives it too
    (90.1° at 0.00135 Hz, below the band). The message now says it is there but not judged."""
    row = _check(ctx, "phase_margin.stuck_limited")
    assert row["status"] == "INFO" and math.isfinite(row["value"])
    assert "no phase margin" not in row["message"]
    assert f"its phase margin there, {report.filters.num(row['value'], 3)} deg" in row["message"]


def test_the_flexure_factors_read_alike_in_step_3_the_check_and_the_conclusion(ctx):
    """Step 3 quoted the stress margin 11.75 and the buckling factor 21.83, the flexure checks,
    the conclusion, the guide and the assumptions 11.8 and 21.8."""
    margin = _step_row(ctx, 3, "stress margin")["value"]
    factor = _step_row(ctx, 3, "buckling factor")["value"]
    assert f"(margin x{margin})" in _check(ctx, "flexure.stress")["message"]
    assert f"a stress margin of {margin} " in ctx["verdict"]["conclusion"]
    assert f"factor {factor}," in _check(ctx, "flexure.buckling")["message"]
    assert f"{factor} times the weight" in ctx["guide"]["gravity"]


def test_the_end_stop_force_reads_alike_in_the_check_and_the_forces_section(ctx):
    """The forces section said 'a contact force of up to 9.612 N', the end-stop check '9.61 N'."""
    row = _check(ctx, "end_stop_force")
    words = report.filters.qty(row["value"], "N")
    assert f"with a contact force of up to {words}" in ctx["nonlinear"]["forces"]["intro"]
    assert f"the largest contact force {words.replace(chr(0xa0), ' ')}" in row["message"]


def test_the_crossover_factor_figure_asks_the_hunting_margin(paper_confirmed_design):
    """The key figure asked '> 1' of design / lowest hunting-free crossover (green from 1 on)
    while the checks table judges it against requirements.hunting_margin (1.2): a design at
    1.1 read PASS in the verdict box beside a FAIL row."""
    import dataclasses

    from fi_design.report.checks import key_figures

    def figure(factor):
        m = dataclasses.replace(paper_confirmed_design.margins, crossover_factor=factor)
        rows = key_figures(dataclasses.replace(paper_confirmed_design, margins=m))
        return next(r for r in rows if r["label"].startswith("Crossover factor"))

    need = paper_confirmed_design.spec.requirements.hunting_margin
    assert need == 1.2
    assert figure(1.1)["requirement"].startswith("\u2265 1.2")
    assert figure(1.1)["css"] == "fail"
    assert figure(1.3)["css"] == "pass"
    assert figure(0.709)["css"] == "warn"


def test_the_legend_does_not_call_an_info_row_s_limit_a_requirement(ctx):
    """Step 1's row reads 'INFO, 3 N, limit < 1 N' (and says: 'a screening rule, not a
    requirement') under a legend saying 'the limit column states the requirement the value
    must meet'."""
    import html

    row = _check(ctx, "friction_gap")
    assert row["status"] == "INFO" and row["limit"] is not None
    text = html.unescape(report.render_html(ctx))
    assert "on an INFO row, the threshold the value is compared with, which it need not meet" \
        in text


def test_the_resting_deflection_keeps_its_sign_in_the_verdict(ctx):
    """The end-stop reason said 'joint deflection 0.278 mm of the 0.3 mm stroke', the key
    figure beside it and step 3 '-0.278 mm' (of the ±0.3 mm stroke)."""
    reason = next(r["text"] for r in ctx["verdict"]["reasons"]
                  if r["text"].startswith("The cart rests"))
    note = next(f["note"] for f in ctx["verdict"]["figures"]
                if f["label"] == "End-stop clearance at rest")
    assert note.replace("\u00a0", " ") in reason.replace("\u00a0", " ")
    assert "-0.278" in reason


@pytest.fixture(scope="module")
def no_isolator_steps():
    """Step 2 of examples/no_isolator.yaml (no isolator, no modes: the achievable crossover
    is not limited below the search cap), without the simulation."""
    from conftest import EXAMPLES, design_options, shared
    from fi_design.guideline.evaluate import evaluate
    from fi_design.report.steps import guideline_steps
    from fi_design.spec.file import load_spec

    spec = load_spec(EXAMPLES / "no_isolator.yaml")
    design = shared("design", spec, lambda: evaluate(spec, confirm=False),
                    *design_options(False, {}))
    assert design.crossover.limit_kind == "scan_limit"
    return design, guideline_steps(design, figures=False)


def test_a_search_cap_is_no_achievable_crossover(no_isolator_steps):
    """The verdict box says '≥ 1000 Hz ... a bound, not a result', step 2 said 'achievable
    crossover 1000 Hz' and f_c ≤ f_c,ach = 1000 Hz."""
    design, steps = no_isolator_steps
    step2 = next(s for s in steps if s["number"] == 2)
    row = next(r for r in step2["results"] if r["quantity"] == "achievable crossover")
    assert isinstance(row["value"], str) and row["value"].startswith("\u2265 1000")
    assert not any("f_c,ach = " in e["text"] for e in step2["equations"])


def _console_case_rows(design) -> dict:
    """The console's limit-case table of a design: case number -> its cells, as printed."""
    from rich.console import Console

    from fi_design import console

    cases = design.to_dict()["crossover"]["cases"]
    out = Console(width=200, record=True)
    out.print(console.cases_table(cases, {c.name: c.number for c in design.loop.cases}))
    rows = {}
    for line in out.export_text().splitlines():
        cells = line.split()
        if cells and cells[0].isdigit() and "cart" in line:
            rows[int(cells[0])] = line
    return rows


@pytest.mark.parametrize("gain_margin_fails", [False, True])
def test_one_rule_for_a_margin_outside_the_band(paper_confirmed_design, gain_margin_fails):
    """Case 4 crosses 0 dB only at 0.00135 Hz: the report's margins table showed – for its phase
    and delay margins (not judged, outside the band), the console 90.12 deg and 185.8 s. Both
    show – and say why, also beside a failing gain margin (the report showed the numbers
    then)."""
    import dataclasses

    from fi_design.report.design import _cases_table
    from fi_design.results import Status

    design = paper_confirmed_design
    stuck = next(c for c in design.crossover.cases if c.name == "stuck_limited")
    assert not stuck.in_band and stuck.criteria["phase margin"] == Status.INFO
    assert stuck.phase_margin_deg > 90 and stuck.delay_margin > 185
    if gain_margin_fails:
        stuck = dataclasses.replace(
            stuck, passed=False, failed=("gain margin",), status=Status.FAIL,
            criteria={**stuck.criteria, "gain margin": Status.FAIL})
        design = dataclasses.replace(design, crossover=dataclasses.replace(
            design.crossover, cases=tuple(stuck if c.name == stuck.name else c
                                          for c in design.crossover.cases)))
    why = "gain margin, outside the band" if gain_margin_fails else "outside the band"
    row = next(r for r in _cases_table(design) if r["description"] == stuck.description)
    assert (row["phase_margin"], row["delay_margin"], row["failed"]) == (None, None, why)
    assert row["gain_margin"] == stuck.gain_margin_db
    html = report.render_html(report.build_context(design, date=DATE, figures=False))
    table = html[html.index('<table class="margins">'):]
    shown = re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", table[
        table.index(stuck.description):table.index("</tr>", table.index(stuck.description))]))
    assert shown.split() == [*stuck.description.split(), report.num(stuck.crossover), "1",
                             "\u2013", report.num(stuck.gain_margin_db),
                             report.num(stuck.modulus_margin), "\u2013", "yes",
                             "FAIL" if gain_margin_fails else "INFO", *why.split()], shown
    number = next(c.number for c in design.loop.cases if c.name == stuck.name)
    cells = _console_case_rows(design)[number].split()
    status = "FAIL" if gain_margin_fails else "INFO"
    assert cells[-len(why.split()) - 6:] == [
        report.num(stuck.crossover), "\u2013", report.num(stuck.gain_margin_db),
        report.num(stuck.modulus_margin), "\u2013", status, *why.split()], cells
    from fi_design import console

    assert "outside its band, where the phase and delay margins are not judged" in (
        console.CASE_CAPTION)


def test_step_2_smallest_phase_margin_is_of_the_judged_cases(paper_confirmed_design):
    """Step 2's 'smallest phase margin at fc (all cases)' took case 4's phase margin too, which
    the margins table shows as – (its loop crosses 0 dB only outside the band): with that
    margin at 20 deg the step reported 20 deg that nothing judges. Now it is the smallest of
    the judged margins, and says so."""
    import dataclasses

    design = paper_confirmed_design
    cases = design.crossover.cases
    assert [c.criteria["phase margin"] for c in cases] == ["PASS", "PASS", "PASS", "INFO"]
    low = dataclasses.replace(cases[3], phase_margin_deg=20.0)
    design = dataclasses.replace(design, crossover=dataclasses.replace(
        design.crossover, cases=cases[:3] + (low,)))
    ctx = report.build_context(design, date=DATE, figures=False)
    row = _step_row(ctx, 2, "smallest phase margin")
    assert row["quantity"] == ("smallest phase margin at fc (the judged cases; case 4 crosses "
                               "0 dB only outside the loop's band, not judged)")
    assert row["value"] == min(c.phase_margin_deg for c in cases[:3]) == cases[1].phase_margin_deg
    table = [r["phase_margin"] for r in ctx["linear"]["cases"]]
    assert row["value"] == min(p for p in table if p is not None)
    gain = _step_row(ctx, 2, "smallest gain margin")
    assert gain["quantity"] == "smallest gain margin at fc (all cases)"


def test_the_nonlinear_tables_have_one_unit_per_column(ctx, paper_confirmed_design):
    """The spec-motion table read '0.0252 µm' over '1.37 mm' (amplitude) and '< 0.001 µm'
    over '-0.625 mm' (final error), and the console's rows alike: a column (a row of the
    console's transposed table) is in one unit, named once in its header."""
    from rich.console import Console

    from fi_design import console

    section = ctx["nonlinear"]
    sim = paper_confirmed_design.simulation
    iso, bare = sim.isolated.metrics, sim.non_isolated.metrics
    assert 0 < abs(iso.final_error) < 1e-9 and iso.amplitude < 1e-7 < 1e-4 < bare.amplitude
    heads = section["plant_heads"]
    assert heads == {"amplitude": "Amplitude (p-p) [mm]", "period": "Period [s]",
                     "settling_time": "Settling time [s]", "final_error": "Final error [mm]"}
    cells = [p["cells"] for p in section["plants"]]
    assert [c["final_error"] for c in cells] == ["< 1\u00a0\u00d7\u00a010\u207b\u2076",
                                                 report.num(bare.final_error * 1e3, 3)]
    assert [c["amplitude"] for c in cells] == [report.num(iso.amplitude * 1e3, 3),
                                               report.num(bare.amplitude * 1e3, 3)]
    assert section["stage_heads"] == {"amplitude": "Cycle (p-p) [mm]", "period": "Period [s]",
                                      "free_from": "No move hunts from [Hz]"}
    html = report.render_html(ctx)
    for head in (*heads.values(), *section["stage_heads"].values()):
        assert f'<th scope="col" class="num">{head}</th>' in html
    data = paper_confirmed_design.to_dict()
    out = Console(width=120, record=True)
    out.print(console.simulation_table(data["simulation"], stages=data["stage_hunting"]))
    text = out.export_text()
    for title in ("Cycle, peak to peak [mm]", "Amplitude, peak to peak [mm]",
                  "Final error x1 - r [mm]"):
        row = next(line for line in text.splitlines() if line.strip().startswith(title))
        assert "\u00b5m" not in row and " mm" not in row.replace(title, ""), row


@pytest.fixture(scope="module")
def robustness_ctx(paper_spec) -> dict:
    """The report context of a one-sample robustness study of the paper setup (about a
    second: one sample, with and without the isolator), with an absolute spread beside a
    relative one and a uniform distribution."""
    from fi_design.studies import Scatter, robustness

    result = robustness(paper_spec, [Scatter("friction.static", 0.1),
                                     Scatter("stage.mass", 0.05, relative=False)],
                        samples=1, seed=3, distribution="uniform", confidence=0.9)
    return report.build_context(result, date=DATE, figures=False)


def _cells(table: dict) -> list[list[str]]:
    return [[cell["text"] for cell in row] for row in table["rows"]]


def test_the_robustness_report_states_what_scattered(robustness_ctx):
    """The robustness report said only '1 samples of the spec with its values drawn around the
    nominal ones': not which values, by how much, in which distribution, with which seed, nor
    the confidence of its interval or the samples per verdict, all of which the console
    prints; a checker could not tell what the probability is of."""
    section = robustness_ctx["robustness"]
    text = " ".join(section["paragraphs"])
    assert "1 samples" not in text
    assert "uniform" in text and "seed 3" in text and "90 % Wilson interval" in text
    scatter = next(t for t in section["tables"] if t["caption"].startswith("Scattered"))
    assert [c["text"] for c in scatter["columns"]] == ["Spec value", "Spread (half-width)"]
    assert _cells(scatter) == [["friction.static", "10 % of nominal"],
                               ["stage.mass", "0.05\u00a0kg"]]
    verdicts = next(t for t in section["tables"] if t["caption"].startswith("Samples per"))
    rows = dict((r[0], r[1:]) for r in _cells(verdicts))
    assert set(rows) >= {"settled", "hunting", "stuck", "undetermined", "invalid", "failed"}
    assert sum(int(v[0]) for v in rows.values()) == 1


def test_the_checks_table_has_one_group_per_step(paper_confirmed_design):
    """The checks table headed 'Nonlinear confirmation (simulated hunting)' twice, split by
    the step 3 refinement's group: its groups followed the checks' order, not their steps."""
    from fi_design.report.checks import verdict

    groups = verdict(paper_confirmed_design)["groups"]
    steps = [g["step"] for g in groups]
    assert len(steps) == len(set(steps)), steps
    assert sum(len(g["rows"]) for g in groups) == len(paper_confirmed_design.checks)


@pytest.fixture(scope="module")
def effects_design():
    """examples/no_isolator.yaml with a 2 ms time_delay effect and a 1 um quantization effect,
    without the simulation: the linear steps analyse the loop with the delay (a delay of the
    loop) and without the quantization, the simulation carries both."""
    from conftest import EXAMPLES
    from fi_design.guideline.evaluate import evaluate
    from fi_design.spec.file import load_spec, with_values

    spec = with_values(load_spec(EXAMPLES / "no_isolator.yaml"),
                       {"effects": [{"type": "time_delay", "delay": "2 ms"},
                                    {"type": "quantization", "resolution": "1 um"}]})
    return evaluate(spec, confirm=False)


def _plain(text: str) -> str:
    return re.sub(r"\s+", " ", text.replace("\u00a0", " "))


#: What the console and the report say of the effect the linear analysis leaves out.
QUANTIZATION_LEFT_OUT = ("the spec's effect quantization (resolution = 1 µm); the linear "
                         "analysis (the gains, the margins, the crossover) leaves it out")


def test_the_console_names_the_effects_the_simulation_carries(effects_design):
    """A spec with a 2 ms time_delay effect: the console's PID line, its gains' caption and
    the conclusion said 'continuous, no controller delay', and that the linear analysis
    leaves the effect out, while the simulation adds it to controller.delay: a delay of the
    loop, which the margins now include. Each names the delay, and only the quantization as
    left out of the linear analysis."""
    from rich.console import Console

    from fi_design.console import print_design

    out = Console(width=120, record=True)
    print_design(out, effects_design)
    text = _plain(out.export_text())
    assert "no delay" not in text and "no controller delay" not in text
    # check, caption, conclusion
    assert text.count("continuous, delay 0.002 s of the effect time_delay") == 3, text
    assert "time_delay (delay = 0.002 s)" not in text
    # the PID check and the gains' caption, the cases' caption, the conclusion
    assert text.lower().count(QUANTIZATION_LEFT_OUT.lower()) == 4, text
    assert text.count("leaves it out") == 4


def test_the_report_names_the_effects_the_simulation_carries(effects_design):
    """The report's step 4 said 'continuous, no controller delay', and step 4, the linear
    section and the assumptions that the linear analysis leaves the time_delay effect out,
    which its margins now include."""
    ctx = report.build_context(effects_design, date=DATE, figures=False)
    step4 = _plain(next(s for s in ctx["steps"] if s["number"] == 4)["explanation"])
    assert "continuous, delay 0.002 s of the effect time_delay" in step4, step4
    assert QUANTIZATION_LEFT_OUT in step4, step4
    intro = _plain(ctx["linear"]["intro"])
    assert ("a Padé model of the 0.002 s loop delay, the spec's effect time_delay included "
            "(the margins of the loop without the spec's other effects: the simulation carries "
            + QUANTIZATION_LEFT_OUT + ")") in intro, intro
    text = " ".join(_plain(t) for t in _strings(ctx))
    assert "no delay" not in text and "without delay" not in text
    assert "time_delay (delay = 0.002 s)" not in text
    assert ("a continuous-time controller without a delay of its own; the spec's effect "
            "time_delay adds 0.002 s to the loop's delay, in the simulation and in the linear "
            "analysis") in text


def test_the_report_does_not_call_a_quantized_sensor_ideal(effects_design):
    """The assumptions said 'The sensor is ideal' beside a quantization effect, which the
    simulation carries: the controller sees the position in whole steps."""
    ctx = report.build_context(effects_design, date=DATE, figures=False)
    text = " ".join(_plain(t) for t in _strings(ctx))
    assert "sensor is ideal" not in text
    assert ("The sensor has no noise and no latency beyond the loop's delay, and resolves the "
            "position in steps of 1 µm (the spec's effect quantization).") in text


def _strings(node):
    """Every string in a report context."""
    if isinstance(node, str):
        yield node
    elif isinstance(node, dict):
        for v in node.values():
            yield from _strings(v)
    elif isinstance(node, (list, tuple)):
        for v in node:
            yield from _strings(v)


def test_each_crossing_of_the_sliding_loop_names_its_pid(ctx, paper_confirmed_design):
    """The hunting margin's two crossings read 'the sliding loop crosses 0 dB at 7.921 Hz and
    11.29 Hz', as if one loop crossed twice: they are the loop with the design's PID and
    with the PID at the hunting-free crossover. Console and report say which is which."""
    from rich.console import Console

    from fi_design.console import print_verdict

    mar = paper_confirmed_design.margins
    design, free = (report.num(f) for f in (mar.hunting_loop_crossover,
                                            mar.hunting_free_loop_crossover))
    note = _plain(next(f["note"] for f in ctx["verdict"]["figures"]
                       if f["label"].startswith("Crossover factor")))
    assert (f"crosses 0 dB at {design} Hz with the design's PID and at {free} Hz with the PID "
            "at the hunting-free crossover") in note, note
    out = Console(width=120, record=True)
    print_verdict(out, paper_confirmed_design)
    box = re.sub(r"[\s\u2500-\u257f]+", " ", out.export_text())  # the frame's lines
    assert (f"crosses 0 dB at {design} Hz with the design's PID, at {free} Hz with the PID at "
            "the hunting-free crossover") in box, box


def test_a_hunting_free_crossover_not_found_reads_not_found(paper_confirmed_design):
    """Where moves still hunt above the last fold the search followed, no hunting-free
    crossover was found; the boundary said kind 'bound' as for a cycle persisting to the top
    of the search, and the console's table said 'above the search', the verdict's margins
    'hunts for some move up to the top of the search', the report's sensitivity 'above the
    search'. Now the boundary's kind is 'not_found' and each says not found. (The paper
    design doctored: its isolated plant's boundary made one not found.)"""
    import dataclasses

    from rich.console import Console

    from fi_design.console import simulation_table
    from fi_design.guideline.verdict import margins
    from fi_design.report.validation import validation_section
    from fi_design.results.sensitivity import CrossoverSensitivity, SensitivityPoint

    d = paper_confirmed_design
    sim = d.simulation
    st = sim.stage["isolated"]
    lost = dataclasses.replace(st.boundary, hunting_free_from=None, kind="not_found",
                               note="not found: moves still hunt at 30 Hz, above the last of "
                                    "several folds the cycles' continuation found")
    st = dataclasses.replace(st, boundary=lost, hunting_free_from=None)
    sim = dataclasses.replace(sim, stage={**sim.stage, "isolated": st},
                              min_hunting_free_crossover={**sim.min_hunting_free_crossover,
                                                          "isolated": None})
    data = d.to_dict()
    data["simulation"]["min_hunting_free_crossover"]["isolated"] = None
    data["stage_hunting"]["isolated"] = st.to_dict()
    out = Console(width=200, record=True)
    out.print(simulation_table(data["simulation"], None, data["stage_hunting"]))
    row = next(ln for ln in out.export_text().splitlines() if "No move hunts from" in ln)
    assert "not found" in row and "above the search" not in row, row

    m = margins(d.model, d.crossover, d.stiffness, d.flexure, d.pid, sim)
    note = " ".join(m.notes)
    assert m.crossover_factor is None and "was found" in note and "top of the search" not in note

    points = tuple(SensitivityPoint(path=p, factor=f, value=1.0, hunting_free_from=x, kind=k)
                   for p in ("friction.bristle_stiffness", "friction.bristle_damping",
                             "friction.stribeck_velocity")
                   for f, x, k in ((1 / 3, 11.0, "fold"), (3.0, None, "not_found")))
    doctored = dataclasses.replace(d, simulation=sim, sensitivity=CrossoverSensitivity(
        plant="isolated", nominal=None, factors=(1 / 3, 1.0, 3.0), points=points))
    s = validation_section(doctored)["sensitivity"]
    cells = [c["crossover"] for r in s["rows"] for c in r["cells"]]
    assert cells.count("not found") == 3, cells
    assert "above the search" not in s["intro"] and "not found" in s["intro"], s["intro"]
