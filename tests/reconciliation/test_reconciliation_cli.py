"""`fi-design reconcile` through typer's CliRunner: outputs, contract, bad input."""

from __future__ import annotations

import json
import re

import pytest
import yaml
from typer.testing import CliRunner

from fi_design.cli.app import app
from fi_design.measured import to_csv_text
from fi_design.spec.file import load_spec

from hidden_effect import Case, base_spec, measure, spec_mapping

runner = CliRunner()

CASE = Case("cli", True, {"type": "cable_force", "stiffness": 60.0, "preload": -0.4}, {},
            duration=3.0, seed=91)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("reconcile")
    raw = spec_mapping(CASE)
    raw["name"] = "Stage <script>alert(1)</script> & co"
    spec_path = d / "stage.yaml"
    spec_path.write_text("# the test stage\n" + yaml.safe_dump(raw, sort_keys=False))
    data = measure(CASE, base_spec(CASE))
    csv_path = d / "trace.csv"
    csv_path.write_text(to_csv_text(data))
    return d, spec_path, csv_path


@pytest.fixture(scope="module")
def run(files):
    d, spec_path, csv_path = files
    out = {k: d / n for k, n in (("json", "gap.json"), ("spec", "fixed.yaml"),
                                 ("report", "gap.html"))}
    result = runner.invoke(app, ["reconcile", str(spec_path), str(csv_path), "--json",
                                 str(out["json"]), "--write-spec", str(out["spec"]), "--report",
                                 str(out["report"])])
    return result, out


def test_reconcile_command_names_the_effect(run):
    result, out = run
    assert result.exit_code == 0, result.output
    assert "Effect: cable_force" in result.stdout
    for word in ("Candidates", "Gap before and after", "misfit", "Noise:"):
        assert word in result.stdout


def test_json_contract(run):
    _, out = run
    d = json.loads(out["json"].read_text())
    assert d["effect"] == "cable_force"
    assert set(d["parameters"]) == {"stiffness", "preload"}
    assert abs(d["parameters"]["stiffness"] - 60.0) < 6.0
    assert [c["name"] for c in d["candidates"]][0] == "cable_force"
    for c in d["candidates"]:
        assert {"name", "score", "parameters"} <= set(c)
    assert set(d["gap_before"]) == set(d["gap_after"])
    assert d["gap_after"]["misfit"] < d["gap_before"]["misfit"]
    assert d["noise"]["position"] > 0


def test_written_spec_reads_back_with_the_effect(run, files):
    _, out = run
    _, spec_path, _ = files
    text = out["spec"].read_text()
    assert text.startswith("# effects added by fi-design reconcile")
    assert "\n# the test stage\n" in text  # the input's text and comments are kept
    fixed = load_spec(out["spec"])
    assert [e.type for e in fixed.effects] == ["cable_force"]
    assert load_spec(spec_path).effects == ()  # the input is untouched


def test_report_is_escaped_html(run):
    _, out = run
    html = out["report"].read_text()
    assert html.startswith("<!DOCTYPE html>")
    for anchor in ('id="finding"', 'id="gap"', 'id="candidates"', 'id="signatures"', "<svg"):
        assert anchor in html
    assert "<script>alert(1)</script>" not in html
    assert "&lt;script&gt;" in html
    visible = re.sub(r"<[^>]+>", " ", re.sub(r"<(svg|style)\b.*?</\1>", " ", html, flags=re.S))
    assert "`" not in visible and "DESIGN.md" not in visible


def test_outputs_never_overwrite_inputs(files):
    d, spec_path, csv_path = files
    for opt, target in (("--write-spec", spec_path), ("--json", csv_path)):
        target_copy = target.read_bytes()
        r = runner.invoke(app, ["reconcile", str(spec_path), str(csv_path), opt, str(target),
                                "--force"])
        assert r.exit_code == 2, r.output
        assert target.read_bytes() == target_copy
        assert "Traceback" not in r.output


def test_bad_measurement_exits_2_naming_the_column(files, tmp_path):
    _, spec_path, _ = files
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,reference_m,position_mm\n" + "\n".join(f"{i},0,0" for i in range(30)))
    r = runner.invoke(app, ["reconcile", str(spec_path), str(bad)])
    assert r.exit_code == 2
    assert "position_mm" in r.output and "Traceback" not in r.output
    r = runner.invoke(app, ["reconcile", str(spec_path), str(tmp_path / "missing.csv")])
    assert r.exit_code == 2 and "no such file" in r.output


def test_gap_table_unit_column_matches_its_values(run):
    """The gap table's unit column said m for values printed in µm (each with its own unit)."""
    _, out = run
    html = out["report"].read_text()
    section = html.split('id="gap"', 1)[1].split("</table>", 1)[0]
    rows = re.findall(r"<tr>(.*?)</tr>", section, flags=re.S)[1:]
    assert rows
    for row in rows:
        cells = [re.sub(r"<[^>]+>", "", c).strip() for c in re.findall(r"<td[^>]*>(.*?)</td>",
                                                                        row, flags=re.S)]
        name, unit, values = cells[0], cells[1], cells[2:8]
        assert unit != "m", (name, unit)  # lengths are read in µm or mm
        for v in values:  # a number alone: the unit column names its unit
            assert re.fullmatch(r"-|–|n/a|-?[\d.]+(\s×\s10[⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)?", v), (name, v)


def test_a_record_shorter_than_the_loop_period_is_refused(tmp_path):
    """60 ms of examples/measured_trace.csv (its stage's loop crosses over at 8 Hz: 125 ms)
    named mass_error "nonetheless" from a replay that had not left its start; a 10 ms capture
    at 100 kHz called force_N's sign wrong or, thinned to its model rate, was refused as
    "noise-only refit: ... too short: 5 sample(s)". Now both are refused before any
    simulation, naming the file, the record's span and the loop's period."""
    from conftest import EXAMPLES

    import numpy as np

    from fi_design.errors import DataError
    from fi_design.measured import load_measurement, measurement_from_arrays
    from fi_design.reconciliation import reconcile

    lines = (EXAMPLES / "measured_trace.csv").read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    short = tmp_path / "slice.csv"
    short.write_text("\n".join([lines[header], *lines[header + 201:header + 261]]) + "\n")
    r = runner.invoke(app, ["reconcile", str(EXAMPLES / "measured_stage.yaml"), str(short)])
    assert r.exit_code == 2, r.output
    assert f"{short}: column 'time_s': too short for a reconciliation: the record spans " \
           "0.059 s, less than one period of the loop's 8 Hz crossover (0.125 s)" \
        in " ".join(r.output.split()), r.output
    full = load_measurement(EXAMPLES / "measured_trace.csv")
    fast = np.arange(1000) * 1e-5 + 0.3  # 10 ms at 100 kHz, in the move
    columns = [np.interp(fast, full.time, getattr(full, c))
               for c in ("reference", "position", "force", "deflection")]
    with pytest.raises(DataError, match="less than one period") as err:
        reconcile(load_spec(EXAMPLES / "measured_stage.yaml"),
                  measurement_from_arrays(fast - fast[0], *columns, source="fast.csv"))
    assert err.value.column == "time_s" and err.value.source == "fast.csv"


def test_a_nominal_model_that_runs_away_prints_no_empty_gap_table(emps_path, tmp_path):
    """examples/measured_stage.yaml against the EMPS record (another stage: the nominal model
    runs away) printed the "Gap before and after" table's headers with no rows; now no table,
    and why (as for the empty candidate table), on the console and in the report."""
    from conftest import EXAMPLES

    from fi_design.measured import load_measurement
    from fi_design.reconciliation import reconcile
    from fi_design.report.gap import gap_sections

    r = runner.invoke(app, ["reconcile", str(EXAMPLES / "measured_stage.yaml"), str(emps_path)])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "The nominal model fails on this record: runaway" in text
    assert "Gap before and after" not in text and "Metric" not in text, r.output
    assert "No gap table: the nominal model did not run through the record" in text
    result = reconcile(load_spec(EXAMPLES / "measured_stage.yaml"), load_measurement(emps_path))
    (gap,) = [s for s in gap_sections(result, figures=False) if s.id == "gap"]
    assert not gap.tables and "No gap table" in gap.paragraphs[0]
