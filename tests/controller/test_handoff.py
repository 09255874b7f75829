"""Step 4 handed over: gains printed and written in the form controller.gains reads, and a design
that was not simulated never passes."""

from __future__ import annotations

import json
import re

import pytest
from typer.testing import CliRunner

from fi_design.cli.app import app
from fi_design.guideline.evaluate import evaluate as design
from fi_design.spec.file import load_spec

from conftest import variant

runner = CliRunner()

MARGINS = ("crossover", "phase_margin_deg", "gain_margin_db", "modulus_margin", "delay_margin")


def _cases(result):
    return [{k: getattr(c, k) for k in MARGINS} for c in result.crossover.cases]


def _printed_gains(output: str) -> dict:
    """kp, ki, kd and roll_off [Hz] as the console's step-4 table prints them."""
    line = next(ln for ln in output.splitlines() if re.match(r"^\s*drive\s+[\d.]", ln))
    kp, ki, kd, roll = (float(x) for x in line.split()[1:5])
    return {"kp": kp, "ki": ki, "kd": kd, "roll_off": roll}


def test_printed_gains_copied_into_controller_gains_keep_the_loop(paper_spec, tmp_path):
    """The report put the roll-off on the whole PID: copied into controller.gains, those numbers
    moved a 10 Hz crossover to 11.13 Hz and took 1.2 dB of gain margin."""
    from fi_design.spec.edit import edited_spec_text

    spec = variant(paper_spec, **{"controller.crossover": "10 Hz"})
    path = tmp_path / "rule10.yaml"
    path.write_text(edited_spec_text(spec))
    out = runner.invoke(app, [str(path), "--no-simulation"], env={"COLUMNS": "120"})
    assert out.exit_code == 0, out.output
    printed = _printed_gains(out.stdout)
    copied = variant(spec, **{"controller.crossover": None,
                              "controller.gains": {"kp": printed["kp"], "ki": printed["ki"],
                                                   "kd": printed["kd"]},
                              "controller.roll_off": f"{printed['roll_off']} Hz"})
    ruled, hw = design(spec, confirm=False), design(copied, confirm=False)
    for a, b in zip(_cases(ruled), _cases(hw)):  # four printed digits: the same loop
        assert b["crossover"] == pytest.approx(a["crossover"], rel=2e-3)
        assert b["gain_margin_db"] == pytest.approx(a["gain_margin_db"], abs=0.02)
        assert b["phase_margin_deg"] == pytest.approx(a["phase_margin_deg"], abs=0.1)


def test_json_has_one_gain_set_named_for_the_drive(paper_spec):
    """No trap: one set of kp, ki, kd (the drive's, pid.drive), frequencies in Hz like the spec,
    every key's unit written beside it; the rule gives its corners, not a second gain set."""
    d = design(paper_spec, confirm=False).to_dict()["pid"]
    drive, rule = d["drive"], d["rule"]
    assert "drive takes" in drive["form"] and "D term only" in drive["form"]
    law = design(paper_spec, confirm=False).pid.controller
    assert (drive["kp"], drive["ki"], drive["kd"]) == (law.kp, law.ki, law.kd)
    assert drive["roll_off"] == pytest.approx(24.0)  # Hz: wt = 3 wc at 8 Hz
    assert drive["sample_rate"] is None and drive["delay"] == 0.0
    assert drive["derivative_on"] == "error" and drive["filters"] == []
    assert drive["discrete"] is None and drive["in_drive_units"] is None
    assert drive["units"]["roll_off"] == "Hz" and drive["units"]["kp"] == "N/m"
    # the rule: its corners in Hz, no kp, ki, kd of another form to copy by mistake
    assert not {"kp", "ki", "kd"} & set(rule) and "in_drive_form" not in rule
    assert rule["roll_off"] == pytest.approx(24.0) and rule["lead_corner"] == pytest.approx(8 / 3)
    assert rule["integrator_corner"] == pytest.approx(0.8) and rule["units"]["ks"] == "N/m"
    assert not {"kp", "ki", "kd", "controller", "hand_off", "wt", "wc"} & set(d)

    def keys(node, path=""):
        for k, v in node.items():
            yield f"{path}{k}"
            if isinstance(v, dict):
                yield from keys(v, f"{path}{k}.")

    # nothing in rad/s: every frequency-like key of pid is in Hz
    assert not [k for k in keys(d) if k.split(".")[-1] in ("wt", "wd", "wi", "wc", "omega")]


def test_write_spec_round_trips_exactly(paper_confirmed_design, paper_spec_path, tmp_path):
    """The design of the written spec gives the same crossover, margins and simulation."""
    out = tmp_path / "handed.yaml"
    r = runner.invoke(app, [str(paper_spec_path), "--no-simulation", "--write-spec", str(out)])
    assert r.exit_code == 0, r.output
    text = out.read_text()
    assert "# fc: PID tuned on m1 + m2" in text  # the input's comments kept
    handed = load_spec(out)
    assert handed.controller.gains is not None
    first, again = paper_confirmed_design, design(handed)
    assert again.pid.controller.source == "gains"
    assert again.crossover.desired == first.crossover.desired
    assert again.crossover.achievable == pytest.approx(first.crossover.achievable, rel=1e-9)
    for a, b in zip(_cases(first), _cases(again)):
        for k in MARGINS:
            assert b[k] == pytest.approx(a[k], rel=1e-9), k
    for plant in ("isolated", "non_isolated"):
        va, vb = getattr(first.simulation, plant), getattr(again.simulation, plant)
        assert vb.outcome == va.outcome
        assert vb.metrics.hunting_cycles == va.metrics.hunting_cycles
        # the same loop to the last bit of the gains; a limit cycle magnifies the rounding
        # of kp' + ki/wt = kp to parts per million, far below what the report prints
        assert vb.metrics.final_error == pytest.approx(va.metrics.final_error, rel=1e-4,
                                                       abs=1e-12)
    assert again.simulation.min_hunting_free_crossover == \
        first.simulation.min_hunting_free_crossover
    assert again.margins.crossover_factor == pytest.approx(first.margins.crossover_factor)


def test_design_without_simulation_never_passes(paper_spec):
    result = design(paper_spec, confirm=False)
    assert not result.failed_checks  # nothing of the linear steps fails ...
    assert result.verdict.status == "NOT_CONFIRMED"  # ... yet it was not simulated
    assert result.passed is False and result.to_dict()["passed"] is False
    assert "does not pass" in result.verdict.headline


def test_no_simulation_fails_the_ci_gate(paper_spec_path, tmp_path):
    out = tmp_path / "r.json"
    r = runner.invoke(app, [str(paper_spec_path), "--no-simulation", "--fail-on", "fail",
                            "--json", str(out)])
    assert r.exit_code == 3, r.output
    assert json.loads(out.read_text())["verdict"]["status"] == "NOT_CONFIRMED"
    assert "Verdict: NOT_CONFIRMED" in r.stdout


def test_write_spec_round_trips_with_filters_and_a_drive(paper_spec, tmp_path):
    """A sampled loop with a notch, a low-pass and the drive's units: the written spec keeps
    the filters and the drive, and its design is the same loop to the last digit."""
    from fi_design.spec.edit import edited_spec_text

    spec = variant(paper_spec, **{
        "controller.sample_rate": "4 kHz", "controller.delay": "250 us",
        "controller.filters": [{"type": "notch", "frequency": "150 Hz", "width": "75 Hz"},
                               {"type": "low_pass", "frequency": "600 Hz", "damping": 0.5}],
        "controller.drive": {"motor_constant": "20 N/A", "encoder_resolution": "1 um"}})
    path, out = tmp_path / "filtered.yaml", tmp_path / "handed.yaml"
    path.write_text(edited_spec_text(spec))
    r = runner.invoke(app, [str(path), "--no-simulation", "--write-spec", str(out)],
                      env={"COLUMNS": "120"})
    assert r.exit_code == 0, r.output
    assert "A/count" in r.stdout and "per sample" in r.stdout  # the drive's own terms
    handed = load_spec(out)
    assert handed.controller.gains is not None
    assert handed.controller.filters == spec.controller.filters
    assert handed.controller.drive == spec.controller.drive
    first, again = design(spec, confirm=False), design(handed, confirm=False)
    assert again.pid.controller.source == "gains"
    assert again.pid.controller.filters == first.pid.controller.filters
    assert again.crossover.achievable == pytest.approx(first.crossover.achievable, rel=1e-6)
    for a, b in zip(_cases(first), _cases(again)):
        for k in MARGINS:
            assert b[k] == pytest.approx(a[k], rel=1e-9), k
    da, db = first.to_dict()["pid"]["drive"], again.to_dict()["pid"]["drive"]
    for key in ("kp", "ki", "kd", "roll_off"):
        assert db[key] == pytest.approx(da[key], rel=1e-12)
    assert db["filters"] == da["filters"]
    assert db["discrete"]["num"] == pytest.approx(da["discrete"]["num"], rel=1e-9)
    assert db["in_drive_units"]["kp"] == pytest.approx(da["in_drive_units"]["kp"], rel=1e-12)


def test_json_units_read_back_as_a_spec_writes_them():
    """pid.drive.units gave ki in 'N/(m s)' and kd in 'N s/m', spelt unlike the spec
    ('N/(m*s)', 'N*s/m'): every unit of pid.drive, pid.rule and the sampled form is one the
    spec's reader takes, and a gain written with it reads back as the same value in SI."""
    from fi_design.results.steps import DISCRETE_UNITS, DRIVE_UNITS, RULE_UNITS
    from fi_design.spec.units import KNOWN_UNITS, to_si

    for table in (DRIVE_UNITS, RULE_UNITS, DISCRETE_UNITS):
        for key, unit in table.items():
            if unit in ("-", "dB"):
                continue
            assert unit in KNOWN_UNITS, (key, unit)
            assert to_si(f"1234.5 {unit}", unit) == pytest.approx(1234.5), (key, unit)

