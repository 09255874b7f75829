"""Reconciliation on traces with a hidden effect (tests/hidden_effect.py).

Each case simulates a "true" stage (the spec plus one hidden effect) with the
spec's exact move profile, adds sensor noise, and reconciles the trace against
the spec without the effect. A case passes when the right effect is named,
every checked parameter is within its stated tolerance, and the gap above
noise (``excess`` = chi2 / n - 1) shrinks by at least half. Controls (noise
only, a hunting trace with noise) must answer ``none``.

These records come from the product's own kernel; the independent simulator's
records (tests/reconciliation/test_reconciliation_independent.py) are the real test, so the
default run keeps two effects and the controls here, and ``-m slow`` adds every
other effect on both plants, more magnitudes, moves, crossovers and seeds. ``joint_damping`` has no
non-isolated case: without an isolator there is no joint (the candidate is
skipped as not applicable, which a test checks).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fi_design.reconciliation import reconcile

from hidden_effect import Case, base_spec, measure, parameter_error, spec_mapping

#: Back-and-forth moves at a speed well above the Stribeck velocity (3 mm/s): the
#: stage slides smoothly over several periods of a position-periodic effect.
OUT_BACK = ({"distance": "15 mm", "velocity": "20 mm/s", "acceleration": "0.5 m/s^2"},
            {"distance": "-15 mm", "velocity": "20 mm/s", "acceleration": "0.5 m/s^2",
             "start": "2 s"})
SHORT = ({"distance": "5 mm", "velocity": "30 mm/s", "acceleration": "2 m/s^2"},)
LONG = ({"distance": "20 mm", "velocity": "60 mm/s", "acceleration": "1 m/s^2"},)

#: 3 s records (4 s until the test run was trimmed: the moves end by 0.4 s; the parameters
#: came out within 1e-4 of the truth at either length, against tolerances of 10 % and 5 %,
#: and the shorter records take a quarter less CPU)
DEFAULT = [
    Case("cable_force-iso", True, {"type": "cable_force", "stiffness": 60.0, "preload": -0.4},
         {"stiffness": 0.1, "preload": 0.1}, duration=3.0, moves=LONG),
    Case("mass_error-rigid", False, {"type": "mass_error", "stage_mass": 1.3, "cart_mass": 0.325},
         {"stage_mass": 0.05}, duration=3.0, moves=SHORT),
]

SLOW = [
    Case("viscous_friction-iso", True, {"type": "viscous_friction", "viscous": 35.0},
         {"viscous": 0.05}, duration=4.0),
    Case("stribeck_velocity-rigid", False,
         {"type": "stribeck_velocity", "stribeck_velocity": 8e-3}, {"stribeck_velocity": 0.1},
         duration=4.0, crossover=10.0),
    Case("position_dependent_friction-iso", True,
         {"type": "position_dependent_friction", "amplitude": 0.2, "wavelength": 4e-3,
          "phase": -1.2}, {"amplitude": 0.1, "wavelength": 0.02, "phase": ("abs", 0.2)},
         moves=OUT_BACK, duration=4.0),
    Case("force_ripple-rigid", False,
         {"type": "force_ripple", "amplitude": 0.4, "pitch": 6e-3, "phase": 2.0},
         {"amplitude": 0.1, "pitch": 0.02, "phase": ("abs", 0.2)}, moves=OUT_BACK, duration=4.0,
         crossover=6.0),
    Case("time_delay-rigid", False, {"type": "time_delay", "delay": 2.5e-3}, {"delay": 0.05},
         duration=4.0),
    # the isolated stage settles without stick-slip cycles; a hunting stage replays its
    # cycles out of phase (the replay starts from the state in the data), see the slow case
    Case("quantization-iso", True, {"type": "quantization", "resolution": 2e-6},
         {"resolution": 0.01}, duration=4.0, seed=8),
    Case("force_saturation-iso", True, {"type": "force_saturation", "limit": 2.2},
         {"limit": 0.03}, duration=4.0),
    Case("joint_damping-iso", True, {"type": "joint_damping", "damping": 15.0},
         {"damping": 0.1}, duration=4.0, force=False),
    Case("viscous_friction-rigid", False, {"type": "viscous_friction", "viscous": 8.0},
         {"viscous": 0.05}, moves=LONG, seed=2),
    Case("stribeck_velocity-iso", True,
         {"type": "stribeck_velocity", "stribeck_velocity": 1e-3}, {"stribeck_velocity": 0.1},
         seed=3),
    Case("position_dependent_friction-rigid", False,
         {"type": "position_dependent_friction", "amplitude": 0.3, "wavelength": 5e-3,
          "phase": 0.5}, {"amplitude": 0.1, "wavelength": 0.02, "phase": ("abs", 0.2)},
         moves=OUT_BACK, seed=4),
    Case("force_ripple-iso", True,
         {"type": "force_ripple", "amplitude": 0.3, "pitch": 4e-3, "phase": 1.0},
         {"amplitude": 0.1, "pitch": 0.02, "phase": ("abs", 0.2)}, moves=OUT_BACK, seed=5,
         crossover=10.0),
    Case("cable_force-rigid", False, {"type": "cable_force", "stiffness": 80.0, "preload": 0.5},
         {"stiffness": 0.1, "preload": 0.1}, seed=6),
    Case("time_delay-iso", True, {"type": "time_delay", "delay": 2e-3}, {"delay": 0.05},
         seed=7),
    Case("quantization-rigid-hunting", False, {"type": "quantization", "resolution": 5e-6},
         {"resolution": 0.01}, duration=4.0, seed=9),
    Case("force_saturation-rigid", False, {"type": "force_saturation", "limit": 4.5},
         {"limit": 0.03}, seed=9),
    Case("mass_error-iso", True, {"type": "mass_error", "stage_mass": 1.9, "cart_mass": 0.5},
         {"stage_mass": 0.05, "cart_mass": 0.1}, seed=10),
    Case("joint_damping-iso-no-force", True, {"type": "joint_damping", "damping": 20.0},
         {"damping": 0.1}, seed=11, force=False, crossover=6.0),
    Case("viscous_friction-iso-position-only", True,
         {"type": "viscous_friction", "viscous": 40.0}, {"viscous": 0.05}, seed=12,
         force=False, deflection=False),
    Case("cable_force-iso-small", True, {"type": "cable_force", "stiffness": 20.0},
         {"stiffness": 0.15}, seed=13, crossover=5.0),
    Case("time_delay-rigid-fast-loop", False, {"type": "time_delay", "delay": 1e-3},
         {"delay": 0.1}, seed=14, crossover=15.0, moves=SHORT),
]

CONTROLS = [
    # 3 s (4 s until the test run was trimmed; the 10 mm move ends at 0.25 s)
    Case("noise-only-iso", True, None, {}, duration=3.0, seed=21),
    # the stage without isolator hunts (stick-slip cycles with a period of about 2 s)
    Case("noise-only-hunting-rigid", False, None, {}, duration=8.0, seed=22),
]
SLOW_CONTROLS = [
    # the same record cut to 6 s (one cycle, every segment in phase): a force limit fitted on
    # a flat stretch of the misfit, with no standard error, was named until a parameter
    # without one failed the distance test
    Case("noise-only-hunting-rigid-one-cycle", False, None, {}, duration=6.0, seed=22),
    Case("noise-only-rigid-short-move", False, None, {}, moves=SHORT, seed=23, crossover=12.0),
    Case("noise-only-iso-out-back", True, None, {}, moves=OUT_BACK, seed=24),
    Case("noise-only-iso-position-only", True, None, {}, seed=25, force=False,
         deflection=False),
]


#: Reconciliations of the cases above, by id: computed once per process (the contract test
#: reads the cable_force case's).
_RESULTS: dict = {}


def _run(case: Case):
    if case.id not in _RESULTS:
        spec = base_spec(case)
        _RESULTS[case.id] = reconcile(spec, measure(case, spec))
    return _RESULTS[case.id]


def _check_found(case: Case, result) -> None:
    want = case.effect["type"]
    ranking = [(c.name, round(c.score, 1)) for c in result.candidates[:3]]
    assert result.effect == want, f"{case.id}: named {result.effect}, ranking {ranking}"
    for name, (err, tol) in parameter_error(case, result.parameters).items():
        assert err <= tol, (f"{case.id}: {name} = {result.parameters[name]:.6g}, true "
                            f"{case.effect[name]:.6g} (error {err:.3g} > {tol})")
    before, after = result.gap_before["excess"], result.gap_after["excess"]
    assert after <= 0.5 * before, f"{case.id}: gap above noise {before:.4g} -> {after:.4g}"
    assert result.gap_after["misfit"] < result.gap_before["misfit"]
    first = result.candidates[0]
    assert first.name == want and first.score > result.threshold


@pytest.mark.parametrize("case", DEFAULT, ids=[c.id for c in DEFAULT])
def test_hidden_effect_found(case):
    _check_found(case, _run(case))


@pytest.mark.slow
@pytest.mark.parametrize("case", SLOW, ids=[c.id for c in SLOW])
def test_hidden_effect_found_more(case):
    _check_found(case, _run(case))


def _check_none(case: Case, result) -> None:
    ranking = [(c.name, round(c.score, 1)) for c in result.candidates[:3]]
    assert result.effect == "none", f"{case.id}: named {result.effect}, ranking {ranking}"
    assert result.entries == ()
    assert result.gap_before["misfit"] < 1.1


@pytest.mark.parametrize("case", CONTROLS, ids=[c.id for c in CONTROLS])
def test_noise_only_answers_none(case):
    result = _run(case)
    _check_none(case, result)
    if "hunting" in case.id:
        # the trace really hunts, and the comparison used phase-free features there
        assert result.gaps[[g.name for g in result.gaps].index("hunting_cycles")].measured >= 1
        assert any(not s.coherent for s in result.segments)


@pytest.mark.slow
@pytest.mark.parametrize("case", SLOW_CONTROLS, ids=[c.id for c in SLOW_CONTROLS])
def test_noise_only_answers_none_more(case):
    _check_none(case, _run(case))


def test_joint_damping_not_applicable_without_isolator():
    case = Case("rigid-skip", False, None, {}, duration=3.0, seed=31)
    spec = base_spec(case)
    result = reconcile(spec, measure(case, spec), candidates=["joint_damping", "viscous_friction"])
    assert "joint_damping" in result.skipped
    assert "isolator" in result.skipped["joint_damping"]
    # a noise-only record: the model agrees within noise, so no candidate is fitted at all
    assert result.candidates == () and "the catalogue was not fitted" in result.conclusion


def test_result_contract_and_spec_round_trip():
    """JSON keys, ranked candidates, uncertainty, and the corrected spec.

    On the reconciliation of the default cable_force case (test_hidden_effect_found, the
    whole catalogue), computed once for both."""
    import json

    result = _run(next(c for c in DEFAULT if c.id == "cable_force-iso"))
    d = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    for key in ("effect", "parameters", "candidates", "gap_before", "gap_after", "noise"):
        assert key in d
    assert d["effect"] == "cable_force"
    assert set(d["gap_before"]) == set(d["gap_after"])
    scores = [c["score"] for c in d["candidates"]]
    assert scores == sorted(scores, reverse=True)
    for c in d["candidates"]:
        assert {"name", "score", "parameters"} <= set(c)
    assert d["noise"]["position"] > 0 and d["noise"]["source"]["position"] == "estimated"
    assert all(v is not None and v > 0 for v in result.uncertainty.values())
    fixed = result.corrected_spec()
    assert [e.type for e in fixed.effects] == ["cable_force"]
    assert math.isclose(fixed.effects[0].stiffness, result.parameters["stiffness"])


def test_noise_from_spec_is_used():
    case = Case("spec-noise", True, None, {}, duration=3.0, seed=51,
                overrides=(("measurement.position_noise", "0.2 um"),
                           ("measurement.force_noise", "2 mN")))
    spec = base_spec(case)
    result = reconcile(spec, measure(case, spec), candidates=["viscous_friction"])
    assert result.noise.source["position"] == "spec"
    assert math.isclose(result.noise.position, 0.2e-6)
    assert result.noise.source["deflection"] == "estimated"
    assert result.effect == "none"


def test_non_uniform_sampling():
    """Jittered sample times: the model is interpolated onto them."""
    from fi_design.measured import measurement_from_arrays

    case = Case("jitter", True, {"type": "viscous_friction", "viscous": 35.0}, {}, duration=3.0,
                seed=61)
    spec = base_spec(case)
    data = measure(case, spec)
    rng = np.random.default_rng(0)
    keep = np.sort(rng.choice(np.arange(1, data.n - 1), size=data.n // 2, replace=False))
    keep = np.concatenate([[0], keep, [data.n - 1]])
    sub = measurement_from_arrays(data.time[keep], data.reference[keep], data.position[keep],
                                  data.force[keep], data.deflection[keep])
    assert not sub.uniform
    result = reconcile(spec, sub, candidates=["viscous_friction", "mass_error"])
    assert result.effect == "viscous_friction"
    assert abs(result.parameters["viscous"] - 35.0) / 35.0 < 0.05


def test_two_effects_with_max_effects():
    from fi_design.spec import EFFECT_MODELS
    from fi_design.simulation.run import simulate
    from fi_design.measured import measurement_from_arrays

    case = Case("two", True, None, {}, duration=3.0, moves=LONG)
    spec = base_spec(case)
    hidden = [EFFECT_MODELS["cable_force"].model_validate({"type": "cable_force",
                                                           "stiffness": 60.0}),
              EFFECT_MODELS["time_delay"].model_validate({"type": "time_delay", "delay": 2e-3})]
    res = simulate(spec, True, effects=hidden)
    rng = np.random.default_rng(71)
    n = len(res.time)
    data = measurement_from_arrays(res.time, res.reference,
                                   res.position + 0.2e-6 * rng.standard_normal(n),
                                   res.force + 2e-3 * rng.standard_normal(n))
    result = reconcile(spec, data, max_effects=2,
                       candidates=["cable_force", "time_delay", "viscous_friction"])
    assert set(result.effects) == {"cable_force", "time_delay"}
    assert len(result.rounds) == 2
    assert result.gap_after["misfit"] < 1.5
    assert len(result.entries) == 2


def test_progress_callback_and_no_printing(capsys):
    case = Case("progress", True, None, {}, duration=2.0, seed=81)
    spec = base_spec(case)
    seen = []
    reconcile(spec, measure(case, spec), candidates=["viscous_friction"],
              progress=lambda msg, frac: seen.append((msg, frac)))
    assert seen and seen[-1][1] == 1.0
    assert all(0.0 <= f <= 1.0 for _, f in seen)
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""


def test_a_nominal_model_that_fails_is_reported_not_raised(tmp_path):
    """A spec whose own loop is unstable on the record: what failed, and a report of the traces."""
    from fi_design.report.gap import render_gap_report

    case = Case("unstable", False, None, {}, duration=2.0, seed=101)
    data = measure(case)
    raw = spec_mapping(case)
    raw["effects"] = [{"type": "time_delay", "delay": "30 ms"}]  # the loop diverges at 1.2 s
    from fi_design.spec.file import load_spec

    spec = load_spec(raw)
    result = reconcile(spec, data, candidates=["viscous_friction"])
    assert result.effect == "none" and result.entries == ()
    assert not result.nominal.success
    assert "fails on this record" in result.conclusion
    assert result.diagnosis.mismatch
    html = render_gap_report(result, tmp_path / "gap.html").read_text()
    assert 'id="finding"' in html and "failed" in html


# --------------------------------------------------------------------------- a faulty record

def _with_force(data, factor: float):
    """The record with its force_N column multiplied by ``factor``."""
    from fi_design.measured import measurement_from_arrays

    return measurement_from_arrays(data.time, data.reference, data.position,
                                   force_N=factor * np.asarray(data.force),
                                   deflection_m=data.deflection, source=f"force x {factor}")


@pytest.mark.parametrize("isolated, factor, cause", [(True, -1.0, "force_sign"),
                                                     (False, 1000.0, "force_scale")],
                         ids=["sign-flipped", "in-millinewtons"])
def test_a_force_column_of_the_wrong_sign_or_scale_is_called_out(isolated, factor, cause):
    """force_N negated (or logged in mN): no effect can explain it, the record is at fault.

    The flipped isolated record used to answer "no catalogue effect explains the gap beyond
    noise" without saying why (its best candidate removed most of the gap, so the structure
    diagnosis stayed silent); the example record flipped named an effect (the slow test below).
    """
    case = Case("faulty-force", isolated, {"type": "force_offset", "offset": 0.5}, {},
                duration=1.0 if not isolated else 2.0, moves=SHORT)
    spec = base_spec(case)
    result = reconcile(spec, _with_force(measure(case, spec), factor),
                       candidates=["force_offset"])
    d = result.diagnosis
    assert result.effect == "none" and result.entries == () and result.steps == ()
    assert d.mismatch and d.causes[0].name == cause and d.causes[0].share > 0.99
    # the replay starts from the first (wrong) force sample, so the model's force is bent too:
    # a flipped record's factor is negative, its size not exact (-0.6 here)
    assert d.force_scale * factor > 0
    if factor > 0:
        assert d.force_scale == pytest.approx(factor, rel=0.05)
    assert result.conclusion.startswith("The nominal model misses the record")
    what = "sign" if factor < 0 else "scale"
    assert f"force_N's {what} looks wrong" in result.conclusion
    assert "No effect is named" in result.conclusion


def test_a_force_column_that_never_changes_is_called_out_without_numpy_warnings(recwarn):
    """force_N logged as 0 N in every row (a dead channel): the record is at fault, said in
    words; before, numpy's "invalid value encountered in divide" of a correlation with a
    constant reached the user's terminal and the cause read "0 times the model's"."""
    case = Case("dead-force", False, {"type": "force_offset", "offset": 0.5}, {},
                duration=1.0, moves=SHORT)
    spec = base_spec(case)
    result = reconcile(spec, _with_force(measure(case, spec), 0.0), candidates=["force_offset"])
    d = result.diagnosis
    assert result.effect == "none" and d.mismatch and d.causes[0].name == "force_scale"
    assert "force_N is 0 N in every row" in d.causes[0].detail
    assert "carries no force signal" in result.conclusion
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)], \
        [str(w.message) for w in recwarn]


@pytest.mark.slow
def test_the_example_record_with_its_force_negated_names_no_effect(tmp_path):
    """examples/measured_trace.csv with force_N negated (about 12 s): position and deflection
    still show the hidden ripple, which used to be named ("The measurement shows
    position_dependent_friction ... misfit 2091 -> 412") with the force channel left 700 times
    its noise after the fit."""
    import json

    from typer.testing import CliRunner

    from fi_design.cli.app import app

    from conftest import EXAMPLES, edited_trace

    def flip(cells):  # force_N negated
        f = cells[3]
        return [*cells[:3], f[1:] if f.startswith("-") else "-" + f, *cells[4:]]

    csv = edited_trace(tmp_path, "flipped.csv", flip)
    res = CliRunner().invoke(app, ["reconcile", str(EXAMPLES / "measured_stage.yaml"), str(csv),
                                   "--json", str(tmp_path / "gap.json")])
    assert res.exit_code == 0, res.output
    assert "Effect: none" in res.output and "The measurement shows" not in res.output
    data = json.loads((tmp_path / "gap.json").read_text())
    assert data["effect"] == "none" and data["steps"] == []
    d = data["diagnosis"]
    assert d["mismatch"] and d["causes"][0]["name"] == "force_sign"
    assert d["best_fit"] == "position_dependent_friction" and d["misfit_after"] > 100
    assert d["force_scale"] == pytest.approx(-1.0, rel=0.02)
    assert "force_N's sign looks wrong" in data["conclusion"]
    top = data["candidates"][0]
    assert top["name"] == "position_dependent_friction" and not top["eligible"]
    assert "force_N looks wrong" in top["reasons"][0]


def test_a_record_far_off_its_reference_carries_the_replays_warning(tmp_path):
    """examples/measured_trace.csv with position_m 50 mm off its reference_m (another zero):
    the replay warns (fi_design.simulation.replay.start_note), but reconcile showed it only as
    a generic "initial state" cause and blamed force_N's scale. The conclusion and the console
    now state the offset, and the initial-state cause names it. One candidate: about 2 s."""
    import io

    from rich.console import Console

    from fi_design import load_measurement, load_spec
    from fi_design.console import print_reconcile
    from fi_design.display import quantity

    from conftest import EXAMPLES, edited_trace

    csv = edited_trace(tmp_path, "offset.csv", lambda c: [*c[:2], repr(float(c[2]) + 0.05),
                                                           *c[3:]])
    rec = load_measurement(csv)
    result = reconcile(load_spec(EXAMPLES / "measured_stage.yaml"), rec,
                       candidates=["cable_force"])
    offset = quantity(float(rec.position[0] - rec.reference[0]), "m", 4)
    assert result.conclusion.startswith("Warning: the record's first position_m")
    assert f"lies {offset} from its first reference_m" in result.conclusion
    assert "subtract the offset" in result.conclusion
    start = next(c for c in result.diagnosis.causes if c.name == "initial_state")
    assert f"position_m starts {offset} from reference_m" in start.detail
    buf = io.StringIO()
    print_reconcile(Console(file=buf, width=200, color_system=None), result)
    assert f"lies {offset} from its first reference_m" in buf.getvalue()


# --------------------------------------------------------------------------- open loop

def _example_with_force(tmp_path, factor: float):
    """examples/measured_trace.csv with force_N times ``factor`` (the cells rewritten)."""
    from fi_design import load_measurement

    from conftest import edited_trace

    csv = edited_trace(tmp_path, f"force_x_{factor:g}.csv",
                       lambda c: [*c[:3], repr(factor * float(c[3])), *c[4:]])
    return csv, load_measurement(csv)


@pytest.mark.parametrize("factor, what", [(-1.0, "sign"), (1000.0, "scale")],
                         ids=["sign-flipped", "in-millinewtons"])
def test_an_open_loop_replay_calls_out_a_force_of_the_wrong_sign_or_scale(tmp_path, factor,
                                                                           what):
    """examples/measured_trace.csv replayed open loop (``--drive force``) with force_N negated
    or logged in mN: the closed loop's force check needs a compared force channel, so the
    flipped record named force_ripple (misfit 9847 -> 5301, "likely causes: initial state;
    controller") after a 7 min search and the mN record answered "the nominal model fails on
    this record ... an unstable closed loop". The measured force is now fitted to the motion
    it drives (mass times acceleration plus friction while sliding): no effect is searched or
    named, and the console, the JSON and the report name force_N and the fault."""
    import io
    import json
    from html import unescape

    from rich.console import Console

    from fi_design import load_spec
    from fi_design.console import print_reconcile
    from fi_design.report import render_gap_report

    from conftest import EXAMPLES

    _, rec = _example_with_force(tmp_path, factor)
    result = reconcile(load_spec(EXAMPLES / "measured_stage.yaml"), rec, drive="force")
    d = result.diagnosis
    assert result.effect == "none" and result.entries == () and result.candidates == ()
    assert d.mismatch and d.causes[0].name == f"force_{what}"
    # the fitted factor: the spec's moving mass is about 0.85 of the one the record's force moves
    assert d.force_scale == pytest.approx(0.85 * factor, rel=0.05)
    message = f"force_N's {what} looks wrong"
    assert message in result.conclusion and "No effect is searched or named" in result.conclusion
    assert ("flip force_N" if factor < 0 else "force_N's unit (N)") in result.conclusion
    buf = io.StringIO()
    print_reconcile(Console(file=buf, width=200, color_system=None), result)
    assert "Effect: none" in buf.getvalue() and message in buf.getvalue()
    assert message in json.loads(json.dumps(result.to_dict()))["conclusion"]
    html = render_gap_report(result, tmp_path / "gap.html").read_text()
    assert message in unescape(html)


def test_an_unedited_open_loop_record_gets_no_force_alarm(tmp_path):
    """The same check on examples/measured_trace.csv as recorded: the record's force moves the
    stage as the spec's mass and friction say (factor about 0.85), no fault; one candidate.
    Its structure diagnosis listed "controller ... check the controller description" (80 %)
    and "the controller's integrator" although the open loop has none."""
    from fi_design import load_measurement, load_spec

    from conftest import EXAMPLES

    result = reconcile(load_spec(EXAMPLES / "measured_stage.yaml"),
                       load_measurement(EXAMPLES / "measured_trace.csv"), drive="force",
                       candidates=["force_offset"])
    d = result.diagnosis
    assert not any(c.name.startswith("force_") for c in d.causes)
    assert d.force_scale == pytest.approx(0.85, rel=0.05)
    assert "force_N" not in result.conclusion
    assert [c.name for c in result.candidates] == ["force_offset"]
    # no controller in the replay: the structure's likely causes name none
    assert d.mismatch and [c.name for c in d.causes][:2] == ["measured_force", "initial_state"]
    assert not any("controller" in c.name or "controller" in c.detail for c in d.causes)
    assert d.causes[1].detail.endswith(
        "check the state of the mechanics the open-loop replay starts from (position and "
        "velocity from the record, the friction's presliding state, the isolator's deflection).")
    assert "Likely causes, strongest first: measured force (" in result.conclusion
    from html import unescape

    from fi_design.report import render_gap_report

    html = unescape(render_gap_report(result, tmp_path / "gap.html").read_text())
    assert "Shares are of the residual's energy (measured force, initial state, disturbance) " \
           "or its R² (mass)" in html
    assert "controller" not in html.split("The model's structure misses the record")[1].split(
        "</table>")[0]
    # the caption of a closed loop (the same result relabelled) keeps the controller
    from dataclasses import replace

    closed = unescape(render_gap_report(replace(result, drive="closed"),
                                        tmp_path / "closed.html").read_text())
    assert "Shares are of the residual's energy (controller, initial state, disturbance) or " \
           "its R² (mass)" in closed


def test_a_nominal_model_that_fails_open_loop_points_at_the_force_not_a_controller():
    """A record whose constant 100 kN force_N throws the open-loop replay off (nothing the
    inverse dynamics can tell: a constant is an offset) said "an unstable closed loop" and
    "check the spec against the record (controller, mass, sample rate)"; open loop it now
    names the force and the mechanics. The closed loop of an unstable spec keeps its text."""
    from fi_design import load_spec
    from fi_design.measured import measurement_from_arrays

    from conftest import EXAMPLES, variant

    spec = load_spec(EXAMPLES / "measured_stage.yaml")
    n = 400
    t = np.arange(n) * 1e-3
    rng = np.random.default_rng(1)
    x = 1e-3 * np.sin(2 * np.pi * 2.0 * t)
    rec = measurement_from_arrays(t, x, x + 1e-7 * rng.standard_normal(n),
                                  np.full(n, 1e5) + rng.standard_normal(n))
    opened = reconcile(spec, rec, drive="force")
    assert opened.effect == "none" and opened.diagnosis.causes == ()
    assert opened.conclusion.startswith("The nominal model fails on this record: solution "
                                        "diverged at t = ")
    assert opened.conclusion.endswith(
        "s; likely cause: the recorded force drives the stage beyond any plausible travel (open "
        "loop, only the spec's friction and stiffness hold it): check force_N's sign and unit "
        "(N), and the friction or stiffness terms of the spec. No effect can be judged against "
        "a model that does not run; check the spec against the record (mass, friction, "
        "force_N's sign and unit).")
    assert "controller" not in opened.conclusion and "closed loop" not in opened.conclusion
    unstable = variant(spec, **{"controller.crossover": "60 Hz", "controller.delay": "5 ms"})
    closed = reconcile(unstable, rec)
    assert closed.conclusion.endswith(
        "s; likely cause: an unstable closed loop: check the crossover against the achievable "
        "one (guideline step 2), the delay and the sample rate. No effect can be judged against "
        "a model that does not run; check the spec against the record (controller, mass, "
        "sample rate).")


def test_a_record_whose_stage_never_moves_is_refused_naming_position_m():
    """position_m frozen at its first value while the reference moves: it was reconciled and
    the diagnosis said to flip force_N (the force was right; the position column was not)."""
    from fi_design.errors import DataError
    from fi_design.measured import measurement_from_arrays

    case = Case("frozen-position", False, {"type": "force_offset", "offset": 0.5}, {},
                duration=1.0, moves=SHORT)
    spec = base_spec(case)
    data = measure(case, spec)
    frozen = measurement_from_arrays(data.time, data.reference,
                                     np.full_like(data.position, data.position[0]),
                                     force_N=data.force, source="frozen.csv")
    with pytest.raises(DataError) as e:
        reconcile(spec, frozen)
    assert e.value.column == "position_m" and "never moves" in str(e.value)


def test_the_specs_own_simulation_agrees_within_noise(tmp_path):
    """A record the spec's own simulation wrote (`fi-design simulate --csv`, noise-free at the
    default tolerance) carries that simulation's integration error, a few nm and correlated,
    which the noise estimate (third differences) does not see. With the position floor at
    1 nm the reconciliation's tight replay read it as a gap of 2.6 noise units and named
    stribeck_velocity = 3.00004 mm/s (the spec's is 3 mm/s). The floors are now the accuracy a
    simulation at the default tolerance has: the nominal model agrees within noise."""
    from typer.testing import CliRunner

    from conftest import EXAMPLES
    from fi_design.cli.app import app
    from fi_design.measured import load_measurement
    from fi_design.spec.file import load_spec

    spec_path, trace = EXAMPLES / "measured_stage.yaml", tmp_path / "own.csv"
    r = CliRunner().invoke(app, ["simulate", str(spec_path), "--csv", str(trace)])
    assert r.exit_code == 0, r.output
    result = reconcile(load_spec(spec_path), load_measurement(trace),
                       candidates=["stribeck_velocity"])
    assert result.effect == "none", result.conclusion
    assert result.diagnosis.misfit < 1.0, result.diagnosis.misfit
    assert result.conclusion.startswith("The nominal model agrees with the measurement within "
                                        "noise"), result.conclusion
    # nothing was fitted: the console and the report say so, with no empty candidate table
    import io

    from rich.console import Console

    from fi_design import report
    from fi_design.console import print_reconcile

    assert result.candidates == ()
    buf = io.StringIO()
    print_reconcile(Console(file=buf, width=120, color_system=None), result)
    assert "Candidates (best first)" not in buf.getvalue()
    html = report.render_html(report.build_context(result, date="2026-01-01", figures=False))
    assert "No catalogue effect was fitted: the nominal model agrees" in html
    assert "Every applicable catalogue effect was fitted" not in html


@pytest.mark.slow  # 9 s; test_replay.py's mid-move record guards the replay by default
def test_a_record_that_starts_in_motion_names_its_effect_not_a_disturbance(tmp_path):
    """examples/measured_trace.csv cut 0.3 s into its move (sliding at 19 mm/s, the
    command rising): the replay started with the roll-off's state in the integrator and a
    velocity read from 5 ms of noisy samples, missed by 4 um RMS for a second, and the
    reconciliation, its best fit still 13 noise units off, called the gap structural with
    "disturbance (90 %)" as its likely cause. The replay now starts on the record's state
    (tests/simulation/test_replay.py): the hidden effect is named with its true values."""
    from conftest import EXAMPLES
    from fi_design.measured import load_measurement, measurement_from_arrays
    from fi_design.spec.file import load_spec

    full = load_measurement(EXAMPLES / "measured_trace.csv")
    i0 = int(np.searchsorted(full.time, 0.3))
    cut = measurement_from_arrays(full.time[i0:] - full.time[i0], full.reference[i0:],
                                  full.position[i0:], force_N=full.force[i0:],
                                  deflection_m=full.deflection[i0:], source="caught mid-move")
    result = reconcile(load_spec(EXAMPLES / "measured_stage.yaml"), cut,
                       candidates=["position_dependent_friction", "force_offset"])
    assert result.effect == "position_dependent_friction", result.conclusion
    assert result.conclusion.startswith("The measurement shows"), result.conclusion
    assert "disturbance" not in result.conclusion
    truth = {"amplitude": 0.25, "wavelength": 5e-3, "phase": 0.8}  # make_measured_trace.py
    for name, value in truth.items():
        fitted, error = result.parameters[name], result.uncertainty[name]
        assert abs(fitted - value) < 4 * error, (name, fitted, error)


@pytest.mark.slow  # 9 s
def test_a_noise_only_hunting_record_answers_none_whatever_its_cycles_phase(monkeypatch):
    """The noise-only hunting record of SLOW_CONTROLS (rigid, one cycle) replayed from a first
    reference rate 3e-15 m/s off (what a one-sided fit of 10 ms instead of 5 ms gives):
    the model agreed within noise (misfit 1.003), yet force_offset scored 32.7 against the
    noise of the cycle's phase, explained "the gap above noise" (chi2 - n, itself noise)
    and was named. A model that agrees within noise leaves no gap: none is named."""
    import fi_design.simulation.run as run
    from fi_design.reconciliation.significance import within_noise

    real = run.reference_state

    def nudged(record, index=0, *args):
        r, rd, rdd = real(record, index, *args)
        return r, rd - 3.03685e-15, rdd

    monkeypatch.setattr(run, "reference_state", nudged)
    case = next(c for c in SLOW_CONTROLS if c.id == "noise-only-hunting-rigid-one-cycle")
    result = reconcile(base_spec(case), measure(case, base_spec(case)))
    assert within_noise(result.chi2_nominal, result.n_points), result.gap_before["misfit"]
    _check_none(case, result)
    assert result.conclusion.startswith("The nominal model agrees with the measurement within "
                                        "noise"), result.conclusion
