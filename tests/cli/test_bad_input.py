"""Bad input: exit code 2, one message naming the problem, no traceback, nothing written.

Every case runs the default command with ``--json`` to a temporary path and
checks that the file was not created (and that no temporary file is left).
The cases start from examples/paper_setup.yaml and change one line, so the
expected YAML line number is known.
"""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from fi_design.cli.app import app

from conftest import EXAMPLES

runner = CliRunner()
BASE = (EXAMPLES / "paper_setup.yaml").read_text()

BILLION_LAUGHS = """\
a: &a ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]
b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]
c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]
d: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]
e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d]
f: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e]
g: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f]
h: &h [*g, *g, *g, *g, *g, *g, *g, *g, *g]
i: &i [*h, *h, *h, *h, *h, *h, *h, *h, *h]
"""


def edit(old: str, new: str) -> str:
    """BASE with the first occurrence of ``old`` replaced (which must exist)."""
    assert old in BASE, old
    return BASE.replace(old, new, 1)


def line_of(text: str, needle: str) -> int:
    """1-based line of the first line containing ``needle``."""
    for i, ln in enumerate(text.splitlines(), 1):
        if needle in ln:
            return i
    raise AssertionError(needle)


def drop(line_start: str) -> str:
    """BASE without the line that starts (after indentation) with ``line_start``."""
    lines = BASE.splitlines(keepends=True)
    kept = [ln for ln in lines if not ln.strip().startswith(line_start)]
    assert len(kept) == len(lines) - 1, line_start
    return "".join(kept)


# (id, file text, substrings the message must contain, line-marker needle or None)
CASES = [
    ("empty", "", ["empty"], None),
    ("only-comments", "# nothing here\n", ["empty"], None),
    ("not-yaml", "stage: {mass: 1 kg\ncart: [\n", ["not valid YAML"], None),
    ("list-top-level", "- stage\n- cart\n", ["top level must be a mapping", "got a list"], None),
    ("scalar-top-level", "just text\n", ["top level must be a mapping"], None),
    ("missing-field", drop("static: 4 N"), ["friction.static", "required field is missing"],
     None),
    ("missing-section", drop("controller:").replace("  crossover: 8 Hz", "").replace(
        "  derivative_ratio: 3", "").replace("  integrator_ratio: 10", ""),
     ["controller", "required field is missing"], None),
    ("negative-mass", edit("stage: {mass: 1.6 kg}", "stage: {mass: -1.6 kg}"),
     ["stage.mass", "greater than 0"], "stage: {mass"),
    ("zero-mass", edit("cart: {mass: 0.4 kg}", "cart: {mass: 0}"),
     ["cart.mass", "greater than 0"], "cart: {mass"),
    ("wrong-dimension", edit("stiffness: 6667 N/m", "stiffness: 5 kg"),
     ["isolator.stiffness", "'5 kg'", "stiffness"], "stiffness: 5 kg"),
    ("unparsable-unit", edit("static: 4 N", "static: 4 bananas"),
     ["friction.static", "4 bananas"], "static: 4 bananas"),
    ("nan", edit("stage: {mass: 1.6 kg}", "stage: {mass: .nan}"),
     ["stage.mass", "finite"], "stage: {mass"),
    ("inf", edit("static: 4 N", "static: .inf"), ["friction.static", "finite"], "static: .inf"),
    ("nan-with-unit", edit("coulomb: 1 N", 'coulomb: "nan N"'),
     ["friction.coulomb", "finite"], "coulomb:"),
    ("inf-with-unit", edit("stroke: 0.3 mm", 'stroke: "inf mm"'),
     ["isolator.stroke", "finite"], "stroke:"),
    ("unknown-key-typo", edit("static: 4 N", "statc: 4 N"),
     ["friction.statc", "unknown key", "did you mean 'static'"], "statc:"),
    ("unknown-section", edit("controller:", "controler:"),
     ["controler", "unknown key", "did you mean 'controller'"], "controler:"),
    # a key no identifier (a hyphen, a space) was taken for a union tag and dropped: the
    # message named the section as its own unknown key ("friction: unknown key 'friction'")
    ("unknown-key-hyphen", edit("stribeck_velocity: 3 mm/s", "stribeck-velocity: 3 mm/s"),
     ["friction.stribeck-velocity", "unknown key 'stribeck-velocity'",
      "did you mean 'stribeck_velocity'"], "stribeck-velocity:"),
    ("unknown-key-space", edit("  static: 4 N", "  static friction: 4 N"),
     ["friction.static friction", "unknown key 'static friction'"], "static friction:"),
    ("unknown-top-level-key-space", BASE + "my notes: checked\n",
     ["unknown key 'my notes'"], "my notes:"),
    ("unknown-effect", BASE + "effects:\n  - {type: time_dleay, delay: 1 ms}\n",
     ["effects[0].type", "unknown effect 'time_dleay'", "did you mean 'time_delay'"],
     "type: time_dleay"),
    ("unit-wrong-case", edit("crossover: 8 Hz", "crossover: 15 hz"),
     ["controller.crossover", "'15 hz'", "did you mean '15 Hz'"], "crossover: 15 hz"),
    ("effect-without-type", BASE + "effects:\n  - {delay: 1 ms}\n",
     ["effects[0].type", "required field is missing", "time_delay"], "{delay: 1 ms}"),
    ("effect-with-empty-type", BASE + "effects:\n  - type:\n    delay: 1 ms\n",
     ["effects[0].type", "required field is missing"], "  - type:"),
    ("effect-missing-parameter", BASE + "effects:\n  - {type: time_delay}\n",
     ["effects[0].delay", "required field is missing"], "type: time_delay"),
    ("python-tag", edit("stage: {mass: 1.6 kg}",
                        "stage: !!python/object/apply:os.system ['touch PWNED']"),
     ["python/object/apply:os.system", "not allowed"], "stage: !!python"),
    ("python-name-tag", edit("name: Paper setup with friction isolator",
                             "name: !!python/name:os.system"),
     ["not allowed"], "name: !!python"),
    ("alias-bomb", BILLION_LAUGHS, ["alias bomb"], None),
    ("duplicate-key", edit("coulomb: 1 N", "coulomb: 1 N\n  coulomb: 2 N"),
     ["friction.coulomb", "appears twice"], None),
    ("static-below-coulomb", edit("static: 4 N", "static: 0.5 N"),
     ["friction", "static friction Fs = 0.5 N must be at least the Coulomb friction"], None),
    ("bare-phase-margin", edit("phase_margin: 30 deg", "phase_margin: 30"),
     ["requirements.phase_margin", "'30 deg'"], "phase_margin: 30"),
    ("bare-gain-margin", edit("gain_margin: 6 dB", "gain_margin: 6"),
     ["requirements.gain_margin", "dB"], "gain_margin: 6"),
    ("wrong-type", edit("stage: {mass: 1.6 kg}", "stage: [1.6 kg]"),
     ["stage", "expected a mapping"], "stage: [1.6"),
    ("zero-distance", edit("distance: 10 mm", "distance: 0 mm"),
     ["motion.moves[0]", "distance must not be zero"], None),
    # values read wrong: a decimal comma or a space inside a number, named with what was read
    ("decimal-comma-mass", edit("stage: {mass: 1.6 kg}", 'stage: {mass: "1,25 kg"}'),
     ["stage.mass", "'1,25 kg'", "comma", "'1.25 kg'"], "stage: {mass"),
    ("decimal-comma-frequency", edit("crossover: 8 Hz", 'crossover: "2,5 Hz"'),
     ["controller.crossover", "'2,5 Hz'", "comma"], "crossover:"),
    ("decimal-comma-to-zero", edit("stroke: 0.3 mm", 'stroke: "0,3 mm"'),
     ["isolator.stroke", "'0,3 mm'", "comma"], "stroke:"),
    ("thousands-comma", edit("stiffness: 6667 N/m", 'stiffness: "6,667 N/m"'),
     ["isolator.stiffness", "'6,667 N/m'", "comma"], "6,667"),
    ("space-in-number", edit("static: 4 N", 'static: "3 5 N"'),
     ["friction.static", "'3 5 N'", "two numbers"], "static:"),
    # a value is one number and its unit, never an expression; absurd values are refused
    ("mass-without-number", edit("stage: {mass: 1.6 kg}", "stage: {mass: kg}"),
     ["stage.mass", "'kg' needs a number"], "stage: {mass"),
    ("mass-expression", edit("stage: {mass: 1.6 kg}", "stage: {mass: 2 kg * 2}"),
     ["stage.mass", "one number followed by its unit"], "stage: {mass"),
    ("mass-power-tower", edit("stage: {mass: 1.6 kg}", 'stage: {mass: "9**9**9 kg"}'),
     ["stage.mass", "one number followed by its unit"], "stage: {mass"),
    ("mass-absurd", edit("stage: {mass: 1.6 kg}", "stage: {mass: 1e300 kg}"),
     ["stage.mass", "not a plausible mass"], "stage: {mass"),
    ("mass-tiny", edit("stage: {mass: 1.6 kg}", "stage: {mass: 1e-300 kg}"),
     ["stage.mass", "not a plausible mass"], "stage: {mass"),
    ("bristle-stiffness-absurd", edit("bristle_stiffness: 1e6 N/m", "bristle_stiffness: 1e300 N/m"),
     ["friction.bristle_stiffness", "not a plausible stiffness"], "bristle_stiffness:"),
    # lengths, frequencies and their kin too (each took the analysis into an internal error)
    ("stroke-absurd", edit("stroke: 0.3 mm", "stroke: 1e300 m"),
     ["isolator.stroke", "not a plausible length"], "stroke: 1e300"),
    ("crossover-absurd", edit("crossover: 8 Hz", "crossover: 1e300 Hz"),
     ["controller.crossover", "not a plausible frequency"], "crossover: 1e300"),
    ("leaf-length-absurd", edit("length: [10 mm, 60 mm]", "length: [10 mm, 1e300 mm]"),
     ["isolator.flexure.length", "not a plausible length"], "length: [10 mm"),
    ("mass-5000-digits", edit("stage: {mass: 1.6 kg}", "stage: {mass: " + "1" * 5000 + "}"),
     ["stage.mass", "5000 digits", "too large"], "stage: {mass"),
    ("mass-5000-digits-kg", edit("stage: {mass: 1.6 kg}", "stage: {mass: " + "1" * 5000 + " kg}"),
     ["stage.mass", "not a finite number"], "stage: {mass"),
    # lists too short or too long, in the tool's words; a dimensionless bound without a unit
    ("empty-family", edit("  duration: 20 s", "  duration: 20 s\n  family: {distances: []}"),
     ["motion.family.distances", "an empty list", "at least one distance", "null"], "family:"),
    ("five-filters", edit("  integrator_ratio: 10", "  integrator_ratio: 10\n  filters: ["
                          + ", ".join(["{type: low_pass, frequency: 300 Hz}"] * 5) + "]"),
     ["controller.filters", "takes at most 4 filters, got 5"], "filters:"),
    # a plain-number field (a ratio, a fraction) given a unit: the message said it expected
    # "a number or a string with units" of a string with units, and named no way out
    ("ratio-with-a-unit", edit("derivative_ratio: 3", "derivative_ratio: 3 Hz"),
     ["controller.derivative_ratio", "a plain number [-], written without a unit",
      "got '3 Hz'"], "derivative_ratio: 3 Hz"),
    ("ratio-in-percent", edit("gain_margin: 6 dB", "gain_margin: 6 dB\n  hunting_margin: "
                                                   "120 %"),
     ["requirements.hunting_margin", "a plain number [-]", "got '120 %': write 1.2"],
     "hunting_margin:"),
    # a yes/no value given to a number was read as 1 (samples: true ran one sample)
    ("true-for-a-count", edit("gain_margin: 6 dB", "gain_margin: 6 dB\n  robustness:\n"
                                                   "    samples: true"),
     ["requirements.robustness.samples", "expected a number, got true (a yes/no value"],
     "samples: true"),
    ("false-for-a-ratio", edit("derivative_ratio: 3", "derivative_ratio: false"),
     ["controller.derivative_ratio", "expected a number, got false"], "derivative_ratio: false"),
    # a bound's message shows the value as written, not its SI number without a unit
    ("negative-stroke-as-written", edit("stroke: 0.3 mm", "stroke: -0.3 mm"),
     ["isolator.stroke", "must be greater than 0 m, got '-0.3 mm'"], "stroke: -0.3 mm"),
    ("negative-margin-as-written", edit("gain_margin: 6 dB", "gain_margin: -6 dB"),
     ["requirements.gain_margin", "at least 0 dB, got '-6 dB'"], "gain_margin: -6 dB"),
    # a label YAML reads as a number: one message, on the label, saying to quote it
    ("numeric-revision", edit("revision: A,", "revision: 2,"),
     ["report.revisions[0].revision", "YAML read 2 as a number", "'2'"], "revision: 2,"),
    ("hunting-margin-below-1", edit("gain_margin: 6 dB", "gain_margin: 6 dB\n  hunting_margin: 0.5"),
     ["requirements.hunting_margin", "must be at least 1, got 0.5"], "hunting_margin:"),
    # checks across sections name the field the user gave, and its line
    ("run-shorter-than-window", edit("duration: 20 s", "duration: 1 ms"),
     ["motion.duration", "hunting window ends at 20 s"], "duration: 1 ms"),
    ("window-after-run", edit("gain_margin: 6 dB", "gain_margin: 6 dB\n  hunting: "
                                                   "{window_start: 15 s}"),
     ["requirements.hunting.window_start", "hunting window ends at 25 s"], "window_start:"),
    # a fixed list too short; a value-or-range with three values: no pydantic internals
    ("size-too-short", edit("stage: {mass: 1.6 kg}", "stage: {mass: 1.6 kg, size: [10 mm, 20 mm]}"),
     ["stage.size: too few values: the list gives 2, value 3 is missing"], "stage: {"),
    # a leaf guide that cannot be built or sized, named at the field that makes it so
    ("leaf-bounds-reversed", edit("length: [10 mm, 60 mm]", "length: [60 mm, 10 mm]"),
     ["isolator.flexure.length", "0 < min <= max", "[60 mm, 10 mm]"], "length: [60 mm"),
    ("leaf-bound-without-unit", edit("thickness: [0.1 mm, 1 mm]", "thickness: [0.1, 1 mm]"),
     ["isolator.flexure.thickness", "[100 mm, 1 mm]", "without a unit is read in m"],
     "thickness: [0.1,"),
    ("leaf-thickness-in-metres", edit("thickness: [0.1 mm, 1 mm]", "thickness: [0.1 mm, 0.1 m]"),
     ["isolator.flexure.thickness_step", "1999 stock thicknesses from 0.1 mm to 100 mm",
      "at most 200"], None),
    ("stock-step-nanometres", edit("thickness: [0.1 mm, 1 mm]",
                                   "thickness: [0.1 mm, 1 mm]\n    thickness_step: 10 nm"),
     ["isolator.flexure.thickness_step", "90001 stock thicknesses", "at most 200"],
     "thickness_step:"),
    ("leaf-thickness-in-kilograms", edit("thickness: [0.1 mm, 1 mm]", "thickness: 0.1 kg"),
     ["isolator.flexure.thickness", "'0.1 kg' is not a length"], "thickness: 0.1 kg"),
    ("drawn-leaf-thicker-than-wide",
     edit("length: [10 mm, 60 mm]\n    width: [5 mm, 30 mm]\n    thickness: [0.1 mm, 1 mm]",
          "length: 40 mm\n    width: 5 mm\n    thickness: 6 mm"),
     ["isolator.flexure.thickness", "thinner than it is wide", "6 mm is not below width 5 mm"],
     "thickness: 6 mm"),
    ("rows-of-leaves-touch", edit("leaves: 2", "leaves: 2\n    spacing: 1 um"),
     ["isolator.flexure.spacing", "rows of leaves would touch"], "spacing: 1 um"),
    ("leaves-of-a-row-overlap", edit("leaves: 2", "leaves: 4\n    lateral_spacing: 1 mm"),
     ["isolator.flexure.lateral_spacing", "would overlap", "smallest leaf width 5 mm"],
     "lateral_spacing: 1 mm"),
    ("lateral-spacing-with-two-leaves", edit("leaves: 2", "leaves: 2\n    lateral_spacing: 20 mm"),
     ["isolator.flexure.lateral_spacing", "needs leaves: 4"], "lateral_spacing: 20 mm"),
    # a leaf material no leaf is made of: a unit left out or mistaken
    ("modulus-without-unit", edit("youngs_modulus: 200 GPa", "youngs_modulus: 200"),
     ["isolator.flexure.material.youngs_modulus", "not the modulus of a leaf spring",
      "read in Pa"], "material:"),
    ("density-in-g-per-cm3", edit("density: 7800 kg/m^3", "density: 7.8 kg/m^3"),
     ["isolator.flexure.material.density", "not the density of a solid"], "material:"),
    ("stress-above-modulus", edit("allowed_stress: 300 MPa", "allowed_stress: 500 GPa"),
     ["isolator.flexure.material.allowed_stress", "a strain of 2.5"], "material:"),
    ("recommend-bounds-reversed", edit("gain_margin: 6 dB", "gain_margin: 6 dB\n  recommend: "
                                                          "{stroke: [2 mm, 1 mm]}"),
     ["requirements.recommend.stroke", "[2 mm, 1 mm]"], "recommend: {stroke"),
    ("range-of-three", edit("length: [10 mm, 60 mm]", "length: [10 mm, 60 mm, 70 mm]"),
     ["isolator.flexure.length: takes at most 2 values, got 3"], "length: [10 mm"),
    # a band wider than the least cycle counted would take a 1.8 mm cycle for rest
    ("band-hides-cycles", edit("gain_margin: 6 dB", "gain_margin: 6 dB\n  hunting: "
                                                    "{settle_band: 5 mm}"),
     ["requirements.hunting", "settle_band = 5 mm is not below min_height = 0.1 mm"],
     "settle_band:"),
    ("effect-twice", BASE + "effects: [{type: time_delay, delay: 1 ms}, "
                            "{type: time_delay, delay: 2 ms}]\n",
     ["effects", "listed twice"], "effects:"),
    # effects with impossible parameters
    ("effect-negative-delay", BASE + "effects:\n  - {type: time_delay, delay: -1 ms}\n",
     ["effects[0].delay", "at least 0 s", "got '-1 ms'"], "type: time_delay"),
    ("effect-negative-resolution",
     BASE + "effects:\n  - {type: quantization, resolution: -1 um}\n",
     ["effects[0].resolution", "at least 0 m"], "type: quantization"),
    ("effect-negative-force-limit",
     BASE + "effects:\n  - {type: force_saturation, limit: -10 N}\n",
     ["effects[0].limit", "greater than 0 N"], "type: force_saturation"),
    ("effect-negative-mass", BASE + "effects:\n  - {type: mass_error, stage_mass: -1 kg}\n",
     ["effects[0].stage_mass", "greater than 0 kg"], "type: mass_error"),
    ("effect-zero-cart-mass", BASE + "effects:\n  - {type: mass_error, cart_mass: 0}\n",
     ["effects[0].cart_mass", "greater than 0 kg"], "type: mass_error"),
    ("effect-negative-viscous",
     BASE + "effects:\n  - {type: viscous_friction, viscous: -5 N*s/m}\n",
     ["effects[0].viscous", "at least 0 N·s/m"], "type: viscous_friction"),
    ("effect-negative-coulomb",
     BASE + "effects:\n  - {type: friction_asymmetry, coulomb_negative: -1 N}\n",
     ["effects[0].coulomb_negative", "at least 0 N"], "type: friction_asymmetry"),
    ("effect-negative-viscous-negative",
     BASE + "effects:\n  - {type: friction_asymmetry, coulomb_negative: 1 N, "
            "viscous_negative: -1}\n",
     ["effects[0].viscous_negative", "at least 0 N·s/m"], "type: friction_asymmetry"),
    ("effect-negative-joint-damping",
     BASE + "effects:\n  - {type: joint_damping, damping: -1 N*s/m}\n",
     ["effects[0].damping", "at least 0 N·s/m"], "type: joint_damping"),
    ("effect-zero-wavelength",
     BASE + "effects:\n  - {type: position_dependent_friction, amplitude: 0.1, "
            "wavelength: 0 m}\n",
     ["effects[0].wavelength", "greater than 0 m"], "type: position_dependent_friction"),
    ("effect-zero-pitch", BASE + "effects:\n  - {type: force_ripple, amplitude: 1 N, pitch: 0}\n",
     ["effects[0].pitch", "greater than 0 m"], "type: force_ripple"),
    ("effect-zero-stribeck",
     BASE + "effects:\n  - {type: stribeck_velocity, stribeck_velocity: 0}\n",
     ["effects[0].stribeck_velocity", "greater than 0 m/s"], "type: stribeck_velocity"),
    ("effect-ripple-amplitude-2",
     BASE + "effects:\n  - {type: position_dependent_friction, amplitude: 2, "
            "wavelength: 1 mm}\n",
     ["effects[0].amplitude", "less than 1", "2"], "type: position_dependent_friction"),
    ("effect-bare-string", BASE + "effects:\n  - time_delay\n",
     ["effects[0]", "'time_delay'", "{type: time_delay, delay: ...}"], "- time_delay"),
    ("effect-unknown-key", BASE + "effects:\n  - {type: time_delay, delya: 1 ms}\n",
     ["effects[0].delya", "unknown key 'delya'", "did you mean 'delay'"], "type: time_delay"),
    ("effect-unknown-key-far", BASE + "effects:\n  - {type: force_ripple, amplitude: 1 N, "
                                      "pitch: 1 mm, zzz: 1}\n",
     ["effects[0].zzz", "allowed: type, amplitude, pitch, phase"], "type: force_ripple"),
    # sizes without a bound: refused up front, naming the limit
    ("output-rate-gigahertz", BASE + "simulation: {output_rate: 1 GHz}\n",
     ["simulation.output_rate", "10⁹ Hz", "output samples", "at most"], "output_rate"),
    ("duration-without-bound", edit("duration: 20 s", "duration: 1e9 s"),
     ["motion.duration", "output samples", "at most"], "duration:"),
    ("step-budget-without-bound", BASE + "simulation: {max_steps: 100000000000}\n",
     ["simulation.max_steps", "at most"], "max_steps"),
    # parse-level crashes
    ("nested-mappings", "a: " + "{b: " * 1000 + "1" + "}" * 1000 + "\n",
     ["nested", "levels"], None),
    ("complex-key", BASE + "? [a, b]\n: 1\n", ["key", "plain", "list"], "? [a, b]"),
    ("huge-integer", edit("stage: {mass: 1.6 kg}", "stage: {mass: " + "9" * 401 + "}"),
     ["stage.mass", "too large"], "stage: {mass"),
    ("huge-integer-ratio", edit("derivative_ratio: 3", "derivative_ratio: " + "9" * 401),
     ["controller.derivative_ratio", "401 digits", "too large"], "derivative_ratio:"),
    ("impossible-date", edit("date: 2026-01-15", "date: 2026-13-45"),
     ["report.revisions[0].date", "'2026-13-45' is not a valid date", "month"], "date: 2026-13-45"),
    ("thirtieth-of-february", edit("date: 2026-01-15", "date: 2026-02-30"),
     ["report.revisions[0].date", "not a valid date"], "date: 2026-02-30"),
    # text that reaches the report
    ("nul-escape-in-text", edit("author: A. Engineer ", 'approved_by: "X\\u0000Y"\n  author: '
                                                        'A. Engineer '),
     ["report.approved_by", "U+0000"], "approved_by:"),
    ("escape-in-name", edit("name: Paper setup with friction isolator", 'name: "Paper\\x1b[31m"'),
     ["name", "U+001B"], "name:"),
    # the recommend report's id alone was a plain str: a control character passed
    ("escape-in-recommend-id", edit("  status: draft", '  status: draft\n  document_ids: '
                                                       '{recommend: "R\\x1b[31m"}'),
     ["report.document_ids.recommend", "U+001B"], "document_ids:"),
]


def _run(spec_arg: str, tmp_path):
    out = tmp_path / "out.json"
    result = runner.invoke(app, [spec_arg, "--json", str(out)])
    return result, out


def _assert_refused(result, out, tmp_path, expected):
    assert result.exit_code == 2, (result.exit_code, result.output)
    message = result.stderr
    assert message.startswith("error: "), message
    for text in expected:
        assert text in message, f"{text!r} not in {message!r}"
    assert "Traceback" not in result.output
    assert result.stdout == "", "nothing but the error message is printed"
    assert not out.exists(), "no output may be written on bad input"
    leftovers = [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert not leftovers, leftovers


@pytest.mark.parametrize("text,expected,needle", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_bad_spec(tmp_path, monkeypatch, text, expected, needle):
    monkeypatch.chdir(tmp_path)
    spec = tmp_path / "bad.yaml"
    spec.write_text(text)
    result, out = _run(str(spec), tmp_path)
    _assert_refused(result, out, tmp_path, expected + [str(spec)])
    if needle is not None:
        n = line_of(text, needle)
        assert f"{spec}:{n}:" in result.stderr or f"(line {n})" in result.stderr, result.stderr
    assert not (tmp_path / "PWNED").exists()


@pytest.mark.parametrize("old,new,path", [
    ("distance: 10 mm", "distance: 10 mmm", "motion.moves[0].distance"),
    ("velocity: 50 mm/s", "velocity: -50 mm/s", "motion.moves[0].velocity"),
    ("acceleration: 1 m/s^2", "acceleration: 1 m/s^2, jerk: fast", "motion.moves[0].jerk"),
])
def test_a_bad_field_in_a_move_is_the_only_problem(tmp_path, monkeypatch, old, new, path):
    """Pydantic also finds the moves "too short" (counting the moves that passed): not a
    problem of the spec, which has its one move."""
    monkeypatch.chdir(tmp_path)
    spec = tmp_path / "bad.yaml"
    spec.write_text(edit(old, new))
    result, out = _run(str(spec), tmp_path)
    _assert_refused(result, out, tmp_path, [path, f"{spec}:{line_of(edit(old, new), new)}:"])
    assert "more problem" not in result.stderr and "at least 1 item" not in result.stderr, \
        result.stderr


def test_a_spec_without_moves_is_still_told_so(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec = tmp_path / "bad.yaml"
    spec.write_text(edit("    - {distance: 10 mm, velocity: 50 mm/s, acceleration: 1 m/s^2}\n",
                         "").replace("moves:", "moves: []"))
    result, out = _run(str(spec), tmp_path)
    _assert_refused(result, out, tmp_path, ["motion.moves", "needs at least one move, got none"])
    assert "Tuple" not in result.stderr and "item" not in result.stderr, result.stderr


def test_missing_file(tmp_path):
    result, out = _run(str(tmp_path / "nope.yaml"), tmp_path)
    _assert_refused(result, out, tmp_path, ["nope.yaml", "no such file"])


def test_directory(tmp_path):
    d = tmp_path / "specs.yaml"
    d.mkdir()
    result, out = _run(str(d), tmp_path)
    _assert_refused(result, out, tmp_path, ["is a directory"])


def test_binary_file(tmp_path):
    spec = tmp_path / "bin.yaml"
    spec.write_bytes(b"\xff\xfe\x00\x01garbage\x80")
    result, out = _run(str(spec), tmp_path)
    _assert_refused(result, out, tmp_path, ["not a text file"])


def test_a_spec_in_another_encoding_names_the_line_and_column(tmp_path):
    # a Latin-1 byte said 'not a text file (not UTF-8)', with no line or position
    spec = tmp_path / "latin.yaml"
    spec.write_bytes(b'name: "\xc3\xa9t\xc3\xa9"\nstage: {mass: 1 kg}   # r\xe9f\n')
    result, out = _run(str(spec), tmp_path)
    _assert_refused(result, out, tmp_path, [
        "latin.yaml:2: byte 0xe9 at column 26 (byte offset 39 of the file) is not UTF-8",
        "save the file as UTF-8"])


@pytest.mark.parametrize("char", ["\x00", "\x07", "\x1b"])
def test_control_character_in_the_spec(tmp_path, char):
    """A NUL (or other control character) is bad input naming file and line, not a bug."""
    text = edit("static: 4 N", f"static: 4{char} N")
    spec = tmp_path / "ctrl.yaml"
    spec.write_bytes(text.encode("utf-8"))
    result, out = _run(str(spec), tmp_path)
    n = line_of(text, "static: 4")
    _assert_refused(result, out, tmp_path, [f"{spec}:{n}:", f"U+{ord(char):04X}",
                                            "not plain text"])
    assert "internal error" not in result.stderr


def test_several_problems_listed(tmp_path):
    text = edit("static: 4 N", "statc: 4 N").replace("stage: {mass: 1.6 kg}", "stage: {mass: -1}")
    spec = tmp_path / "two.yaml"
    spec.write_text(text)
    result, out = _run(str(spec), tmp_path)
    _assert_refused(result, out, tmp_path, ["more problem", "stage.mass", "friction.statc"])


def test_usage_errors_exit_2(tmp_path, paper_spec_path):
    out = tmp_path / "out.json"
    r = runner.invoke(app, [str(paper_spec_path), "--json", str(out), "--no-such-option"])
    assert r.exit_code == 2
    assert "no-such-option" in r.output
    assert not out.exists()
    r = runner.invoke(app, ["design"])
    assert r.exit_code == 2


def test_unknown_key_is_reported_before_the_missing_field_it_causes(tmp_path):
    """A misspelt required key is both unknown and missing: the typo comes first."""
    text = edit("static: 4 N", "statc: 4 N")
    spec = tmp_path / "typo.yaml"
    spec.write_text(text)
    result, out = _run(str(spec), tmp_path)
    _assert_refused(result, out, tmp_path, ["friction.statc", "friction.static"])
    first = result.stderr.splitlines()[0]
    n = line_of(text, "statc:")
    assert f"{spec}:{n}: friction.statc: unknown key 'statc'; did you mean 'static'?" in first, \
        result.stderr
    assert "required field is missing" in result.stderr.split("\n", 1)[1]


# --------------------------------------------------------------------------- sizes a user sets

NO_SPEC = "absent-spec.yaml"  # options are refused before the spec is read

SIZES = [
    ("sweep-points", ["sweep", "PAPER", "--x", "controller.crossover=1 Hz:30 Hz:10000000000",
                      "--json", "OUT"],
     ["controller.crossover", "N = 10000000000 points", "at most 100000"]),
    ("sweep-grid", ["sweep", "PAPER", "--x", "controller.crossover=1 Hz:30 Hz:1000",
                    "--y", "isolator.stroke=0.1 mm:1 mm:1000", "--json", "OUT"],
     ["1000 x 1000 = 1000000 points", "at most 100000"]),
    ("replay-window", ["simulate", "MSPEC", "--record", "TRACE", "--drive", "force",
                       "--window", "1e-12", "--json", "OUT"],
     ["window = 1\u00a0×\u00a010⁻¹² s", "fewer than 10 samples"]),
    ("robustness-samples", ["robustness", NO_SPEC, "--scatter", "friction.static=10%",
                            "--samples", "1000000000", "--json", "OUT"],
     ["--samples", "1000000000", "100000"]),
    ("robustness-seed", ["robustness", NO_SPEC, "--scatter", "friction.static=10%",
                         "--seed", "-1", "--json", "OUT"],
     ["--seed", "greater than or equal to 0"]),
    ("study-resolution", ["study", "paper", NO_SPEC, "--resolution", "200"],
     ["--resolution", "200", "150"]),
    ("jobs", ["sweep", NO_SPEC, "--x", "stage.mass=1,2", "--jobs", "100000", "--json", "OUT"],
     ["--jobs", "100000", "64"]),
]


@pytest.mark.parametrize("argv,expected", [c[1:] for c in SIZES], ids=[c[0] for c in SIZES])
def test_sizes_are_bounded_up_front(tmp_path, monkeypatch, argv, expected):
    """A size that cannot finish (memory, hours of work, a fork per job) is refused before any
    work, naming the option or value, what was read and the bound."""
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out.json"
    names = {"PAPER": str(EXAMPLES / "paper_setup.yaml"),
             "MSPEC": str(EXAMPLES / "measured_stage.yaml"),
             "TRACE": str(EXAMPLES / "measured_trace.csv"), "OUT": str(out)}
    result = runner.invoke(app, [names.get(a, a) for a in argv])
    assert result.exit_code == 2, (result.exit_code, result.output)
    assert "Traceback" not in result.output
    for text in expected:
        assert text in result.output, f"{text!r} not in {result.output!r}"
    assert not out.exists()


# --------------------------------------------------------------------------- inputs never lost


def test_the_record_is_an_input_not_an_output(tmp_path):
    """`simulate --record rec.csv --csv rec.csv --force` replaced the measured record with the
    replay: every input is protected, even with --force."""
    record = tmp_path / "rec.csv"
    record.write_bytes((EXAMPLES / "measured_trace.csv").read_bytes())
    before = record.read_bytes()
    result = runner.invoke(app, ["simulate", str(EXAMPLES / "measured_stage.yaml"), "--record",
                                 str(record), "--csv", str(record), "--force"])
    assert result.exit_code == 2, result.output
    assert "refusing to overwrite the input file" in result.stderr
    assert record.read_bytes() == before


def test_two_options_naming_one_file_are_refused_as_such(tmp_path, paper_spec_path):
    """`--json o.json --write-spec o.json` said "refusing to overwrite the input file o.json":
    o.json is no input; the message names the two options, and nothing is written."""
    out = tmp_path / "o.json"
    for second in (out, tmp_path / "." / "o.json"):
        result = runner.invoke(app, [str(paper_spec_path), "--json", str(out), "--write-spec",
                                     str(second), "--no-simulation"])
        assert result.exit_code == 2, result.output
        assert "--json and --write-spec name the same file" in result.stderr
        assert "input" not in result.stderr and not out.exists()


def test_a_file_that_appears_during_the_run_is_kept(tmp_path, paper_spec_path, monkeypatch):
    """A file created after the start-up check (another program, another run) is not replaced
    without --force; the run says so and exits 2."""
    import fi_design.guideline.evaluate as guideline

    out = tmp_path / "out.json"
    real = guideline.evaluate

    def design_while_someone_writes(*args, **kwargs):
        out.write_text("written by someone else")
        return real(*args, **kwargs)

    monkeypatch.setattr(guideline, "evaluate", design_while_someone_writes)
    result = runner.invoke(app, [str(paper_spec_path), "--no-simulation", "--json", str(out)])
    assert result.exit_code == 2, result.output
    assert "appeared while this run worked" in result.stderr
    assert out.read_text() == "written by someone else"
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]


def test_a_record_without_excitation_is_refused_not_agreed_with(tmp_path):
    """`reconcile` on a record in which nothing moves answered "agrees within noise (misfit 0):
    no effect is missing" although nothing was tested; it is refused, saying what was read."""
    import numpy as np

    still = tmp_path / "still.csv"
    t = np.arange(0.0, 8.0, 1e-3)
    rows = "\n".join(f"{x:.3f},0,0,0.0,0" for x in t)
    still.write_text("time_s,reference_m,position_m,force_N,deflection_m\n" + rows + "\n")
    out = tmp_path / "gap.json"
    result = runner.invoke(app, ["reconcile", str(EXAMPLES / "measured_stage.yaml"), str(still),
                                 "--json", str(out)])
    assert result.exit_code == 2, result.output
    assert "no excitation" in result.stderr and "position_m" in result.stderr
    assert "the reference spans 0 µm" in result.stderr
    assert not out.exists()
