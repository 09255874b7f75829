"""The simulated confirmation: the paper's headline, the landing refinement, the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fi_design.cli import app
from fi_design.confirm import confirm, scan_crossover
from fi_design.guideline import design
from fi_design.specfile import load_spec

runner = CliRunner()


@pytest.fixture(scope="module")
def paper_confirmation(paper_spec):
    return confirm(paper_spec)


def test_paper_headline_isolator_needs_far_less_bandwidth(paper_confirmation):
    """Paper: hunting-free at 5 Hz with the isolator, 14-20 Hz needed without."""
    c = paper_confirmation
    assert c.isolated.metrics.verdict == "settled" and c.non_isolated.metrics.verdict == "hunting"
    m = c.min_hunting_free_crossover
    assert m["resolution"] == 0.5
    assert 4.0 <= m["isolated"] <= 7.0
    assert 14.0 <= m["non_isolated"] <= 22.0
    assert m["non_isolated"] >= 2.5 * m["isolated"]
    # the scans are consistent with the minimum: everything above it settles
    for plant in ("isolated", "non_isolated"):
        s = c.scans[plant]
        assert s.verdicts[0] != "settled" and set(s.verdicts[1:]) == {"settled"}
        assert s.crossovers[1] == s.minimum and s.crossovers[-1] == s.grid[1]


def test_more_bandwidth_means_fewer_cycles_without_isolator(paper_spec):
    """Paper Figure 4 B: the hunting cycles fall away with crossover; none above ~20 Hz."""
    from fi_design.simulation import simulate

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
    from fi_design.simulation import simulate
    from fi_design.confirm import landing

    low = simulate(spec, isolated=True, crossover=5.0)
    land5 = landing(spec, low)
    assert land5.on_limiter and low.metrics.verdict == "stuck"


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
    assert set(m) >= {"isolated", "non_isolated", "resolution"}
    names = {c["name"] for c in d["checks"]}
    assert {"simulation_isolated", "min_crossover_isolated", "landing_force"} <= names
    assert "hunting-free" in d["conclusion"]
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
    assert ex.submitted == ["confirm"]
    d, ref = r.to_dict(), paper_confirmed_design.to_dict()
    assert d["simulation"] == ref["simulation"] and d["checks"] == ref["checks"]
    assert r.conclusion == paper_confirmed_design.conclusion
    messages = []
    design(paper_spec, confirm=False, executor=ex, progress=messages.append)
    assert ex.submitted == ["confirm"] and messages == []  # nothing to confirm, nothing sent


def test_spec_without_isolator_is_confirmed_against_the_suggestion(repo_root):
    spec = load_spec(repo_root / "examples" / "no_isolator.yaml")
    r = design(spec)
    sim = r.simulation
    assert sim.suggested_isolator
    assert sim.non_isolated.metrics.verdict == "hunting"
    assert sim.isolated.metrics.verdict == "settled"
    assert "suggested isolator" in r.conclusion


def test_scan_finds_no_minimum_when_the_top_hunts(paper_spec):
    s = scan_crossover(paper_spec, False, 6.0, 8.0, 1.0)
    assert s.minimum is None
    assert list(s.verdicts) == ["hunting"] and list(s.crossovers) == [8.0]


def test_cli_design_prints_the_confirmation(paper_spec_path, tmp_path):
    out = tmp_path / "r.json"
    res = runner.invoke(app, [str(paper_spec_path), "--json", str(out)])
    assert res.exit_code == 0, res.output
    assert "Nonlinear confirmation" in res.output and "Hunting-free from [Hz]" in res.output
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
