"""The design search: a recommendation the tool itself signs off, checked by what it did not make.

The recommended design of the paper setup is checked by moves simulated with the
independent solve_ivp simulator of ``tests/independent.py`` (none hunts), by the product's
kernel over a dense move scan at the four corners of the friction scatter, and by the design
command on it (it passes). A space with no feasible point says so, with the nearest design.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fi_design.recommend import recommend
from fi_design.stage import stage_hunts

from conftest import remember, variant


@pytest.fixture(scope="module")
def paper_search(paper_spec):
    """The design search on the paper setup and what it said as it went, run once."""
    said: list[str] = []
    found = recommend(paper_spec, progress=said.append)
    remember("recommend", paper_spec, found)
    return found, said


@pytest.fixture(scope="module")
def paper_recommendation(paper_search):
    return paper_search[0]


def test_paper_recommendation_passes_where_the_spec_fails(paper_recommendation, paper_spec):
    r = paper_recommendation
    assert r.feasible and r.design.status == "feasible"
    d = r.design
    # the spec's own isolator hunts up to 11.28 Hz; the recommendation has margin
    assert d.hunting_free_from < d.crossover and r.margins["crossover_factor"] > 1.2
    assert d.stiffness <= paper_spec.friction.static / d.stroke          # k <= k_max
    assert r.margins["end_stop_clearance"] > 0
    assert d.unsettled_probability is not None and d.unsettled_probability <= 0.05
    assert r.stage_hunting is not None and not r.stage_hunting.hunts
    # the crossover is the highest the loop margins allow: step 2's achievable one
    assert d.crossover == pytest.approx(11.82, abs=0.01)
    assert any("gain margin of case 4" in b for b in r.binding)
    # the spec's own design is a point of the map that hunts at some crossover below
    statuses = {c.status for c in r.candidates}
    assert {"feasible", "hunts", "k_max"} <= statuses
    data = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    assert data["feasible"] is True and set(data["isolator"]) == {"stroke", "stiffness",
                                                                  "damping"}
    assert {"crossover", "binding", "stage_hunting", "robustness", "margins"} <= set(data)


def test_the_recommendation_has_the_most_margin_the_search_found(paper_search):
    """The map's best point that passes is refined along the stiffness between its map
    neighbours; the answer has the largest crossover factor of every point judged (factors
    equal to the fold's 0.1 % resolution are ties), and of ties the softest joint (on the
    paper setup the corner of the map: the longest stroke and the lowest stiffness, as the
    paper has it)."""
    r, said = paper_search
    d = r.design
    judged = [c for c in r.candidates if c.crossover_factor is not None
              and c.status in ("feasible", "not_evaluated")]
    best = max(round(c.crossover_factor, 3) for c in judged)
    assert round(d.crossover_factor, 3) >= best
    ties = [c.stiffness for c in judged if round(c.crossover_factor, 3) == best]
    assert d.stiffness <= min(ties)
    ks = sorted(r.stiffnesses)  # the map's stiffness axis
    i = int(np.argmin([abs(math.log(k / d.stiffness)) for k in ks]))
    lo, hi = ks[max(i - 1, 0)], ks[min(i + 1, len(ks) - 1)]
    refined = [t for t in said if t.startswith("refining the stiffness")]
    assert refined and refined[0] == (f"refining the stiffness between {lo:.4g} and {hi:.4g} "
                                      "N/m ...")


def test_recommended_design_settles_under_the_scatter_corners_for_a_dense_scan(
        paper_recommendation, paper_spec):
    """The product's kernel, 60 moves of 0.01 to 100 mm, at Fs and Fc scattered by +-20 %."""
    d = paper_recommendation.design
    dense = np.geomspace(1e-5, 0.1, 60)
    for fs, fc in ((0.8, 0.8), (0.8, 1.2), (1.2, 0.8), (1.2, 1.2)):
        spec = variant(paper_spec, **{
            "isolator.stroke": d.stroke, "isolator.stiffness": d.stiffness,
            "isolator.damping": d.damping, "controller.crossover": d.crossover,
            "friction.static": 4.0 * fs, "friction.coulomb": 1.0 * fc})
        moves, _ = stage_hunts(spec, True, family=dense)
        assert not any(m.hunts for m in moves), (fs, fc)
        assert all(m.outcome == "settles" for m in moves), (fs, fc)


def _independent(design, distance, t_end=25.0):
    from independent import generate

    return generate(1.6, 0.4, friction=dict(Fs=4.0, Fc=1.0, vs=3e-3, sigma0=1e6, sigma1=1414.0,
                                            sigma2=20.0),
                    isolator=dict(k=design.stiffness, s=design.stroke, c=design.damping),
                    controller=dict(rule=dict(fc=design.crossover)),
                    moves=[dict(distance=distance, velocity=0.05, acceleration=1.0)],
                    t_end=t_end, rate=500.0)


def test_recommended_design_settles_in_the_independent_simulator(paper_recommendation):
    """solve_ivp on its own equations: the moves that hunt on the spec's isolator settle."""
    d = paper_recommendation.design
    for distance in (0.4e-3, 20e-3):
        rec = _independent(d, distance)
        e = rec.truth.x1 - rec.reference
        tail = rec.time > 15.0
        assert np.max(np.abs(e[tail])) < 1e-5, distance   # in the 10 um band, for good


@pytest.mark.slow
def test_recommended_design_dense_scan_in_the_independent_simulator(paper_recommendation):
    d = paper_recommendation.design
    for distance in np.geomspace(3e-5, 5e-2, 12):
        rec = _independent(d, float(distance))
        e = rec.truth.x1 - rec.reference
        assert np.max(np.abs(e[rec.time > 15.0])) < 1e-5, distance


def test_an_empty_space_says_so_with_the_nearest_design(paper_spec):
    """Strokes of 0.05 to 0.1 mm: every move family hunts at every stiffness."""
    spec = variant(paper_spec, **{"requirements.recommend": {"stroke": ["0.05 mm", "0.1 mm"]},
                                  "requirements.robustness": {"samples": 20}})
    r = recommend(spec, grid=(2, 3))
    assert not r.feasible and r.design.status != "feasible"
    assert r.violates and "What would open the space" in r.advice
    assert "a longer stroke" in r.advice and "friction gap" in r.advice
    assert all(c.status != "feasible" for c in r.candidates)
    assert r.to_dict()["feasible"] is False


def test_no_isolator_gets_one_and_keeps_a_crossover_the_model_does_not_limit(repo_root):
    from fi_design.specfile import load_spec

    spec = variant(load_spec(repo_root / "examples" / "no_isolator.yaml"),
                   **{"requirements.robustness": {"samples": 20}})
    r = recommend(spec, grid=(3, 3))
    assert r.spec_design["suggested"]
    # no parasitic mode, no sampling: the linear model sets no limit, so the crossover stays
    assert r.design.crossover == pytest.approx(8.0)
    assert r.feasible and not r.stage_hunting.hunts


def test_the_written_spec_keeps_comments_and_the_design_command_passes_it(
        paper_recommendation, paper_spec, tmp_path):
    """--write-spec: the input's text with the recommended values (comments kept); the design
    command on it runs the computation that signed the design off, and passes."""
    from fi_design.guideline import design
    from fi_design.recommend import recommended_spec_text
    from fi_design.specfile import load_spec

    text = recommended_spec_text(paper_recommendation)
    assert "# m1: actuated, carries the encoder" in text      # the input's comments stay
    assert "written by fi-design recommend" in text
    written = tmp_path / "written.yaml"
    written.write_text(text, encoding="utf-8")
    spec = load_spec(written)
    d = paper_recommendation.design
    assert spec.isolator.stroke == d.stroke and spec.isolator.stiffness == d.stiffness
    assert spec.controller.crossover == d.crossover
    r = design(spec)
    assert r.verdict.status != "FAIL", [x.text for x in r.verdict.reasons]
    assert not r.simulation.stage["isolated"].hunts


def test_recommend_command_writes_a_spec_that_passes_or_says_why_not(repo_root, tmp_path):
    import yaml
    from typer.testing import CliRunner

    from fi_design.cli import app

    runner = CliRunner()
    raw = yaml.safe_load((repo_root / "examples" / "no_isolator.yaml").read_text())
    raw.setdefault("requirements", {})["robustness"] = {"samples": 20}
    raw["requirements"]["recommend"] = {"stroke": ["0.3 mm", "1 mm"]}
    src = tmp_path / "bare.yaml"
    src.write_text(yaml.safe_dump(raw))
    out, js = tmp_path / "with_isolator.yaml", tmp_path / "rec.json"
    r = runner.invoke(app, ["recommend", str(src), "--write-spec", str(out), "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert "Binds it" in r.output and "Design space at" in r.output
    assert json.loads(js.read_text())["feasible"] is True
    again = runner.invoke(app, [str(out), "--no-recommend", "--fail-on", "fail"])
    assert again.exit_code == 0, again.output                  # the written spec passes
    # nothing passes (the paper stage with strokes of 0.05 to 0.1 mm): the spec is not
    # written, the command says why and exits 3
    raw = yaml.safe_load((repo_root / "examples" / "paper_setup.yaml").read_text())
    raw["requirements"]["robustness"] = {"samples": 20}
    raw["requirements"]["recommend"] = {"stroke": ["0.05 mm", "0.1 mm"]}
    src.write_text(yaml.safe_dump(raw))
    none = tmp_path / "none.yaml"
    r = runner.invoke(app, ["recommend", str(src), "--write-spec", str(none)])
    assert r.exit_code == 3 and not none.exists()
    assert "not written" in r.output and "What would open the space" in r.output
