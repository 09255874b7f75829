"""The design search: the stiffest buildable joint that keeps the hunting margin, checked by what
it did not make.

The paper setup's recommendation is checked by the finite-element model of its guide (it does
not buckle standing, its modes clear the separation), by moves simulated with the independent
solve_ivp simulator of ``tests/independent.py`` at nominal friction, at the corners of the
friction scatter and with the masses 15 % off (none hunts), and by the design command on the
written spec and on the least change (both pass).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fi_design.recommend import recommend

from conftest import variant

FEW = {"requirements.robustness.samples": 30}


@pytest.fixture(scope="module")
def paper_file(paper_spec_path, tmp_path_factory):
    """examples/paper_setup.yaml as written (comments kept), with 30 scatter samples."""
    text = paper_spec_path.read_text(encoding="utf-8")
    text = text.replace("  gain_margin: 6 dB\n", "  gain_margin: 6 dB\n  robustness: {samples: 30}\n")
    path = tmp_path_factory.mktemp("paper") / "paper_setup.yaml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def search_cache(tmp_path_factory):
    """The folder the paper setup's search is kept in (``FI_DESIGN_CACHE_DIR/recommend``)."""
    return tmp_path_factory.mktemp("cache") / "recommend"


@pytest.fixture(scope="module")
def paper_recommendation(paper_file, search_cache):
    """The search of the paper setup (30 scatter samples), run once and kept in
    :func:`search_cache`."""
    from fi_design.spec.file import load_spec

    return recommend(load_spec(paper_file), cache=search_cache)


def test_the_recommendation_is_a_buildable_stiff_joint_bound_by_physics(paper_recommendation):
    r = paper_recommendation
    assert r.feasible and r.design.status == "feasible"
    d, req = r.design, r.spec.requirements
    assert d.hunting_margin >= req.hunting_margin and d.hunting_free_from < d.crossover
    assert d.stiffness <= 4.0 / d.stroke * (1 + 1e-9)                  # k <= k_max
    # and so does the stock's thickest leaf (t + dt): the drawing's every leaf keeps it
    assert r.flexure.stiffness_range[1] <= 4.0 / d.stroke * (1 + 1e-9)
    # the stiffest of the designs that keep the margin and that the search judged
    keep = [c for c in r.candidates if c.hunting_margin is not None
            and c.hunting_margin >= req.hunting_margin and c.status != "hunts"]
    assert d.stiffness >= max(c.stiffness for c in keep) * (1 - 1e-9)
    # not the edge of a searched range: a stroke inside them, what binds is physical
    assert r.strokes[0] < d.stroke < r.strokes[-1]
    assert r.binding and any(w in r.binding[0] for w in ("k_max", "hunting margin", "guide"))
    assert not any("searched" in b or "range" in b for b in r.binding)
    # its reserves and the scatter: every draw kept
    assert r.reserves and all(c["passed"] for c in r.reserves)
    assert {c["name"].split()[0] for c in r.reserves} >= {"masses", "leaves", "computed"}
    assert r.robustness.valid == r.robustness.samples == 30
    data = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    assert data["feasible"] is True and data["flexure"]["thickness"] == d.thickness
    assert {"least_change", "pareto", "reserves", "binding", "flexure"} <= set(data)


def test_the_recommended_guide_on_its_length_bound_says_so_everywhere(paper_recommendation):
    """The paper setup's guide, 60 x 15.3 x 0.55 mm, has its length on the upper bound of
    isolator.flexure.length [10, 60] mm, and nothing said so: the sizing's tie-break (the
    largest smallest margin) grows with length, so the user's range chose it. The console, the
    JSON and the report now name the bound and its key, and that longer leaves add margin (a
    guide sized past the bound has more: tests/mechanism/test_bounds.py)."""
    from datetime import date

    from rich.console import Console

    from fi_design.console.recommend import print_recommendation
    from fi_design.report import build_context

    r = paper_recommendation
    [n] = r.flexure_bounds
    assert r.flexure.length == n.bound == 0.06 and n.key == "isolator.flexure.length"
    assert n.side == "upper" and n.given and n.adds_margin and n.margin_beyond > n.margin
    text = n.text
    assert text.startswith("the leaves' length, 60 mm, sits on the upper bound of its range "
                           "10 mm to 60 mm (isolator.flexure.length, you set); their smallest "
                           "margin, ")
    assert text.endswith(": longer leaves would add margin (widen isolator.flexure.length to "
                         "let the sizing choose)")
    data = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    assert data["flexure_bounds"] == [n.to_dict()] and data["flexure_bounds"][0]["text"] == text
    ctx = json.dumps(build_context(r, date=date(2024, 5, 1), figures=False), default=str)
    assert json.dumps(f"On a bound: {text}.") in ctx
    console = Console(record=True, width=100)
    print_recommendation(console, r)
    assert f"On a bound: {text}" in " ".join(console.export_text().split())
    # the one sentence a person acts on (the design command's recommendation box) says it too
    assert ("what binds it: k_max" in r.advice and "The leaves' length sits on the upper bound of "
            "isolator.flexure.length; past it the guide would have more margin." in r.advice)


def test_what_binds_it_agrees_with_the_front_and_k_max(paper_recommendation):
    """'Binds it' read 'a shorter stroke (0.5196 mm) allows a softer joint at most: 3652 N/m'
    beside a front with 7611 N/m at 0.52 mm. Each stroke's sentence gives that stroke's k_max
    (higher at the shorter one) and its stiffest joint that keeps the margin, as the candidates
    and the Pareto front have them: no joint of the front stiffer than that keeps the margin."""
    from fi_design import spec as _spec
    from fi_design.display import quantity

    r = paper_recommendation
    d, need = r.design, r.spec.requirements.hunting_margin
    kmax = d.stiffness * r.margins["stiffness_factor"]
    assert r.binding[0].startswith(f"k_max = Fs / stroke = {quantity(kmax, 'N/m', 4)} at")
    i = r.strokes.index(d.stroke)
    for s, side, word in ((r.strokes[i - 1], "shorter", "raises"),
                          (r.strokes[i + 1], "longer", "lowers")):
        text = next(b for b in r.binding if b.startswith(f"a {side} stroke"))
        k_s = _spec.stiffness_limit(r.spec, s)
        assert (k_s > kmax) == (side == "shorter")
        assert text.startswith(f"a {side} stroke ({quantity(s, 'm')}) {word} k_max to "
                               f"{quantity(k_s, 'N/m', 4)}")
        kept = max(c.stiffness for c in r.candidates if c.stroke == s
                   and c.status in ("feasible", "not_evaluated"))
        assert f"keeps the margin is {quantity(kept, 'N/m', 4)}" in text
        assert kept < d.stiffness
        for p in r.pareto:
            if p["stroke"] == s and p["stiffness"] > kept * (1 + 1e-9):
                assert p["hunting_margin"] < need, p        # the front's stiffer ones fail it


def test_the_recommended_guide_stands_and_keeps_its_modes_in_the_fe_model(
        paper_recommendation):
    """The FE model (pyfe3d) of the recommended guide: buckling and modes as the search saw."""
    pytest.importorskip("pyfe3d")
    from fi_design.mechanism.fe import fe_mechanics

    r = paper_recommendation
    fx = r.flexure
    assert fx.guide.orientation == "standing"
    fe = fe_mechanics(fx.guide)
    req = r.spec.requirements
    assert fe.buckling_factor >= req.buckling_factor
    low = min(m.frequency for m in fe.modes if m.direction != "x")
    assert low >= req.parasitic_separation * r.design.crossover
    assert fx.lowest_mode.frequency == pytest.approx(low, rel=0.05)


def _independent(design, distance, *, fs=4.0, fc=1.0, masses=(1.6, 0.4), t_end=12.0):
    from independent import generate

    m1, m2 = masses
    return generate(m1, m2, friction=dict(Fs=fs, Fc=fc, vs=3e-3, sigma0=1e6, sigma1=1414.0,
                                          sigma2=20.0),
                    isolator=dict(k=design.stiffness, s=design.stroke, c=design.damping,
                                  c_stop=2 * 0.2 * math.sqrt(1e6 * 1.6)),
                    controller=dict(rule=dict(fc=design.crossover, mass=2.0)),
                    moves=[dict(distance=distance, velocity=0.05, acceleration=1.0)],
                    t_end=t_end, rate=500.0, rtol=1e-7)


@pytest.mark.parametrize("case", [dict(), dict(fs=4.8, fc=0.8), dict(masses=(1.84, 0.46))])
def test_the_recommended_design_settles_in_the_independent_simulator(paper_recommendation,
                                                                     case):
    """solve_ivp on its own equations: the moves that hunt on the spec's isolator (0.4 mm,
    20 mm) settle at nominal friction, at the scatter's worst corner (Fs + 20 %, Fc - 20 %)
    and with both masses 15 % heavier (the controller tuned on the nominal 2 kg)."""
    d = paper_recommendation.design
    for distance in (0.4e-3, 20e-3):
        rec = _independent(d, distance, **case)
        e = rec.truth.x1 - rec.reference
        tail = rec.time > 8.0                  # a hunting cycle's period is 2 to 3 s
        assert np.max(np.abs(e[tail])) < 1e-5, (case, distance)   # in the band, for good


@pytest.mark.slow
def test_recommended_design_dense_scan_in_the_independent_simulator(paper_recommendation):
    d = paper_recommendation.design
    for distance in np.geomspace(3e-5, 5e-2, 12):
        for case in (dict(), dict(fs=4.8, fc=0.8), dict(fs=3.2, fc=1.2)):
            rec = _independent(d, float(distance), t_end=25.0, **case)
            e = rec.truth.x1 - rec.reference
            assert np.max(np.abs(e[rec.time > 15.0])) < 1e-5, (distance, case)


def test_the_written_spec_carries_every_digit_of_the_design(paper_recommendation, tmp_path):
    """--write-spec wrote a drawing's four digits (crossover 10.6 Hz for 10.6018 Hz, width
    27.94 mm for 27.946 mm), so the written spec's joint was 4398.99 N/m, not the 4400 N/m signed
    off. Read back, it is the design: the joint stiffness, the crossover, the stroke and the guide
    to the last digits, in the units the input wrote (mm stays mm)."""
    import re

    from fi_design import spec as _spec
    from fi_design.model import resolve
    from fi_design.recommend import recommended_spec_text
    from fi_design.spec.file import load_spec

    d = paper_recommendation.design
    path = tmp_path / "written.yaml"
    path.write_text(recommended_spec_text(paper_recommendation), encoding="utf-8")
    text = path.read_text(encoding="utf-8")
    for key in ("stroke", "length", "width", "thickness"):
        assert re.search(rf"^ +{key}: [0-9.]+ mm ", text, re.M), key
    spec = load_spec(path)
    assert resolve(spec).joint.stiffness == pytest.approx(d.stiffness, rel=1e-9, abs=0)
    assert _spec.design_crossover(spec) == pytest.approx(d.crossover, rel=1e-9, abs=0)
    g = spec.isolator.flexure
    assert (spec.isolator.stroke, g.length, g.width, g.thickness, spec.isolator.damping) == \
        pytest.approx((d.stroke, d.length, d.width, d.thickness, d.damping), rel=1e-12, abs=0)


def test_the_written_spec_passes_the_design_command(paper_recommendation, tmp_path):
    """--write-spec: the input's text with the guide drawn in its own units (mm stays mm), the
    comments of the keys replaced, a revision added; the design command on it runs the
    computation that signed the design off, and passes."""
    from fi_design.guideline.evaluate import evaluate as design
    from fi_design.recommend import recommended_spec_text
    from fi_design.spec.edit import spec_quantity
    from fi_design.spec.file import load_spec

    text = recommended_spec_text(paper_recommendation)
    assert "# m1: actuated, carries the encoder" in text      # the input's comments stay
    assert "Fs / 2" not in text                                 # the replaced value's comment
    d = paper_recommendation.design
    assert f"stroke: {spec_quantity('isolator.stroke', d.stroke, unit='mm')} " in text
    assert f"thickness: {spec_quantity('isolator.flexure.thickness', d.thickness, unit='mm')} " \
        in text
    assert "revision: B" in text
    written = tmp_path / "written.yaml"
    written.write_text(text, encoding="utf-8")
    spec = load_spec(written)
    assert spec.isolator.flexure.drawn and spec.isolator.stiffness is None
    r = design(spec)
    assert r.verdict.status != "FAIL", [x.text for x in r.verdict.reasons]
    assert not r.simulation.stage["isolated"].hunts
    assert r.model.joint.stiffness == pytest.approx(d.stiffness, rel=1e-9)


def test_the_least_change_passes(paper_recommendation, paper_spec):
    from fi_design.display import quantity
    from fi_design.guideline.evaluate import evaluate as design
    from fi_design.spec.file import with_values

    lc = paper_recommendation.least_change
    assert lc is not None and lc.feasible and 1 <= len(lc.changes) <= 2
    assert lc.tried and "crossover alone" in lc.tried[0]     # the crossover alone was tried first
    r = design(with_values(variant(paper_spec, **FEW), lc.changes))
    assert r.verdict.status != "FAIL", [x.text for x in r.verdict.reasons]
    # the guide the spec then sizes keeps k_max with the stock's thickest leaves too (it asked
    # for k_max itself, 3333 N/m at 1.2 mm, whose 0.56 mm leaves gave 3536 N/m)
    fx, kmax = r.flexure, r.stiffness.maximum
    assert r.stiffness.chosen <= 0.99 * kmax and fx.stiffness_range[1] <= kmax * (1 + 1e-9)
    # that stiffness keeps the margin, so k_max binds it (it said the hunting margin)
    assert lc.binding[0].startswith(f"k_max = Fs / stroke = {quantity(kmax, 'N/m', 4)} at")


def test_an_empty_space_says_so_with_the_nearest_design(repo_root, tmp_path):
    """Strokes of 0.05 to 0.1 mm: every guide hunts at the loop's crossover. Through the
    command: the spec is not written, it says why and exits 3; the JSON says infeasible."""
    import yaml
    from typer.testing import CliRunner

    from fi_design.cli.app import app

    raw = yaml.safe_load((repo_root / "examples" / "paper_setup.yaml").read_text())
    raw["requirements"]["robustness"] = {"samples": 20}
    raw["requirements"]["recommend"] = {"stroke": ["0.05 mm", "0.1 mm"]}
    src = tmp_path / "short.yaml"
    src.write_text(yaml.safe_dump(raw))
    none, js = tmp_path / "none.yaml", tmp_path / "none.json"
    r = CliRunner().invoke(app, ["recommend", str(src), "--write-spec", str(none), "--json",
                                 str(js), "-j", "1"])
    assert r.exit_code == 3 and not none.exists()
    assert "not written" in r.output and "No design of the searched space passes" in r.output
    data = json.loads(js.read_text())
    assert data["feasible"] is False and data["violates"]
    assert all(c["status"] != "feasible" for c in data["map"]["candidates"])
    # no design to build: the least change never says to build one (it did when it found none)
    lc = data["least_change"]
    assert lc is not None
    assert "build the recommended design" not in r.output + lc["text"], (r.output, lc)
    assert lc["feasible"] or "no edit of one or two values passes" in r.output


@pytest.mark.slow
def test_no_isolator_gets_a_buildable_one_at_the_crossover_the_model_does_not_limit(repo_root):
    from fi_design.spec.file import load_spec

    spec = variant(load_spec(repo_root / "examples" / "no_isolator.yaml"), **FEW)
    r = recommend(spec)
    assert r.spec_design["suggested"] and r.assumptions
    # no parasitic mode, no sampling: the linear model sets no limit, so the crossover stays
    assert r.design.crossover == pytest.approx(8.0)
    assert r.feasible and not r.stage_hunting.hunts
    assert r.flexure is not None and r.flexure.feasible and r.design.thickness is not None


@pytest.mark.slow
def test_recommend_command_writes_a_spec_that_passes(repo_root, tmp_path):
    import yaml
    from typer.testing import CliRunner

    from fi_design.cli.app import app

    runner = CliRunner()
    raw = yaml.safe_load((repo_root / "examples" / "paper_setup.yaml").read_text())
    raw["requirements"]["robustness"] = {"samples": 20}
    raw["requirements"]["recommend"] = {"stroke": ["0.6 mm", "1.5 mm"]}
    src = tmp_path / "narrow.yaml"
    src.write_text(yaml.safe_dump(raw))
    out, js = tmp_path / "recommended.yaml", tmp_path / "rec.json"
    r = runner.invoke(app, ["recommend", str(src), "--write-spec", str(out), "--json", str(js),
                            "-j", "1"])
    assert r.exit_code == 0, r.output
    assert "Binds it" in r.output and "Least change" in r.output
    assert json.loads(js.read_text())["feasible"] is True
    again = runner.invoke(app, [str(out), "--no-recommend", "--fail-on", "fail"])
    assert again.exit_code == 0, again.output                  # the written spec passes


# --------------------------------------------------------------------------- a notch it may add


def _rule_loop_margins(model, fc: float, notch_hz: tuple[float, float] | None) -> dict:
    """python-control's margins of each limit case with the paper's rule and a notch, both
    written out here (docs/model.md), on the library's state-space plant of the case."""
    import control

    from fi_design.loop import linear

    wc = 2 * math.pi * fc
    m = model.law.tuning_mass
    ks, wd, wt, wi = m * wc ** 2 / 3, wc / 3, 3 * wc, wc / 10
    C = ks * control.tf([1, wi], [1, 0]) * control.tf([1 / wd, 1], [1 / wt, 1])
    if notch_hz is not None:
        f0, width = notch_hz
        w = 2 * math.pi * f0
        C = C * control.tf([1, 0, w * w], [1, 2 * (width / (2 * f0)) * w, w * w])
    out = {}
    for lc in linear.limit_cases(model):
        L = C * control.ss2tf(lc.plant)
        gm, pm, *_ = control.stability_margins(L, returnall=True)
        db = 20 * np.log10(np.asarray(gm, float))
        db = db[np.isfinite(db) & (np.abs(db) < 100)]
        stable = bool(np.all(np.real(control.poles(control.feedback(L, 1))) < 0))
        out[lc.name] = (stable, float(np.min(np.abs(db))) if db.size else math.inf,
                        float(np.min(np.abs(pm))))
    return out


def test_the_search_may_add_a_notch_where_the_spec_allows_it(paper_spec):
    """requirements.recommend.filters: the paper setup's loop, limited by its 150 Hz stage tilt,
    gets a notch there and the search tunes to 0.95 x the notched loop's achievable crossover,
    about three times the plain cap. python-control's margins on the same plants, with the rule
    and the notch written out here, hold the margins plus their reserve (7 dB, 35 deg) just
    below the notched limit and miss them just above it; without the key, no notch."""
    from fi_design.model import resolve
    from fi_design.recommend.constraints import crossover_cap, reserve_values
    from fi_design.spec.file import with_values

    loop = variant(paper_spec, **{"isolator.flexure": None})
    plain_cap, _, plain_notch = crossover_cap(resolve(paper_spec), True)
    assert plain_notch is None
    allowed = variant(paper_spec, **{"requirements.recommend.filters": True})
    cap, why, notch = crossover_cap(resolve(allowed), True)
    assert notch is not None and notch.kind == "notch" and notch.frequency == pytest.approx(150.0)
    assert "stage tilt" in why and "requirements.recommend.filters" in why
    assert cap > 2.5 * plain_cap
    ach = cap / paper_spec.requirements.reserve.crossover
    model = resolve(with_values(loop, reserve_values(loop)))
    req = model.requirements

    def meets(fc):
        return all(s and gm >= req.gain_margin and pm >= req.phase_margin
                   for s, gm, pm in _rule_loop_margins(model, fc, (150.0, notch.width)).values())

    assert meets(0.99 * ach) and not meets(1.01 * ach)
    assert not all(s and gm >= req.gain_margin for s, gm, _ in
                   _rule_loop_margins(model, 0.99 * ach, None).values())  # the notch is needed


@pytest.mark.slow
def test_a_recommendation_with_the_notch_writes_it_and_passes(paper_spec, tmp_path):
    """The whole search with requirements.recommend.filters (about 35 s of CPU): the written
    spec carries the notch in controller.filters and the crossover the search tuned to, and
    the design command passes it."""
    from fi_design.guideline.evaluate import evaluate
    from fi_design.recommend.write import recommended_spec_text

    allowed = variant(paper_spec, **{"requirements.recommend.filters": True, **FEW})
    r = recommend(allowed)
    assert r.feasible and r.notch is not None
    assert r.design.crossover > 2.5 * 10.6
    path = tmp_path / "notched.yaml"
    path.write_text(recommended_spec_text(r), encoding="utf-8")
    from fi_design.spec.file import load_spec

    written = load_spec(path)
    assert [f.type for f in written.controller.filters] == ["notch"]
    assert written.controller.filters[0].frequency == pytest.approx(150.0)
    assert evaluate(written).verdict.status != "FAIL"


# --------------------------------------------------------------------------- read back


def test_the_search_read_back_is_the_search_computed(paper_recommendation, paper_file,
                                                     search_cache, monkeypatch):
    """The paper setup's search, computed once and kept, read back by the next search of its
    spec (the search itself would fail): its JSON and its report are those of the search
    computed, but for saying where the result came from; through the command too."""
    import importlib
    from datetime import date

    from typer.testing import CliRunner

    from fi_design.cli.app import app
    from fi_design.report import build_context
    from fi_design.spec.file import load_spec

    search = importlib.import_module("fi_design.recommend.search")

    def searched(*args, **kwargs):
        raise AssertionError("the search ran again")

    monkeypatch.setattr(search, "_searched", searched)
    computed = paper_recommendation
    again = recommend(load_spec(paper_file), cache=search_cache)
    assert computed.from_cache is None and again.from_cache is not None
    assert again.from_cache.startswith(str(search_cache))
    data, expected = again.to_dict(), computed.to_dict()
    assert data.pop("from_cache") == again.from_cache and expected.pop("from_cache") is None
    assert data == expected                     # wall time and evaluations: the computing run's
    day = date(2024, 5, 1)
    report, report_computed = (json.dumps(build_context(r, date=day, figures=False),
                                          sort_keys=True, default=str)
                               for r in (again, computed))
    note = " (read from the result cache: the same search of the same spec by the same code, " \
           "run earlier)."
    assert note in report and note not in report_computed
    assert report.replace(note, ".") == report_computed
    # the command reads the same entry (FI_DESIGN_CACHE_DIR/recommend)
    monkeypatch.setenv("FI_DESIGN_CACHE_DIR", str(search_cache.parent))
    out = paper_file.parent / "read_back.json"
    r = CliRunner().invoke(app, ["recommend", str(paper_file), "--json", str(out), "-j", "1",
                                 "--force"])
    assert r.exit_code == 0, r.output
    assert "The design search: from the cache (" in " ".join(r.stdout.split())
    assert f"({search_cache})" in "".join(r.stdout.split())       # a long path folds
    data = json.loads(out.read_text())
    assert data.pop("from_cache") == again.from_cache
    assert data == json.loads(json.dumps(expected))


def test_the_search_holds_a_candidates_modes_at_the_loops_crossover(paper_spec):
    """loop_meets held the modes at 3 x the controller's crossover (24 Hz at 8 Hz) while step 2
    and step 3 hold them at 3 x the loop's (12.04 Hz here, the cart stuck and the joint free:
    36.1 Hz): a drawn guide's lateral mode at 30.02 Hz (no coupling to x, so the margins do
    not see it) passed the search's screen and failed the design's checks."""
    from fi_design.loop import linear
    from fi_design.model import resolve
    from fi_design.recommend.constraints import loop_meets

    drawn = resolve(variant(paper_spec, **{
        "isolator.flexure.length": "50.7 mm", "isolator.flexure.width": "9 mm",
        "isolator.flexure.thickness": "0.45 mm", "isolator.stiffness": None,
        "isolator.damping": None}))
    top = linear.analyse(drawn).loop_crossover
    lateral = next(m for m in drawn.modes if m.name.startswith("stage y"))
    assert 3 * drawn.crossover < lateral.frequency < 3 * top  # 24 < 30.02 < 36.1 Hz
    ok, why = loop_meets(drawn)
    assert not ok and "stage y (lateral)" in why and "loop's crossover" in why


def test_the_report_s_table_quotes_the_design_as_the_advice_does(paper_recommendation):
    """The advice above the table read '60 x 15.3 x 0.55 mm leaves', the table beneath it
    '60 mm x 15.31 mm x 0.55 mm' (and the console's 15.3); the spec's column of the drive
    stiffness, 'net of gravity', held the joint's given 6667 N/m, not its guide's net."""
    import re

    from fi_design.report.recommend import STIFFNESS_ROW, _design_rows

    rows = {r[0]: r for r in _design_rows(paper_recommendation)}
    leaves = rows["Leaves L \u00d7 b \u00d7 t"][2].replace("\u00a0", " ")
    numbers = re.findall(r"[0-9.]+", leaves)
    assert " x ".join(numbers) + " mm leaves" in paper_recommendation.advice
    assert STIFFNESS_ROW in rows and "net of gravity" not in STIFFNESS_ROW.split("(")[0]


def test_the_console_and_the_report_show_k_over_the_stock_tolerance(paper_recommendation):
    """The engineer orders stock of +-0.01 mm: the design's table shows the drive stiffness
    over that tolerance, its thick end within k_max (it was 4148 to 4662 N/m against k_max
    4444 N/m, and shown nowhere)."""
    from datetime import date

    from rich.console import Console

    from fi_design.console.recommend import print_recommendation
    from fi_design.display import number
    from fi_design.report import build_context

    r = paper_recommendation
    lo, hi = r.flexure.stiffness_range
    kmax = r.design.stiffness * r.margins["stiffness_factor"]
    assert lo < r.design.stiffness < hi <= kmax * (1 + 1e-9)
    console = Console(record=True, width=100)
    print_recommendation(console, r)
    text = " ".join(console.export_text().split())
    assert f"k over the leaves' tolerance (\u00b10.01 mm) {number(lo)} to {number(hi)} N/m" in text
    ctx = json.dumps(build_context(r, date=date(2024, 5, 1), figures=False), default=str,
                     ensure_ascii=False)
    assert "k over the leaves' tolerance (\u00b10.01\u00a0mm)" in ctx and f"{number(lo)} to " in ctx


def test_the_report_says_the_advice_once_and_the_strokes_in_one_unit(paper_recommendation):
    """The recommend report printed its advice as the summary and again as the first paragraph
    of 'Recommended design', and its method read 'Strokes from 100 µm to 2.916 mm'."""
    from datetime import date

    from fi_design.display import quantities
    from fi_design.report import build_context

    r = paper_recommendation
    ctx = json.dumps(build_context(r, date=date(2024, 5, 1), figures=False), default=str,
                     ensure_ascii=False)
    assert ctx.count(json.dumps(r.advice, ensure_ascii=False)[1:-1]) == 1
    shortest, longest = quantities([r.strokes[0], r.strokes[-1]], "m", sep="\u00a0")
    assert f"Strokes from {shortest} to {longest} " in ctx
    assert shortest.split("\u00a0")[1] == longest.split("\u00a0")[1]


@pytest.mark.slow
def test_the_least_change_keeps_within_the_bounds_the_user_set(repo_root):
    """requirements.recommend.stroke of 2 to 3 mm (the travel the mechanism allows): the
    least change of the spec's 0.3 mm stroke never proposes a stroke outside it (it proposed
    1.2 mm at 3141 N/m, below the bound; about 11 s)."""
    from fi_design.spec.file import load_spec

    spec = variant(load_spec(repo_root / "examples" / "paper_setup.yaml"),
                   **{"requirements.robustness.samples": 20,
                      "requirements.recommend.stroke": ["2 mm", "3 mm"]})
    r = recommend(spec)
    assert r.feasible and 2e-3 * (1 - 1e-9) <= r.design.stroke <= 3e-3 * (1 + 1e-9)
    lc = r.least_change
    assert lc is not None
    assert "isolator.stroke" not in lc.changes, lc
    assert not any("1.2 mm" in t or "0.6 mm" in t for t in lc.tried), lc.tried


@pytest.mark.slow
def test_the_nearest_design_of_a_vertical_axis_holds_its_own_guide(repo_root):
    """The paper setup on a vertical drive axis: no design passes (the joint sags past its
    stroke under the cart). The nearest design's leaves and its guide were two sizings (50.72 x
    30 x 0.15 mm against 50.16 x 29.01 x 0.15 mm: the guide sized again for the stiffness the
    first had reached), and its clearance at rest read +0.38 mm beside "rests on its end
    stop"."""
    from fi_design.spec.file import load_spec

    spec = variant(load_spec(repo_root / "examples" / "paper_setup.yaml"),
                   **{"isolator.flexure.orientation": "vertical_axis",
                      "requirements.robustness.samples": 20})
    r = recommend(spec)
    assert not r.feasible
    fx, d = r.flexure, r.design
    assert fx is not None and (fx.length, fx.width, fx.thickness) == \
        (d.length, d.width, d.thickness)
    sag = fx.mechanics.gravity.sag
    assert sag > d.stroke and any("sags" in v for v in r.violates)
    # the stiffest that kept the margin (0.93 mm of sag on 0.9 mm), not the softest (12.6 mm
    # on 2.92 mm, when the nearest was ranked by hunting margin alone)
    assert sag < 1.1 * d.stroke, (sag, d.stroke)
    assert d.end_stop_clearance is not None and d.end_stop_clearance < 0.0


@pytest.mark.parametrize("paths", [{}, {"controller.sample_rate": "1 kHz"}])
def test_the_delay_reserve_lengthens_the_loop_delay_of_a_time_delay_effect(paper_spec,
                                                                           monkeypatch, paths):
    """The reserve's corner 'delay +50 %' lengthened controller.delay (and half the sample
    period) alone: a loop whose delay is a time_delay effect had no such corner, or one with
    the effect's delay not lengthened. Now the corner's loop delay, as the linear analysis
    models it, is the nominal one times 1 + reserve.delay."""
    from fi_design.loop import linear
    from fi_design.model import resolve
    from fi_design.recommend import constraints

    model = resolve(variant(paper_spec, isolator=None,
                            effects=[{"type": "time_delay", "delay": "2 ms"}], **paths))
    analysed = {}
    real = linear.analyse
    monkeypatch.setattr(linear, "analyse", lambda m: analysed.setdefault(id(m), (m, real(m)))[1])
    monkeypatch.setattr(constraints, "_settles", lambda m: True)  # the simulation: not here
    corners = constraints.reserve_corners(model)
    r = model.requirements.reserve.delay
    assert [c["name"].split()[0] for c in corners].count("delay") == 1
    late = [m for m, _ in analysed.values() if m.changed == ("controller.delay",)]
    assert len(late) == 1
    assert linear.delay_time(late[0]) == pytest.approx((1 + r) * linear.delay_time(model),
                                                       rel=1e-12)
