"""Specs the tool writes: the input's own YAML edited in place, and every one loads in the tool."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
import yaml

from fi_design import effects
from fi_design.reconciliation import fixed_spec_text
from fi_design.spec.edit import REMOVE, edited_spec_text, spec_quantity
from fi_design.spec.file import load_spec

from conftest import EXAMPLES

#: A value inside the bounds of each effect parameter (SI; relative bounds are factors).
VALUES = {
    "viscous_friction": {"viscous": 35.0},
    "stribeck_velocity": {"stribeck_velocity": 4.2e-3},
    "position_dependent_friction": {"amplitude": 0.25, "wavelength": 5.000022803450486e-3,
                                    "phase": 0.8000697798443959},
    "force_ripple": {"amplitude": 0.4, "pitch": 5.2e-3, "phase": 0.6},
    "cable_force": {"stiffness": 60.0032533887628, "preload": -0.40003027476442554},
    "time_delay": {"delay": 1.2e-3},
    "quantization": {"resolution": 1e-05},
    "force_saturation": {"limit": 2.5},
    "mass_error": {"stage_mass": 1.7, "cart_mass": 0.35},
    "joint_damping": {"damping": 8.0},
    "force_offset": {"offset": -0.3},
    "friction_asymmetry": {"coulomb_negative": 1.2, "viscous_negative": 25.0},
}


def _reconciled(spec, entries, source="trace.csv"):
    """What fixed_spec_text reads of a ReconcileResult."""
    return SimpleNamespace(spec=spec, entries=tuple(entries),
                           measurement=SimpleNamespace(source=source),
                           conclusion="The measurement shows it. With it the misfit drops.")


def test_every_effect_is_covered():
    assert set(VALUES) == set(effects.EFFECT_NAMES)


@pytest.mark.parametrize("name", sorted(VALUES) + ["none"])
def test_reconcile_writes_a_spec_that_loads(paper_spec, tmp_path, name):
    """`reconcile --write-spec` wrote `resolution: '1e-05'` (refused) and failed on `none`."""
    entries = [] if name == "none" else [{"type": name, **VALUES[name]}]
    text = fixed_spec_text(_reconciled(paper_spec, entries))
    path = tmp_path / "fixed.yaml"
    path.write_text(text, encoding="utf-8")
    for spec in (load_spec(path), load_spec(yaml.safe_load(text))):  # any YAML reader
        if name == "none":
            assert spec.effects == ()
            continue
        (entry,) = spec.effects
        assert entry.type == name
        for key, value in VALUES[name].items():
            assert getattr(entry, key) == value, key  # every digit written
    assert "# fi_design" not in text and "Fs" in text  # the input's comments are kept


def test_reconcile_replaces_an_entry_of_the_same_type_and_keeps_the_others(paper_spec, tmp_path):
    path = tmp_path / "stage.yaml"
    path.write_text((EXAMPLES / "paper_setup.yaml").read_text()
                    + "effects:\n  - {type: time_delay, delay: 1 ms}   # measured\n"
                      "  - {type: force_offset, offset: 0.1 N}\n")
    spec = load_spec(path)
    text = fixed_spec_text(_reconciled(spec, [{"type": "force_offset", "offset": -0.3}]))
    fixed = load_spec(yaml.safe_load(text))
    assert [(e.type, getattr(e, "delay", None) or getattr(e, "offset", None))
            for e in fixed.effects] == [("time_delay", 1e-3), ("force_offset", -0.3)]


@pytest.mark.parametrize("name", ["paper_setup", "no_isolator", "small_gap", "industrial_axis",
                                  "measured_stage", "emps_axis"])
def test_an_unchanged_spec_is_written_byte_for_byte(name):
    path = EXAMPLES / f"{name}.yaml"
    assert edited_spec_text(load_spec(path)) == path.read_text(encoding="utf-8")


def test_values_replaced_added_and_removed_with_comments_kept(paper_spec):
    text = edited_spec_text(paper_spec, {
        "isolator.stroke": "0.5 mm", "isolator.damping": REMOVE,
        "controller.sample_rate": "10 kHz", "measurement.position_noise": "0.3 um"},
        comments={"isolator.stroke": "a longer stroke", "controller.sample_rate": "the drive"},
        header="written by a test")
    lines = text.splitlines()
    assert lines[0] == "# written by a test"
    stroke = next(ln for ln in lines if ln.strip().startswith("stroke:"))
    assert stroke.split("#")[0].strip() == "stroke: 0.5 mm"
    assert stroke.split("#")[1].strip() == "a longer stroke; one-sided, before the limiter engages"
    assert not any(ln.strip().startswith("damping: 4.62") for ln in lines)
    assert "  sample_rate: 10 kHz  " in text.replace("# the drive", "") or \
        any(ln.startswith("  sample_rate: 10 kHz") for ln in lines)
    spec = load_spec(yaml.safe_load(text))
    assert spec.isolator.stroke == 5e-4 and spec.isolator.damping is None
    assert spec.controller.sample_rate == 1e4
    assert spec.measurement.position_noise == pytest.approx(3e-7)
    # every untouched line of the input is still there, in order
    original = (EXAMPLES / "paper_setup.yaml").read_text().splitlines()
    kept = [ln for ln in original if "stroke:" not in ln and "damping: 4.62" not in ln]
    it = iter(lines)
    assert all(any(ln == other for other in it) for ln in kept)


def test_a_refused_value_names_the_path(paper_spec):
    from fi_design.errors import SpecError

    with pytest.raises(SpecError, match="stage.mass") as err:
        edited_spec_text(paper_spec, {"stage.mass": "-1 kg"})
    assert "does not load" in str(err.value)


def test_spec_quantity_keeps_every_digit():
    text = spec_quantity("controller.gains.ki", 33073.41234567891)
    assert text == "33073.41234567891 N/(m*s)"
    spec_unit = spec_quantity("isolator.stroke", 1e-05)
    assert spec_unit == "1e-05 m"



@pytest.mark.parametrize("path, value, unit, text", [
    ("isolator.flexure.width", 0.02794601559143691, "mm", "27.94601559143691 mm"),
    ("isolator.stroke", 0.0009, "mm", "0.9 mm"),                 # not 0.90000000000000002
    ("isolator.flexure.length", 0.06, "mm", "60 mm"),            # not 6e+01
    ("isolator.stiffness", 4399.999999966574, "N/mm", "4.399999999966575 N/mm"),
    ("controller.crossover", 10.601806058103774, "Hz", "10.601806058103774 Hz"),
    ("isolator.stroke", 1e-7, "um", "0.1 um"),
])
def test_spec_quantity_in_the_users_unit_reads_back_as_the_value(path, value, unit, text):
    """In the unit the user wrote (mm stays mm), the shortest text the spec reads back as the
    value: the same float, or within the ulp the unit's conversion leaves."""
    from fi_design.spec.file import path_unit
    from fi_design.spec.units import to_si

    assert spec_quantity(path, value, unit=unit) == text
    assert to_si(text, path_unit(path)) == pytest.approx(value, rel=4e-16, abs=0)

def test_a_recommended_isolator_and_crossover_written_into_a_spec_without_one():
    """What `recommend --write-spec` needs: a section added, values replaced, comments kept."""
    spec = load_spec(EXAMPLES / "no_isolator.yaml")
    values = {"isolator.stroke": spec_quantity("isolator.stroke", 3e-4),
              "isolator.stiffness": spec_quantity("isolator.stiffness", 6666.67),
              "isolator.damping": spec_quantity("isolator.damping", 4.62),
              "controller.crossover": spec_quantity("controller.crossover", 9.5)}
    text = edited_spec_text(spec, values, comments={"isolator.stroke": "recommended"},
                            header="recommended by a test")
    written = load_spec(yaml.safe_load(text))
    assert written.isolator.stroke == 3e-4 and written.isolator.stiffness == 6666.67
    assert written.isolator.damping == 4.62 and written.controller.crossover == 9.5
    original = (EXAMPLES / "no_isolator.yaml").read_text()
    for line in original.splitlines():
        if "crossover:" not in line:
            assert line in text, line  # every other line of the input, comments included
    assert "\n\nisolator:\n  stroke: 0.0003 m" in text  # a new section after a blank line


def test_a_comment_after_an_alias_stays_on_its_line(tmp_path):
    # ruamel.yaml writes the comment after 'cart: *s' on a line of its own under it
    text = (EXAMPLES / "paper_setup.yaml").read_text(encoding="utf-8")
    text = text.replace("stage: {mass: 1.6 kg}", "stage: &s {mass: 1.6 kg}").replace(
        "cart: {mass: 0.4 kg}             # m2", "cart: *s   # m2 = m1")
    spec = tmp_path / "alias.yaml"
    spec.write_text(text, encoding="utf-8")
    out = edited_spec_text(load_spec(spec), {"controller.crossover": "9 Hz"})
    assert "\ncart: *s   # m2 = m1: the bearing cart, friction acts here\n\n" in out, out[:600]
