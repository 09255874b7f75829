"""One grammar of dotted spec paths: reading, varying and writing a spec accept and refuse alike."""

from __future__ import annotations

import pytest

from fi_design.errors import SpecError
from fi_design.spec.edit import edited_spec_text, written_unit
from fi_design.spec.file import load_spec, value_at, with_values
from fi_design.spec.paths import parse_path, path_text

#: Well-formed paths that name a value of the paper spec, with a value to write there.
GOOD = {
    "friction.static": "2.5 N",
    " friction.static ": "2.5 N",
    "motion.moves[0].distance": "1 mm",
    "effects[type=time_delay].delay": "1 ms",
    "effects[0].delay": "1 ms",
}
#: Malformed paths: the message every reader gives.
BAD = {
    "": "empty spec path",
    "friction..static": "not a valid path element",
    "friction.static]": "not a valid path element",
    "motion.moves[x].distance": "not a list selector",
    "motion.moves[-1].distance": "not a list selector",
    "1friction.static": "not a valid path element",
    "friction.static[": "not a valid path element",
}


@pytest.fixture
def spec_with_effect(paper_spec_path, tmp_path):
    text = paper_spec_path.read_text() + "\neffects: [{type: time_delay, delay: 2 ms}]\n"
    path = tmp_path / "spec.yaml"
    path.write_text(text)
    return load_spec(path)


@pytest.mark.parametrize("path", sorted(GOOD))
def test_good_paths_read_vary_and_write_alike(spec_with_effect, path, tmp_path):
    value = GOOD[path]
    varied = with_values(spec_with_effect, {path: value})
    out = tmp_path / "written.yaml"
    out.write_text(edited_spec_text(spec_with_effect, {path: value}))
    written = load_spec(out)
    assert value_at(written, path) == pytest.approx(value_at(varied, path))
    assert value_at(varied, path) != pytest.approx(value_at(spec_with_effect, path))
    assert path_text(parse_path(path)) == path.strip()


@pytest.mark.parametrize("path", sorted(BAD))
def test_bad_paths_refused_alike(spec_with_effect, path):
    words = BAD[path]
    for use in (lambda: value_at(spec_with_effect, path),
                lambda: with_values(spec_with_effect, {path: 1.0}),
                lambda: edited_spec_text(spec_with_effect, {path: 1.0}),
                lambda: written_unit(spec_with_effect, path)):
        with pytest.raises(SpecError, match=words):
            use()


def test_written_unit_follows_list_selectors(spec_with_effect):
    assert written_unit(spec_with_effect, "effects[type=time_delay].delay") == "ms"
    assert written_unit(spec_with_effect, "effects[0].delay") == "ms"
    assert written_unit(spec_with_effect, "effects[3].delay") is None
