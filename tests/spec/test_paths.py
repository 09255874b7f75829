"""Dotted-path access to a spec: with_values, path_unit, value_at (fi_design.spec.file)."""

from __future__ import annotations

import numpy as np
import pytest

from fi_design.errors import SpecError
from fi_design.spec.file import path_unit, value_at, with_values


def test_replaces_and_revalidates(paper_spec):
    new = with_values(paper_spec, {"isolator.stroke": "0.5 mm", "controller.crossover": 5.0})
    assert new.isolator.stroke == pytest.approx(5e-4)
    assert new.controller.crossover == 5.0
    assert paper_spec.isolator.stroke == pytest.approx(3e-4)  # the original is untouched
    assert new.friction is paper_spec.friction  # untouched sections are shared
    assert new.requirements.phase_margin == paper_spec.requirements.phase_margin


def test_sections_with_angles_and_decibels_revalidate(paper_spec):
    # bare numbers are refused for deg and dB in YAML; the stored values must still round-trip
    new = with_values(paper_spec, {"requirements.friction_gap": 1.5})
    assert new.requirements.gain_margin == paper_spec.requirements.gain_margin
    assert with_values(paper_spec, {"requirements.phase_margin": 45.0}) \
        .requirements.phase_margin == 45.0


def test_lists_numpy_scalars_and_effects(paper_spec):
    new = with_values(paper_spec, {"motion.moves[0].distance": "5 mm",
                                   "isolator.parasitic_modes[0].frequency": np.float64(300),
                                   "simulation.max_steps": np.int64(5000)})
    assert new.motion.moves[0].distance == pytest.approx(5e-3)
    assert new.isolator.parasitic_modes[0].frequency == 300.0
    assert new.simulation.max_steps == 5000
    eff = with_values(paper_spec, {"effects": [{"type": "time_delay", "delay": "1 ms"}]})
    eff = with_values(eff, {"effects[type=time_delay].delay": 2e-3})
    assert eff.effects[0].delay == pytest.approx(2e-3)
    assert value_at(eff, "effects[0].delay") == pytest.approx(2e-3)


@pytest.mark.parametrize("values,path,words", [
    ({"friction.statik": 1.0}, "friction.statik", "did you mean 'static'"),
    ({"frction.static": 1.0}, "frction", "did you mean 'friction'"),
    ({"friction.static": 0.5}, "friction", "at least the Coulomb friction"),
    ({"stage.mass": "3 mm"}, "stage.mass", "not a mass"),
    ({"isolator.stiffness": -1.0}, "isolator.stiffness", "greater than 0"),
    ({"motion.moves[3].distance": 1.0}, "motion.moves[3]", "out of range"),
    ({"effects[type=time_delay].delay": 1e-3}, "effects[type=time_delay]", "no entry"),
    ({"friction.static.x": 1.0}, "friction.static.x", "holds a value"),
    ({"friction..static": 1.0}, None, "not a valid path element"),
])
def test_errors_name_the_path(paper_spec, values, path, words):
    with pytest.raises(SpecError) as info:
        with_values(paper_spec, values)
    if path is not None:
        assert info.value.path == path
    assert words in str(info.value)


def test_path_into_a_missing_section(paper_spec):
    bare = with_values(paper_spec, {"isolator": None})
    with pytest.raises(SpecError, match="not set in this spec") as info:
        with_values(bare, {"isolator.stroke": 1e-3})
    assert info.value.path == "isolator"


def test_path_unit():
    assert path_unit("friction.static") == "N"
    assert path_unit("isolator.stroke") == "m"
    assert path_unit("isolator.stiffness") == "N/m"
    assert path_unit("controller.crossover") == "Hz"
    assert path_unit("requirements.phase_margin") == "deg"
    assert path_unit("effects[type=position_dependent_friction].phase") == "rad"
    assert path_unit("controller.derivative_ratio") == "1"
    assert path_unit("friction.model") == ""
    with pytest.raises(SpecError, match="section"):
        path_unit("friction")
    with pytest.raises(SpecError, match="did you mean"):
        path_unit("isolator.strok")


def test_value_at(paper_spec):
    assert value_at(paper_spec, "isolator.stroke") == pytest.approx(3e-4)
    assert value_at(paper_spec, "controller.sample_rate") is None
    assert value_at(paper_spec, "motion.moves[0].velocity") == pytest.approx(0.05)


def test_type_selectors_name_any_list_of_typed_entries(paper_spec):
    # [type=NAME] worked for effects only: 'controller.filters[type=notch].frequency' (as
    # docs/spec.md writes the filter keys) said "no list entry of type 'notch' here"
    notch = with_values(paper_spec, {"controller.filters": [
        {"type": "notch", "frequency": "150 Hz", "width": "20 Hz"}]})
    path = "controller.filters[type=notch].frequency"
    assert path_unit(path) == "Hz" and path_unit(path, notch) == "Hz"
    assert value_at(with_values(notch, {path: "140 Hz"}), path) == 140.0
    assert path_unit("controller.filters[0].frequency", notch) == "Hz"
    with pytest.raises(SpecError, match="did you mean 'notch'.*notch, low_pass"):
        path_unit("controller.filters[type=notsh].frequency")
    with pytest.raises(SpecError, match="not a list of typed entries.*'parasitic_modes\\[0\\]'"):
        path_unit("isolator.parasitic_modes[type=x].frequency")


def test_an_index_beyond_the_specs_list_says_so(paper_spec):
    # effects[0] of a spec without effects said "cannot resolve this list entry without a spec"
    with pytest.raises(SpecError, match="the spec has no entry 0: its 'effects' list is empty"):
        path_unit("effects[0].delay", paper_spec)
    with pytest.raises(SpecError, match="pass the spec, or name the entry by its type"):
        path_unit("effects[0].delay")
