"""Bad input: exit code 2, one message naming the problem, no traceback, nothing written.

Every case runs the default command with ``--json`` to a temporary path and
checks that the file was not created (and that no temporary file is left).
The cases start from examples/paper_setup.yaml and change one line, so the
expected YAML line number is known.
"""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from fi_design.cli import app

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
    ("unknown-effect", BASE + "effects:\n  - {type: time_dleay, delay: 1 ms}\n",
     ["effects[0].type", "unknown effect 'time_dleay'", "did you mean 'time_delay'"],
     "type: time_dleay"),
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
