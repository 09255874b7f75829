"""The spec resolved once (fi_design.model): its values, its variants, its one home per value.

The resolved values are checked against the documented formulas written out here, the
friction curve against the compiled kernel's Stribeck function, the variants of
``Model.at`` against the spec resolved with the same values, and the design workflow
against rebuilding any value from the spec more than once.
"""

from __future__ import annotations

import ast
import dataclasses
import math
import typing
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from fi_design.errors import SpecError
from fi_design.model import Model, given_mode, resolve

from conftest import variant

PACKAGE = Path(__file__).resolve().parents[1] / "fi_design"


# --------------------------------------------------------------------------- resolving


def test_resolve_fills_the_defaults_design_md_gives(paper_spec):
    """Bristle, joint and limiter damping and the proposed stiffness, as the spec documents them."""
    bare = variant(paper_spec, **{"friction.bristle_damping": None, "isolator.stiffness": None,
                                  "isolator.damping": None, "isolator.limiter": None})
    m = resolve(bare)
    m1, m2 = bare.stage.mass, bare.cart.mass
    f = bare.friction
    assert m.friction.sigma1 == pytest.approx(math.sqrt(f.bristle_stiffness * (m1 + m2)),
                                              rel=1e-15)
    k = 0.5 * f.static / (bare.requirements.stiffness_safety * bare.isolator.stroke)
    assert m.joint.stiffness == pytest.approx(k, rel=1e-15)
    assert not m.joint.stiffness_given and not m.joint.damping_given
    assert m.joint.damping == pytest.approx(2 * 0.05 * math.sqrt(k * m1 * m2 / (m1 + m2)),
                                            rel=1e-15)
    assert m.limiter.stiffness == 1e6
    assert m.limiter.damping == pytest.approx(2 * 0.2 * math.sqrt(1e6 * m1), rel=1e-15)
    assert (m.m1, m.m2, m.offset, m.crossover) == (m1, m2, f.offset, 8.0)
    # the measured structure mode joins the sized guide's own modes
    assert m.given_modes == tuple(given_mode(x) for x in bare.isolator.parasitic_modes)
    assert set(m.given_modes) <= set(m.modes) and m.effects == bare.effects
    assert {x.source for x in m.modes} == {"given", "computed"}


def test_the_kernel_parameters_are_the_resolved_values(paper_spec):
    """Model.plant: joint, limiter, friction and the tuning rule's gains."""
    m = resolve(paper_spec)
    p = m.plant(True)
    assert (p.m1, p.m2, p.k, p.c, p.s) == (1.6, 0.4, 6667.0, 4.62, 0.3e-3)
    assert (p.k_stop, p.c_stop) == (m.limiter.stiffness, m.limiter.damping)
    assert (p.Fs, p.Fc, p.vs, p.sigma0, p.sigma1, p.sigma2) == (4.0, 1.0, 3e-3, 1e6, 1414.0, 20.0)
    wc = 2 * math.pi * 8.0
    ks = 2.0 * wc ** 2 / 3  # m wc^2 / r on m1 + m2
    wi, wd, wt = wc / 10, wc / 3, 3 * wc
    assert p.kp == pytest.approx(ks * (1 + wi / wd), rel=1e-14)
    assert p.ki == pytest.approx(ks * wi, rel=1e-14)
    assert p.kd == pytest.approx(ks / wd, rel=1e-14)
    assert p.wt == pytest.approx(wt, rel=1e-14)
    assert math.isnan(p.Fc_neg) and math.isnan(p.sigma2_neg)  # follow the positive direction
    rigid = m.plant(False)
    assert (rigid.isolated, rigid.k, rigid.c, rigid.s, rigid.k_stop) == (0.0, 0.0, 0.0, 0.0, 0.0)
    with pytest.raises(Exception, match="no isolator"):
        resolve(variant(paper_spec, isolator=None)).plant(True)


def test_a_model_passes_where_a_spec_does(paper_spec):
    from fi_design.model import as_model

    m = resolve(paper_spec)
    assert as_model(m) is m and isinstance(as_model(paper_spec), Model)


def test_resolve_takes_the_path_and_mapping_design_and_simulate_take(paper_spec,
                                                                     paper_spec_path):
    """resolve(path or mapping) loads the spec as design() and simulate() do (resolve took a
    Spec only: "expected a Spec (or a Model), got PosixPath"); anything else is refused
    naming what it is, and a mapping that is no spec names the missing field."""
    from fi_design.errors import ArgumentError
    from fi_design.spec.file import origin

    want = resolve(paper_spec)
    for given in (paper_spec_path, str(paper_spec_path), origin(paper_spec).raw):
        m = resolve(given)
        assert m.spec.model_dump() == paper_spec.model_dump()
        assert m.plant(True) == want.plant(True) and m.law == want.law
    for bad, name in ((5, "int"), (None, "NoneType"), ([paper_spec], "list"), (want, "Model")):
        with pytest.raises(ArgumentError, match="spec must be a Spec, a path to a YAML spec or "
                           f"a mapping, got {name}$"):
            resolve(bad)
    with pytest.raises(SpecError, match="stage"):
        resolve({"name": "a mapping"})


def _entry_points():
    """(name, call on a bad argument, the argument's name, whether it takes a Model)."""
    import fi_design
    from fi_design.model import as_model
    from fi_design.stage import stage_hunting, stage_hunts
    from fi_design.studies import paper_study

    return [
        ("design", lambda x: fi_design.design(x), "spec", True),
        ("simulate", lambda x: fi_design.simulate(x), "spec", True),
        ("recommend", lambda x: fi_design.recommend(x), "spec", True),
        ("sweep", lambda x: fi_design.sweep(x, ("controller.crossover", [8.0])), "spec", True),
        ("robustness", lambda x: fi_design.robustness(x, []), "spec", True),
        ("paper_study", lambda x: paper_study(x), "spec", True),
        ("stage_hunting", lambda x: stage_hunting(x), "model", True),
        ("stage_hunts", lambda x: stage_hunts(x, True), "model", True),
        ("as_model", lambda x: as_model(x), "spec", True),
        ("resolve", lambda x: fi_design.resolve(x), "spec", False),
        ("with_values", lambda x: fi_design.with_values(x, {}), "spec", False),
        ("reconcile", lambda x: fi_design.reconcile(x, None), "spec", False),
    ]


@pytest.mark.parametrize("case", range(len(_entry_points())),
                         ids=[c[0] for c in _entry_points()])
def test_a_bad_spec_is_refused_naming_what_the_call_takes(case):
    """simulate(42) said 'spec must be a Spec, a path to a YAML spec or a mapping, got int',
    though simulate takes a Model as well, and stage_hunts(42, True) named its argument
    `model` 'spec'. Each entry point names its argument and what it takes: a Model where it
    takes one, and not where it does not (resolve, with_values, reconcile)."""
    from fi_design.errors import ArgumentError

    _, call, name, takes_model = _entry_points()[case]
    model = "a Model, " if takes_model else ""
    with pytest.raises(ArgumentError, match=f"^{name} must be a Spec, {model}a path to a YAML "
                       "spec or a mapping, got int$"):
        call(42)


# --------------------------------------------------------------------------- variants


def test_at_crossover_is_the_spec_resolved_at_that_crossover(paper_spec):
    """The rule retunes, a given roll-off stays, explicit gains scale in frequency."""
    for extra in ({}, {"controller.roll_off": "40 Hz"}):
        spec = variant(paper_spec, **extra)
        shifted = resolve(spec).at(crossover=13.0).law
        fresh = resolve(variant(spec, **{"controller.crossover": "13 Hz"})).law
        assert dataclasses.asdict(shifted) == dataclasses.asdict(fresh)
    gains = variant(paper_spec, **{"controller.crossover": None,
                                   "controller.gains": {"kp": 5000.0, "ki": 20000.0, "kd": 90.0},
                                   "controller.roll_off": "100 Hz"})
    law = resolve(gains).law
    lam = 13.0 / law.crossover
    moved = resolve(gains).at(crossover=13.0).law
    assert (moved.kp, moved.ki, moved.kd, moved.roll_off) == pytest.approx(
        (law.kp * lam ** 2, law.ki * lam ** 3, law.kd * lam, law.roll_off * lam), rel=1e-14)
    assert moved.crossover == 13.0 and moved.source == "gains"


def test_at_stiffness_keeps_the_joint_modes_damping_ratio(paper_spec):
    free = variant(paper_spec, **{"isolator.damping": None})
    m = resolve(free)
    stiffer = m.at(stiffness=4.0 * m.joint.stiffness)
    assert stiffer.joint.damping == pytest.approx(2.0 * m.joint.damping, rel=1e-14)
    same = resolve(variant(free, **{"isolator.stiffness": 4.0 * m.joint.stiffness}))
    assert stiffer.plant(True) == same.plant(True)
    given = resolve(paper_spec)  # damping given: it stays
    assert given.at(stiffness=1000.0).joint.damping == given.joint.damping == 4.62


def test_at_stroke_moves_a_proposed_stiffness_with_it(paper_spec):
    proposed = variant(paper_spec, **{"isolator.stiffness": None, "isolator.damping": None})
    m = resolve(proposed)
    wider = m.at(stroke=2.0 * m.joint.stroke)
    assert wider.joint.stiffness == pytest.approx(m.joint.stiffness / 2.0, rel=1e-14)
    assert wider.plant(True) == resolve(
        variant(proposed, **{"isolator.stroke": 2.0 * m.joint.stroke})).plant(True)
    given = resolve(paper_spec)
    assert given.at(stroke=1e-3).joint.stiffness == 6667.0


def test_at_adds_the_isolator_a_spec_would_get(paper_spec):
    from fi_design.stage.confirm import with_isolator

    bare = variant(paper_spec, isolator=None)
    added = resolve(bare).at(stroke=0.3e-3, stiffness=5000.0)
    assert added.has_isolator and added.modes == ()
    assert added.plant(True) == with_isolator(resolve(bare), 0.3e-3, 5000.0).plant(True)
    assert resolve(bare).at(stroke=0.3e-3).joint.stiffness == pytest.approx(
        0.5 * bare.friction.static / 0.3e-3, rel=1e-14)


@pytest.mark.parametrize("change, path", [
    (dict(crossover=0.0), "controller.crossover"),
    (dict(crossover=-3.0), "controller.crossover"),
    (dict(crossover=math.nan), "controller.crossover"),
    (dict(crossover=math.inf), "controller.crossover"),
    (dict(stiffness=0.0), "isolator.stiffness"),
    (dict(stroke=-1e-3), "isolator.stroke"),
    (dict(damping=-1.0), "isolator.damping"),
    (dict(friction_model="coulomb"), "friction.model"),
    (dict(effects=[{"type": "time_delay", "delay": 1e-3}]), "effects[0]"),
])
def test_at_refuses_what_the_spec_refuses(paper_spec, change, path):
    m = resolve(paper_spec)
    with pytest.raises(SpecError) as err:
        m.at(**change)
    assert err.value.path == path
    assert m.crossover == 8.0 and m.joint.stiffness == 6667.0  # unchanged


def test_varied_is_the_spec_with_the_values_resolved(paper_spec):
    """Model.varied: the spec edited at dotted paths, validated and resolved once; its spec
    holds the values (nothing differs from it) and the fast form at() gives the same plant."""
    from fi_design.spec.file import with_values

    m = resolve(paper_spec)
    values = {"isolator.stroke": "0.5 mm", "isolator.stiffness": 4000.0,
              "controller.crossover": 11.0, "friction.coulomb": 2.5}
    v = m.varied(values)
    fresh = resolve(with_values(paper_spec, values))
    assert v.plant(True) == fresh.plant(True) and v.law == fresh.law
    assert v.spec.isolator.stroke == 0.5e-3 and v.spec.friction.coulomb == 2.5
    assert v.changed == () and m.spec is paper_spec  # the model it came from is unchanged
    fast = m.at(stroke=0.5e-3, stiffness=4000.0, crossover=11.0)
    assert fast.plant(True) == m.varied({k: x for k, x in values.items()
                                         if k != "friction.coulomb"}).plant(True)
    assert fast.changed and fast.spec is paper_spec
    with pytest.raises(SpecError, match="friction.statc"):
        m.varied({"friction.statc": 1.0})
    with pytest.raises(SpecError, match="friction"):
        m.varied({"friction.static": 0.5})  # below friction.coulomb (1 N)


def test_varied_refuses_a_model_varied_by_at(paper_spec):
    """at() leaves the spec as written, so varying its spec would drop the at() values."""
    from fi_design.errors import ArgumentError

    m = resolve(paper_spec)
    for fast, where in ((m.at(crossover=10.0), "controller.crossover"),
                        (m.at(delay=1e-3), "controller.delay"),
                        (m.at(masses=(m.m1 * 1.1, m.m2)), "stage.mass, cart.mass"),
                        (m.at(mode_scale=0.9), "mode_scale")):
        with pytest.raises(ArgumentError, match=where):
            fast.varied({"isolator.stroke": 1e-3})


def test_at_refuses_isolator_values_without_an_isolator(paper_spec):
    from fi_design.spec import EFFECT_MODELS

    bare = resolve(variant(paper_spec, isolator=None))
    with pytest.raises(SpecError, match="no isolator") as err:
        bare.at(stiffness=5000.0)
    assert err.value.path == "isolator.stroke"
    damping = EFFECT_MODELS["joint_damping"].model_validate({"type": "joint_damping",
                                                            "damping": 3.0})
    with pytest.raises(SpecError, match="needs an isolator"):
        bare.at(effects=[damping])
    assert resolve(paper_spec).at(effects=[damping]).plant(True).c == 3.0


# --------------------------------------------------------------------------- friction curve


def test_steady_state_friction_is_the_kernels_stribeck_curve(paper_spec):
    """One friction law: the model's numpy curve equals the compiled kernel's g(v) per direction."""
    from fi_design.kernel.build import compiled

    spec = variant(paper_spec, **{"friction.coulomb_negative": "1.5 N",
                                  "friction.viscous_negative": "30 N*s/m"})
    m = resolve(spec)
    p = m.plant(False).to_array()
    v = np.concatenate([-np.geomspace(1e-6, 0.1, 40), np.geomspace(1e-6, 0.1, 40)])
    ours = m.friction.steady_state(v)
    for vi, fi in zip(v, ours):
        sgn = 1.0 if vi > 0 else -1.0
        g = compiled().stribeck(vi, 0.0, sgn, p)[0]
        s2 = 20.0 if vi > 0 else 30.0
        assert fi == pytest.approx(sgn * g + s2 * vi, rel=1e-13)
    # g(v) = Fc + (Fs - Fc) exp(-(v/vs)^2), Fs scaled by Fc_neg / Fc going back
    fs_neg = 4.0 * 1.5 / 1.0
    assert m.friction.steady_state(-0.002) == pytest.approx(
        -(1.5 + (fs_neg - 1.5) * math.exp(-(0.002 / 3e-3) ** 2)) - 30.0 * 0.002, rel=1e-14)
    assert m.friction.steady_state(0.0) == pytest.approx(0.5 * (4.0 - fs_neg))
    assert resolve(paper_spec).friction.steady_state(0.0) == 0.0


# --------------------------------------------------------------------------- resolved once


def _count(monkeypatch, module, name) -> list:
    """Count calls of ``module.name`` wherever a loaded fi_design module holds it."""
    import sys

    original = getattr(module, name)
    calls = []

    def counted(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    for mod in list(sys.modules.values()):
        if getattr(mod, "__name__", "").startswith("fi_design") and \
                getattr(mod, name, None) is original:
            monkeypatch.setattr(mod, name, counted)
    return calls


def test_design_resolves_the_spec_once(paper_spec, monkeypatch):
    """The control law, the gains' crossover and the drive stiffness are worked out once."""
    import fi_design.guideline.evaluate  # noqa: F401  (the modules whose references are counted)
    import fi_design.guideline.steps  # noqa: F401
    import fi_design.loop.linear  # noqa: F401
    import fi_design.guideline.verdict  # noqa: F401
    from fi_design.controller import pid
    from fi_design import spec as spec_module
    from fi_design.guideline.evaluate import evaluate as design

    gains = variant(paper_spec, **{"controller.crossover": None,
                                   "controller.gains": {"kp": 5000.0, "ki": 20000.0, "kd": 90.0}})
    laws = _count(monkeypatch, pid, "control_law")
    roots = _count(monkeypatch, spec_module, "gains_crossover")
    stiffness = _count(monkeypatch, spec_module, "drive_stiffness")
    result = design(gains, confirm=False)
    assert (len(laws), len(roots), len(stiffness)) == (1, 1, 1)
    assert result.model.law is result.pid.controller
    assert result.crossover.desired == result.model.crossover


def test_the_gains_crossover_is_the_root_of_the_loop_gain(paper_spec):
    """|C(j w)| = m w^2 at the crossover of explicit gains, to the last digits (a root finder)."""
    for roll_off in (None, "60 Hz"):
        spec = variant(paper_spec, **{"controller.crossover": None, "controller.roll_off": roll_off,
                                      "controller.gains": {"kp": 7.8e5, "ki": 8.3e6,
                                                           "kd": 1.3e4}})
        law = resolve(spec).law
        w = 2 * math.pi * law.crossover
        wf = math.inf if roll_off is None else 2 * math.pi * 60.0
        d = 1j * w * law.kd if math.isinf(wf) else 1j * w * law.kd / (1 + 1j * w / wf)
        excess = abs(law.kp + law.ki / (1j * w) + d) / (spec.total_mass * w * w) - 1.0
        assert abs(excess) < 1e-14


# --------------------------------------------------------------------------- one home per value


def test_the_value_types_live_in_the_results_layer_and_are_typed():
    from fi_design.loop import linear
    from fi_design.controller import pid
    from fi_design.results import controller, design
    from fi_design.results import linear as linear_results

    assert linear.CaseMargins is linear_results.CaseMargins
    assert pid.ControlLaw is controller.ControlLaw and pid.PidGains is controller.PidGains
    for cls in (linear_results.CaseMargins, linear_results.LoopAnalysis,
                linear_results.AchievableCrossover):
        assert cls.__module__ == "fi_design.results.linear"
    hints = typing.get_type_hints(design.CrossoverResult)
    assert hints["cases"] == tuple[linear_results.CaseMargins, ...]
    hints = typing.get_type_hints(design.PidResult)
    assert (hints["gains"], hints["controller"]) == (controller.PidGains, controller.ControlLaw)


def test_no_spec_is_copied_without_validation():
    """pydantic's model_copy(update=...) skips validation: the package never calls it."""
    calls = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                    and node.func.attr == "model_copy" and node.keywords:
                calls.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert calls == []


def test_with_sections_validates_what_it_replaces(paper_spec):
    from fi_design.stage.confirm import with_isolator
    from fi_design.results.reconciliation import ReconcileResult
    from fi_design.spec import EFFECT_MODELS

    bare = variant(paper_spec, isolator=None)
    with pytest.raises(SpecError) as err:
        bare.with_sections(isolator={"stroke": -1e-3})
    assert err.value.path == "isolator.stroke"
    with pytest.raises(SpecError, match="unknown section"):
        bare.with_sections(isolater=None)
    damping = EFFECT_MODELS["joint_damping"].model_validate({"type": "joint_damping",
                                                            "damping": 3.0})
    with pytest.raises(SpecError, match="joint_damping needs an isolator"):
        bare.with_sections(effects=(damping,))
    # the corrected spec of a reconciliation is checked like every spec
    with pytest.raises(SpecError, match="joint_damping needs an isolator"):
        ReconcileResult.corrected_spec(SimpleNamespace(spec=bare, effect_entries=(damping,)))
    added = with_isolator(resolve(bare), 0.3e-3, 5000.0)
    assert (added.spec.isolator.stroke, added.spec.isolator.stiffness) == (0.3e-3, 5000.0)
    assert (added.joint.stroke, added.joint.stiffness, added.changed) == (0.3e-3, 5000.0, ())
    assert added.spec.controller is bare.controller  # untouched sections are shared
    # the same spec the section written by hand gives
    assert added.spec.content_sha256() == bare.with_sections(
        isolator={"stroke": 0.3e-3, "stiffness": 5000.0}).content_sha256()
    with pytest.raises(SpecError) as err:
        with_isolator(resolve(bare), -1e-3, 5000.0)
    assert err.value.path == "isolator.stroke"


# --------------------------------------------------------------------------- judged once


def test_a_limit_case_is_judged_where_its_margins_are_computed(paper_spec):
    """The status and the criteria of each case; step 2's checks are those judgements."""
    from fi_design.loop import linear
    from fi_design.guideline.steps import step2_crossover
    from fi_design.results import Status

    cases = linear.analyse(resolve(paper_spec)).cases
    by_name = {c.name: c for c in cases}
    for c in cases:
        assert c.status == (Status.FAIL if not c.passed else
                            Status.INFO if not c.in_band else Status.PASS)
        worst = max(c.criteria.values(), key=[Status.PASS, Status.INFO, Status.FAIL].index)
        assert c.status == worst
    stuck = by_name["stuck_limited"]  # the integrator against the bristles: crosses far below
    assert not stuck.in_band and stuck.status == Status.INFO
    assert stuck.criteria["phase margin"] == Status.INFO
    checks = {ch.name: ch for ch in step2_crossover(resolve(paper_spec)).checks}
    for c in cases:
        for criterion, key in (("phase margin", "phase_margin"), ("gain margin", "gain_margin")):
            assert checks[f"{key}.{c.name}"].status == c.criteria[criterion]


def test_report_and_console_show_the_status_the_analysis_gave(paper_spec):
    """Presentation reads a case's status: a case judged FAIL shows FAIL, whatever else it holds."""
    from rich.console import Console

    from fi_design import console as console_module
    from fi_design.guideline.evaluate import evaluate as design
    from fi_design.report.design import _cases_table
    from fi_design.results import Status

    result = design(paper_spec, confirm=False)
    first = result.crossover.cases[0]
    assert first.passed and first.in_band and first.status == Status.PASS
    judged = dataclasses.replace(first, status=Status.FAIL)
    doctored = dataclasses.replace(result, crossover=dataclasses.replace(
        result.crossover, cases=(judged,) + result.crossover.cases[1:]))
    rows = _cases_table(doctored)
    assert [r["status"] for r in rows] == [c.status.value for c in doctored.crossover.cases]
    assert rows[0]["status"] == "FAIL"
    cases = doctored.to_dict()["crossover"]["cases"]
    table = console_module.cases_table(cases, {c.name: c.number for c in result.loop.cases})
    out = Console(width=200, record=True)
    out.print(table)
    lines = [ln for ln in out.export_text().splitlines() if "cart sliding, joint free" in ln]
    assert len(lines) == 1 and "FAIL" in lines[0] and "PASS" not in lines[0]


# --------------------------------------------------------------------------- identification


def _old_curve(p, form, stribeck, v):
    """The identified friction curve written out from its definition (the report's curve before)."""
    symmetric = form == "symmetric"
    fc_pos = p["coulomb"] + (p["offset"] if symmetric else 0.0)
    fc_neg = (p["coulomb"] - p["offset"]) if symmetric else p["coulomb_negative"]
    pos = fc_pos + p["viscous"] * v
    neg = -fc_neg + p["viscous_negative"] * v
    if stribeck:
        e = np.exp(-(v / p["stribeck_velocity"]) ** 2)
        ratio = 1.0 if symmetric else p["coulomb_negative"] / p["coulomb"]
        pos = pos + (p["static"] - p["coulomb"]) * e
        neg = neg - (p["static"] - p["coulomb"]) * ratio * e
    return np.where(v > 0, pos, np.where(v < 0, neg, 0.5 * (pos + neg)))


@pytest.fixture(scope="module")
def identified():
    import fi_design
    from fi_design.measured import load_measurement
    from fi_design.spec.file import load_spec

    root = PACKAGE.parent / "examples"
    record = load_measurement(root / "measured_trace.csv")
    spec = load_spec(root / "measured_stage.yaml")
    return {form: fi_design.identify(record, spec=spec, form=form)
            for form in ("symmetric", "per_direction")}


@pytest.mark.parametrize("form", ["symmetric", "per_direction"])
@pytest.mark.parametrize("stribeck", [False, True])
def test_the_identified_friction_curve_is_the_models_friction_law(identified, form, stribeck):
    from fi_design.model import FrictionLaw

    r = identified[form]
    if stribeck:  # as if the record held breakaways: static friction and vs identified
        extra = {"static": 1.6 * r.value("coulomb"), "stribeck_velocity": 2e-3}
        r = dataclasses.replace(r, parameters={
            k: (dataclasses.replace(p, value=extra[k], identifiable=True) if k in extra else p)
            for k, p in r.parameters.items()})
    p = {k: (x.value if x.value is not None else 0.0) for k, x in r.parameters.items()}
    v = np.concatenate([-np.geomspace(1e-6, 0.05, 50), [0.0], np.geomspace(1e-6, 0.05, 50)])
    assert isinstance(r.friction, FrictionLaw)
    np.testing.assert_allclose(r.friction_curve(v), _old_curve(p, form, stribeck, v),
                               rtol=1e-12, atol=1e-12)


def test_the_identification_report_draws_the_results_curve(identified, monkeypatch):
    from fi_design.identification import IdentificationResult
    from fi_design.plots import force_velocity_figure

    monkeypatch.setattr(IdentificationResult, "friction_curve",
                        lambda self, v: np.full(np.shape(v), 123.0))
    fig = force_velocity_figure(identified["symmetric"])
    fitted = [ln for ln in fig.axes[0].get_lines() if len(ln.get_xdata()) > 100
              and ln.get_linestyle() == "-"]
    assert fitted and all(np.all(np.asarray(ln.get_ydata()) == 123.0) for ln in fitted)


def test_a_varied_model_says_what_it_changed_and_design_takes_it(paper_spec):
    from fi_design.errors import ArgumentError
    from fi_design.guideline.evaluate import evaluate as design

    m = resolve(paper_spec)
    assert m.changed == ()
    varied = m.at(crossover=10.0).at(stiffness=5000.0, crossover=9.0)
    assert varied.changed == ("controller.crossover", "isolator.stiffness")
    result = design(varied, confirm=False)  # the linear steps on the varied model
    assert result.crossover.desired == 9.0 and result.stiffness.chosen == 5000.0
    assert result.model is varied and result.spec is paper_spec
    with pytest.raises(ArgumentError, match="controller.crossover, isolator.stiffness"):
        design(varied)  # the robustness study would vary the spec, not the model


def test_a_model_names_where_it_departs_from_its_spec(paper_spec):
    """Model.at's paths and a mode scale are departures; a study, the search and the
    sign-off's robustness study refuse such a model with their names."""
    from fi_design.errors import ArgumentError
    from fi_design.model import resolve
    from fi_design.studies.points import study_model

    model = resolve(paper_spec)
    assert model.departures == ()
    assert model.varied({"controller.crossover": 9.0}).departures == ()
    moved = model.at(crossover=9.0, mode_scale=0.9)
    assert moved.departures == ("controller.crossover", "mode_scale")
    assert model.at(mode_scale=0.9).departures == ("mode_scale",)
    for refuse in (lambda: study_model(model.at(mode_scale=0.9)),
                   lambda: model.at(mode_scale=0.9).varied({"isolator.stroke": 4e-4})):
        with pytest.raises(ArgumentError, match="mode_scale"):
            refuse()
