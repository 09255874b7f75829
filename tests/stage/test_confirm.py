"""The simulated confirmation: the paper's headline, the landing refinement, the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fi_design.cli.app import app
from fi_design.stage.confirm import confirm
from fi_design.guideline.evaluate import evaluate as design
from fi_design.spec.file import load_spec
from fi_design.model import resolve

runner = CliRunner()


@pytest.fixture(scope="module")
def paper_confirmation(paper_spec):
    return confirm(resolve(paper_spec))


def test_paper_headline_isolator_needs_far_less_bandwidth(paper_confirmation):
    """Paper: the isolator needs far less bandwidth. Judged over every move of the family
    (the folds of the cycles): 11.3 Hz with the isolator against 24.5 Hz without."""
    c = paper_confirmation
    # the spec's own 10 mm move settles with the isolator: the paper's one-move answer ...
    assert c.isolated.metrics.verdict == "settled" and c.non_isolated.metrics.verdict == "hunting"
    # ... but the stage hunts after other moves at the same crossover
    assert c.stage["isolated"].hunts and c.stage["non_isolated"].hunts
    m = c.min_hunting_free_crossover
    assert m["resolution"] <= 0.03
    assert 11.0 <= m["isolated"] <= 11.5
    assert 24.0 <= m["non_isolated"] <= 25.0
    assert m["non_isolated"] >= 2.0 * m["isolated"]
    for plant in ("isolated", "non_isolated"):
        b = c.stage[plant].boundary
        assert b.kind == "fold" and b.bracket[1] == m[plant]
        # the branch of the cycle ends below the fold, its amplitude shrinking on the way
        f = [p[0] for p in b.branch]
        a = [p[1] for p in b.branch]
        assert max(f) < m[plant] and a[0] > a[-1] > 0


def test_more_bandwidth_means_fewer_cycles_without_isolator(paper_spec):
    """Paper Figure 4 B: the hunting cycles fall away with crossover; none above ~20 Hz."""
    from fi_design.simulation.run import simulate

    cycles = [simulate(paper_spec, isolated=False, crossover=fc).metrics.hunting_cycles
              for fc in (8.0, 12.0, 16.0, 19.0, 22.0, 26.0)]
    assert cycles[0] > 0 and cycles[-1] == 0 and cycles[-2] == 0
    assert all(c > 0 for c in cycles[:4])


def test_landing_refinement(paper_confirmation, paper_spec):
    """k * min(stroke, landing deflection) is the force the resting cart feels."""
    land = paper_confirmation.landing
    assert not land.on_limiter
    assert land.force == pytest.approx(land.stiffness * abs(land.deflection))
    assert land.force <= land.rule_force < land.static_friction
    # lower crossover: the cart lands on the limiter and the stage is stuck (hunting returns later)
    spec = paper_spec
    from fi_design.simulation.run import simulate
    from fi_design.stage.confirm import landing

    low = simulate(spec, isolated=True, crossover=5.0)
    land5 = landing(resolve(spec), low)
    assert land5.on_limiter and low.metrics.verdict == "stuck"


def test_rows_of_a_stage_that_cannot_be_judged_read_as_such(paper_confirmation, paper_spec):
    """A failed or stuck run has no count and no landing: the rows said 'n/a ... FAIL', 'FAIL 0
    = 0 moves' and 'after the spec's own motion it undetermined'. Built from the paper's
    confirmation with the outcomes replaced: no simulation here."""
    import dataclasses
    import math

    from fi_design.results.stage import MoveOutcome
    from fi_design.stage.confirm import _checks

    c = paper_confirmation
    why = "the simulation did not complete: solution diverged at t = 1.7 s"
    diverged = MoveOutcome(10e-3, "spec", "undetermined", math.nan, None, None, 1.7, why,
                           failed=True)
    hunting = MoveOutcome(57.2e-6, "family", "hunts", 0.0, 0.1e-3, 0.187, 1.0, "a cycle")
    stuck = MoveOutcome(10e-3, "spec", "stuck", 0.2e-3, None, None, 5.0, "at the force limit")
    iso = c.stage["isolated"]
    hunts = dataclasses.replace(iso, moves=(hunting, diverged), cycle=None, other_cycles=())
    text = hunts.describe("The stage")
    assert "the 57.2 µm move ends in" in text
    assert text.endswith(f"after the spec's own motion it cannot be judged ({why})")
    failed = dataclasses.replace(c.isolated, metrics=dataclasses.replace(
        c.isolated.metrics, verdict="undetermined", hunting_cycles=0, reason=why))
    for stage in (dataclasses.replace(iso, moves=(stuck,), cycle=None, other_cycles=()),
                  dataclasses.replace(iso, moves=(diverged,), cycle=None, other_cycles=())):
        checks = {ch.name: ch for ch in _checks(
            resolve(paper_spec), failed, c.non_isolated, {**c.stage, "isolated": stage},
            c.min_hunting_free_crossover, dataclasses.replace(c.landing, deflection=math.nan),
            True, c.isolated, c.non_isolated, False)}
        sim = checks["simulation_isolated"]
        assert sim.status.value == "FAIL" and sim.value is None and sim.limit is None
        assert checks["spec_move_isolated"].value is None
        land = checks["landing_force"]
        assert land.value is None and land.status.value == "INFO" and "n/a" not in land.message
        assert land.message == f"where the cart comes to rest could not be determined ({why})"


def test_friction_models_agree_on_the_paper_setup(paper_confirmation):
    assert paper_confirmation.models_agree
    assert paper_confirmation.cross_check["non_isolated"].friction_model == "switch"
    assert paper_confirmation.cross_check["non_isolated"].metrics.verdict == "hunting"


def test_design_json_contract_simulation(paper_confirmed_design):
    d = paper_confirmed_design.to_dict()
    sim = d["simulation"]
    for plant in ("isolated", "non_isolated"):
        v = sim[plant]
        assert isinstance(v["hunting_cycles"], int)
        assert isinstance(v["amplitude"], float) and v["amplitude"] >= 0
        assert v["period"] is None or v["period"] > 0
        assert isinstance(v["settled"], bool)
        assert isinstance(v["final_error"], float)
        assert v["verdict"] in ("settled", "hunting", "stuck", "undetermined")
    m = sim["min_hunting_free_crossover"]
    assert set(m) >= {"isolated", "non_isolated", "resolution", "search"}
    stage = d["stage_hunting"]
    for plant in ("isolated", "non_isolated"):
        st = stage[plant]
        assert {"hunts", "moves_tried", "moves_hunting", "entered_by", "cycle",
                "hunting_free_from"} <= set(st)
        assert st["hunts"] is True and st["moves_tried"] == 25
        assert len(st["entered_by"]) == st["moves_hunting"] > 0
        assert {"amplitude", "period", "stable", "multiplier"} <= set(st["cycle"])
        assert st["hunting_free_from"] == m[plant]
    names = {c["name"] for c in d["checks"]}
    assert {"simulation_isolated", "spec_move_isolated", "min_crossover_isolated",
            "landing_force"} <= names
    assert "The lowest crossover from which no move hunts" in d["conclusion"]
    assert f"hunts from {m['isolated']:.4g} Hz up" in d["conclusion"]
    json.dumps(d, allow_nan=False)


class _RecordingExecutor:
    """A thread pool that records what it was given (the library creates no pool)."""

    def __init__(self):
        from concurrent.futures import ThreadPoolExecutor

        self.pool = ThreadPoolExecutor(max_workers=1)
        self.submitted = []

    def submit(self, fn, *args):
        self.submitted.append(fn.__name__)
        return self.pool.submit(fn, *args)


def test_design_runs_the_confirmation_on_the_given_executor(paper_spec, paper_confirmed_design):
    ex = _RecordingExecutor()
    try:
        r = design(paper_spec, executor=ex)
    finally:
        ex.pool.shutdown()
    # the confirmation and the robustness samples (in chunks) on the caller's executor
    assert ex.submitted[0] == "confirm" and set(ex.submitted[1:]) == {"run_chunk"}
    assert len(ex.submitted) >= 3
    d, ref = r.to_dict(), paper_confirmed_design.to_dict()
    assert d["simulation"] == ref["simulation"] and d["checks"] == ref["checks"]
    assert d["robustness"] == ref["robustness"] and d["verdict"] == ref["verdict"]
    assert r.conclusion == paper_confirmed_design.conclusion
    messages = []
    sent = len(ex.submitted)
    design(paper_spec, confirm=False, executor=ex, progress=messages.append)
    assert len(ex.submitted) == sent and messages == []  # nothing to confirm, nothing sent


def test_spec_without_isolator_is_confirmed_against_the_suggestion(repo_root):
    spec = load_spec(repo_root / "examples" / "no_isolator.yaml")
    r = design(spec)
    sim = r.simulation
    assert sim.suggested_isolator
    assert sim.non_isolated.metrics.verdict == "hunting"
    assert sim.isolated.metrics.verdict == "settled"
    assert sim.stage["non_isolated"].hunts and r.verdict.status == "FAIL"
    # the isolator simulated beside it is the rule's, for comparison, never a recommendation
    assert "the rule's first isolator (simulated for comparison" in r.conclusion


def test_a_cycle_that_outlives_the_search_gives_no_hunting_free_crossover(paper_spec):
    from conftest import variant

    from fi_design.stage import stage_hunting

    spec = variant(paper_spec, **{"simulation.crossover_scan.stop": "20 Hz"})
    st = stage_hunting(spec, False)  # its fold lies at 24.5 Hz
    assert st.hunts and st.hunting_free_from is None
    assert st.boundary.kind == "bound" and st.boundary.bracket[1] == 20.0


def test_cli_design_prints_the_confirmation(paper_spec_path, tmp_path, shared_designs):
    out = tmp_path / "r.json"
    res = runner.invoke(app, [str(paper_spec_path), "--json", str(out)])
    assert res.exit_code == 0, res.output
    assert "Nonlinear confirmation" in res.output and "No move hunts from" in res.output
    assert json.loads(out.read_text())["simulation"]["non_isolated"]["verdict"] == "hunting"
    res = runner.invoke(app, [str(paper_spec_path), "--no-simulation"])
    assert res.exit_code == 0 and "Nonlinear confirmation" not in res.output


def test_cli_simulate_writes_traces_in_the_measured_layout(paper_spec_path, tmp_path):
    csv = tmp_path / "trace.csv"
    res = runner.invoke(app, ["simulate", str(paper_spec_path), "--csv", str(csv)])
    assert res.exit_code == 0, res.output
    header = csv.read_text().splitlines()[0]
    assert header == "time_s,reference_m,position_m,force_N,deflection_m"
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert data.shape == (20001, 5)
    assert np.allclose(np.diff(data[:, 0]), 1e-3)
    assert data[-1, 1] == pytest.approx(0.01)
    # the measured-data loader reads it back when it exists
    res = runner.invoke(app, ["simulate", str(paper_spec_path), "--no-isolator", "--csv",
                              str(csv), "--force"])
    assert res.exit_code == 0
    assert csv.read_text().splitlines()[0] == "time_s,reference_m,position_m,force_N"
    assert "hunting" in res.output


def test_cli_simulate_refuses_existing_output_and_bad_extension(paper_spec_path, tmp_path):
    csv = tmp_path / "trace.csv"
    csv.write_text("keep me")
    res = runner.invoke(app, ["simulate", str(paper_spec_path), "--csv", str(csv)])
    assert res.exit_code == 2 and csv.read_text() == "keep me"
    res = runner.invoke(app, ["simulate", str(paper_spec_path), "--csv", str(tmp_path / "t.txt")])
    assert res.exit_code == 2 and not (tmp_path / "t.txt").exists()
    res = runner.invoke(app, ["simulate", str(paper_spec_path), "--csv", str(paper_spec_path),
                              "--force"])
    assert res.exit_code == 2


def test_landing_on_a_vertical_axis_counts_the_sag(paper_spec, paper_confirmation):
    """The simulation carries no weight: on a vertical drive axis whose joint sags past its
    stroke (the paper's 0.4 kg cart sags 0.59 mm on 6667 N/m) the landing check does not pass
    a cart 'inside the stroke' while the sag check says it rests on its end stop."""
    from fi_design.stage.confirm import _checks

    c = paper_confirmation
    model = resolve(paper_spec).varied({"isolator.flexure.orientation": "vertical_axis"})
    assert model.flexure.sag > model.joint.stroke
    checks = {ch.name: ch for ch in _checks(
        model, c.isolated, c.non_isolated, c.stage, c.min_hunting_free_crossover, c.landing,
        True, c.isolated, c.non_isolated, False)}
    land = checks["landing_force"]
    assert land.status.value == "FAIL"
    assert "rests on its end stop" in land.message and "sags a further" in land.message
