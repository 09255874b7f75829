"""The unit boundary: strings with units in, SI floats out, wrong dimensions refused by path."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st

from fi_design.errors import ArgumentError, UnitError
from fi_design.spec.units import registry, to_si


@pytest.mark.parametrize("value,unit,expected", [
    ("0.3 mm", "m", 3e-4), ("2 N/mm", "N/m", 2000.0), ("5 Hz", "Hz", 5.0),
    ("10 N*s/m", "N*s/m", 10.0), ("200 GPa", "Pa", 2e11), ("1 um", "m", 1e-6),
    ("1 m/s**2", "m/s**2", 1.0), ("7.8 g/cm**3", "kg/m**3", 7800.0), ("1.6 kg", "kg", 1.6),
    ("10 ms", "s", 0.01), ("0.5 rad", "deg", math.degrees(0.5)), ("30 deg", "deg", 30.0),
    ("6 dB", "dB", 6.0), ("-3.5 dB", "dB", -3.5), ("3", "1", 3.0), ("50 %", "1", 0.5),
    (0.3, "m", 0.3), (8, "Hz", 8.0),
])
def test_conversions(value, unit, expected):
    assert to_si(value, unit) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("text,hz", [("62.83185307179586 rad/s", 10.0), ("360 deg/s", 1.0),
                                     ("60 rpm", 1.0), ("1 kHz", 1000.0), ("2 1/s", 2.0)])
def test_angular_frequencies_become_hertz(text, hz):
    """pint treats the radian as dimensionless; without the guard rad/s would read as Hz."""
    assert to_si(text, "Hz") == pytest.approx(hz, rel=1e-12)


def test_the_guard_is_needed():
    """The hazard the guard removes: pint's own conversion of rad/s to Hz drops the 2 pi."""
    naive = registry().Quantity("62.83185307179586 rad/s").to("Hz").magnitude
    assert naive == pytest.approx(62.83185307179586)
    assert to_si("62.83185307179586 rad/s", "Hz") == pytest.approx(naive / (2 * math.pi))


@pytest.mark.parametrize("value,unit,words", [
    ("3 mm", "N", ["not a force", "mm"]), ("2 kg", "Hz", ["not a frequency"]),
    ("3 N", "1", ["expected a plain number"]), ("fast", "m/s", ["cannot read"]),
    ("", "m", ["empty"]), ("inf mm", "m", ["not a finite number"]), (30, "deg", ["ambiguous"]),
    (6, "dB", ["ambiguous"]), ("6", "dB", ["cannot read"]), ("30", "deg", ["no unit"]),
    ([1, 2], "m", ["expected a number or a string"]), (float("nan"), "m", ["finite"]),
    # pint reads these as other numbers (125 kg, 0 mm, 6667 N/m, 15 N): refused, showing the text
    ("1,25 kg", "kg", ["'1,25 kg'", "comma", "'1.25 kg'"]),
    ("0,3 mm", "m", ["'0,3 mm'", "comma"]), ("6,667 N/m", "N/m", ["'6,667 N/m'", "comma"]),
    ("2,5 Hz", "Hz", ["'2,5 Hz'", "comma"]), ("3 5 N", "N", ["'3 5 N'", "two numbers"]),
    ("2. 5 N", "N", ["two numbers"]), ("3 -5 N", "N", ["two numbers"]),
    pytest.param(10 ** 401, "kg", ["402 digits", "too large"], id="401-digit-integer"),
])
def test_bad_values_name_the_path(value, unit, words):
    with pytest.raises(UnitError) as err:
        to_si(value, unit, path="friction.static")
    assert err.value.path == "friction.static"
    for w in words:
        assert w in str(err.value), str(err.value)


@pytest.mark.parametrize("value,unit,meant", [
    ("15 hz", "Hz", ["'15 Hz'"]), ("2 khz", "Hz", ["'2 kHz'"]), ("1 KN", "N", ["'1 kN'"]),
    ("2 Kg", "kg", ["'2 kg'"]), ("1e5 n/m", "N/m", ["'1e5 N/m'"]),
    # read as megamolar: pint knows MM, only not as a length
    ("10 MM", "m", ["'10 Mm'", "'10 mm'"]),
])
def test_a_unit_in_the_wrong_case_is_named(value, unit, meant):
    with pytest.raises(UnitError) as err:
        to_si(value, unit, path="friction.static")
    assert "did you mean " + " or ".join(meant) + "?" in str(err.value), str(err.value)
    assert to_si(meant[-1].strip("'"), unit) > 0  # the suggestion reads


@pytest.mark.parametrize("value,unit", [("3 bananas", "m"), ("10 mmm", "m"), ("3 mm", "N")])
def test_no_case_suggestion_where_case_does_not_help(value, unit):
    with pytest.raises(UnitError) as err:
        to_si(value, unit)
    assert "did you mean" not in str(err.value)


def test_unknown_target_unit_is_a_programming_error():
    with pytest.raises(ArgumentError, match="unknown target unit"):
        to_si(1.0, "furlong")


@settings(max_examples=50, deadline=None)
@given(x=st.floats(-1e6, 1e6, allow_nan=False), prefix=st.sampled_from(
    [("mm", 1e-3), ("um", 1e-6), ("km", 1e3), ("m", 1.0)]))
def test_lengths_scale_by_their_prefix(x, prefix):
    unit, factor = prefix
    assume(x == 0 or 1e-15 <= abs(x * factor) <= 1e3)  # plausible lengths (PLAUSIBLE["m"])
    assert to_si(f"{x!r} {unit}", "m") == pytest.approx(x * factor, rel=1e-12, abs=1e-300)


@pytest.mark.parametrize("value,unit,expected", [
    # the forms examples/ and docs/ write, read as before
    ("1e6 N/m", "N/m", 1e6), ("1.371e6 N/m", "N/m", 1.371e6), ("0 N/(m*s)", "N/(m*s)", 0.0),
    ("0.5 m/s^2", "m/s**2", 0.5), ("7800 kg/m^3", "kg/m**3", 7800.0), ("20 %", "1", 0.2),
    ("10%", "1", 0.1), ("1e-6", "1", 1e-6), ("-0.2 N", "N", -0.2), ("-3 dB", "dB", -3.0),
    ("50.26 rad/s", "Hz", 50.26 / (2 * math.pi)), ("2 s^-1", "Hz", 2.0), ("2Hz", "Hz", 2.0),
    ("4 (m/s)^2/m", "m/s**2", 4.0),
    # numpy's numbers as Python's
    (np.int64(2), "kg", 2.0), (np.float32(1.5), "kg", 1.5), (np.float64(1.6), "kg", 1.6),
])
def test_one_number_and_its_unit_reads(value, unit, expected):
    assert to_si(value, unit) == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("value,unit,words", [
    # pint evaluated these as expressions: 1 kg, 1 kg, 4 kg, a hang, a number of 302 digits
    ("kg", "kg", ["'kg' needs a number", "'1 kg'"]),
    ("kg kg/kg", "kg", ["needs a number"]), ("mm/s", "m/s", ["needs a number"]),
    ("2 kg * 2", "kg", ["'2 kg * 2'", "one number followed by its unit"]),
    ("9**9**9 kg", "kg", ["one number followed by its unit"]),
    ("2**1000 kg", "kg", ["one number followed by its unit"]),
    ("2 kg^9^9", "kg", ["one number followed by its unit"]),
    # not finite, or overflowing: refused as such
    (".nan", "kg", ["'.nan' is not a finite number"]), ("-.inf", "kg", ["not a finite number"]),
    ("1e400 kg", "kg", ["not a finite number", "too large"]),
    ("1" * 5000 + " kg", "kg", ["not a finite number", "too large", "..."]),
    # finite but absurd: the analysis overflowed on these
    ("1e300 kg", "kg", ["not a plausible mass"]), ("1e-300 kg", "kg", ["not a plausible mass"]),
    (1e300, "kg", ["not a plausible mass"]), ("1e300 N/m", "N/m", ["not a plausible stiffness"]),
    ("1e300 N*s/m", "N*s/m", ["not a plausible damping"]),
    ("1e300 N", "N", ["not a plausible force"]),
    ("1e300 m", "m", ["not a plausible length"]), ("1e-300 mm", "m", ["not a plausible length"]),
    ("1e300 Hz", "Hz", ["not a plausible frequency"]), ("1e300 s", "s", ["not a plausible time"]),
    ("1e300 m/s", "m/s", ["not a plausible velocity"]),
    ("1e20 GPa", "Pa", ["not a plausible pressure"]),
    (np.bool_(True), "kg", ["got bool"]),
])
def test_a_value_is_one_number_and_its_unit(value, unit, words):
    with pytest.raises(UnitError) as err:
        to_si(value, unit, path="stage.mass")
    assert err.value.path == "stage.mass"
    for w in words:
        assert w in str(err.value), str(err.value)
    assert len(str(err.value)) < 300


@pytest.mark.parametrize("path", ["stage.mass", "requirements.parasitic_separation",
                                  "requirements.hunting_margin", "requirements.robustness.samples"])
def test_an_integer_beyond_pythons_digit_limit_is_a_spec_error_in_a_mapping(path,
                                                                          paper_spec_path):
    """A library mapping (or with_values, Model.varied) holding an integer of 5000 digits was a
    raw ValueError from the spec's hash or the message's str(): now a SpecError naming the path."""
    import copy

    import yaml

    from fi_design.errors import SpecError
    from fi_design.model import resolve
    from fi_design.spec.file import load_spec
    from fi_design.spec.paths import with_values

    raw = yaml.safe_load(paper_spec_path.read_text())
    data = copy.deepcopy(raw)
    node = data
    *head, last = path.split(".")
    for key in head:
        node = node.setdefault(key, {})
    node[last] = 10 ** 5000
    spec = load_spec(raw)
    for call in (lambda: load_spec(data), lambda: with_values(spec, {path: 10 ** 5000}),
                 lambda: resolve(spec).varied({path: 10 ** 5000})):
        with pytest.raises(SpecError) as err:
            call()
        assert err.value.path == path
        assert "more than 4300 digits" in str(err.value), str(err.value)


def test_the_plausible_range_reads_in_one_unit():
    # '0.3 Mm' said a length lies 'within < 0.001 µm to 1 × 10⁶ mm': the bounds each in the
    # unit its size picked (the lower one below what quantity shows), not the value in SI
    with pytest.raises(UnitError) as err:
        to_si("0.3 Mm", "m", path="isolator.stroke")
    assert "'0.3 Mm' (300000 m) is not a plausible length: a nonzero one lies within " \
           "1\u00a0×\u00a010⁻¹⁵ to 1000 m;" in str(err.value), str(err.value)
    with pytest.raises(UnitError, match="is at most 1\u00a0×\u00a010¹⁵ N;"):
        to_si("5e15 N", "N")
