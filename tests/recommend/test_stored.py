"""The design search's results kept on disk (fi_design.recommend.stored): what keys an entry,
what reads it back, and what never fails the search.

The search itself is replaced here by a stand-in that counts its calls (the real search and its
result read back are compared in test_recommend.py, the commands sharing an entry in
tests/cli/test_cli.py): these tests are about the store, not about what the search finds.
"""

from __future__ import annotations

import importlib
import logging
import pickle
from dataclasses import replace

import pytest

from fi_design.errors import ArgumentError
from fi_design.recommend import recommend
from fi_design.recommend.stored import SearchStore, open_store, search_key
from fi_design.results.recommend import DesignCandidate, RecommendResult

from conftest import variant

search = importlib.import_module("fi_design.recommend.search")  # the module, not the function


def _result(spec) -> RecommendResult:
    """A small search result (what the stand-in search returns)."""
    d = DesignCandidate(stroke=9e-4, stiffness=4400.0, damping=None, crossover=10.6,
                        status="feasible", length=0.06, width=0.0279, thickness=4.5e-4,
                        hunting_free_from=7.5, hunting_margin=1.41)
    return RecommendResult(
        spec=spec, feasible=True, design=d, binding=("k_max",), violates=(), advice="build it",
        flexure=None, least_change=None, stage_hunting=None, robustness=None, reserves=(),
        forces=None, margins={"hunting_margin": 1.41}, pareto=(), strokes=(9e-4,),
        stiffnesses=(4400.0,), candidates=(d,), spec_design={"stroke": 3e-4},
        crossover_limit="the stage tilt", assumptions=(), rule=True, evaluations=7,
        wall_time=12.5)


@pytest.fixture
def searches(monkeypatch):
    """The searches run (the models searched), the search a stand-in that records them."""
    runs = []

    def searched(model, executor, say, start):
        runs.append(model)
        return _result(model.spec)

    monkeypatch.setattr(search, "_searched", searched)
    return runs


def test_a_second_search_of_the_spec_is_read_back_as_it_was_computed(paper_spec, tmp_path,
                                                                     searches):
    said = []
    first = recommend(paper_spec, cache=tmp_path)
    again = recommend(paper_spec, cache=tmp_path, progress=said.append)
    assert len(searches) == 1
    entry = tmp_path / f"{search_key(paper_spec)}.pickle"
    assert first.from_cache is None and again.from_cache == str(entry)
    assert said == [f"the design search: from the cache ({tmp_path})"]
    assert again.spec is paper_spec                          # the caller's spec, not a copy
    # the result and its provenance as computed: the wall time is the run's that computed it
    assert again.wall_time == 12.5 and again.evaluations == 7
    assert again.fi_design_source == first.fi_design_source
    data, computed = again.to_dict(), first.to_dict()
    assert data.pop("from_cache") == str(entry) and computed.pop("from_cache") is None
    assert data == computed
    assert [p.name for p in tmp_path.iterdir()] == [entry.name]    # no temporary file left


def test_without_a_cache_nothing_is_read_or_written(paper_spec, tmp_path, searches,
                                                    monkeypatch):
    monkeypatch.setenv("FI_DESIGN_CACHE_DIR", str(tmp_path))
    for cache in (None, False):
        assert recommend(paper_spec, cache=cache).from_cache is None
    assert recommend(paper_spec).from_cache is None              # the library's default: none
    assert len(searches) == 3 and list(tmp_path.iterdir()) == []
    # True: the user cache folder, under FI_DESIGN_CACHE_DIR here
    recommend(paper_spec, cache=True)
    assert recommend(paper_spec, cache=True).from_cache is not None and len(searches) == 4
    assert [p.name for p in (tmp_path / "recommend").iterdir()] == \
        [f"{search_key(paper_spec)}.pickle"]


def test_another_spec_or_other_code_is_another_entry(paper_spec, paper_spec_path, tmp_path,
                                                     searches, monkeypatch):
    from fi_design.spec.file import load_spec

    key = search_key(paper_spec)
    other = variant(paper_spec, **{"friction.static": "4.2 N"})
    assert search_key(other) != key
    recommend(paper_spec, cache=tmp_path)
    assert recommend(other, cache=tmp_path).from_cache is None and len(searches) == 2
    # the same values written in other units: the least change is worded in the file's units
    metres = variant(paper_spec, **{"isolator.stroke": "0.0003 m"})
    assert metres.content_sha256() == paper_spec.content_sha256()
    assert search_key(metres) != key
    # comments and layout alone change nothing
    text = paper_spec_path.read_text(encoding="utf-8")
    commented = tmp_path / "commented.yaml"
    commented.write_text("# another comment\n" + text.replace("# Fs", "# the static force"),
                         encoding="utf-8")
    assert search_key(load_spec(commented)) == key
    # the code: an edit of the package's source, another version, other libraries
    studies_cache = importlib.import_module("fi_design.studies.cache")
    stored = importlib.import_module("fi_design.recommend.stored")
    monkeypatch.setattr(studies_cache, "_CODE_DIGEST", "0" * 64)
    assert search_key(paper_spec) != key
    monkeypatch.undo()
    assert search_key(paper_spec) == key
    import fi_design

    monkeypatch.setattr(fi_design, "__version__", "0.0.0-other")
    assert search_key(paper_spec) != key
    monkeypatch.undo()
    monkeypatch.setattr(stored, "_environment", lambda: (("numpy", "0.1"),))
    assert search_key(paper_spec) != key


@pytest.mark.parametrize("damage", ["garbage", "cut short", "another object", "another key"])
def test_an_entry_that_cannot_be_read_is_computed_again(paper_spec, tmp_path, searches, damage,
                                                        caplog):
    store = SearchStore(tmp_path)
    entry = store.entry(paper_spec)
    good = pickle.dumps({"key": entry.stem, "result": replace(_result(None), spec=None)})
    entry.write_bytes({"garbage": b"\x00not a pickle at all",
                       "cut short": good[:len(good) // 2],
                       "another object": pickle.dumps(["a", "list"]),
                       "another key": good.replace(entry.stem.encode(), b"0" * 64)}[damage])
    with caplog.at_level(logging.WARNING, logger="fi_design.recommend.stored"):
        result = recommend(paper_spec, cache=tmp_path)
    assert result.from_cache is None and len(searches) == 1
    assert "runs again" in caplog.text and str(entry) in caplog.text
    # the entry computed again replaced the damaged one, and reads back
    assert recommend(paper_spec, cache=tmp_path).from_cache == str(entry) and len(searches) == 1


def test_a_folder_that_cannot_be_written_costs_the_entry_not_the_search(paper_spec, tmp_path,
                                                                        searches, caplog):
    blocked = tmp_path / "a file"
    blocked.write_text("not a folder")
    store = SearchStore(blocked / "recommend")  # a path into a file is refused up front
    with caplog.at_level(logging.WARNING, logger="fi_design.recommend.stored"):
        result = recommend(paper_spec, cache=store)
    assert result.advice == "build it" and result.from_cache is None
    assert "was not cached" in caplog.text
    assert recommend(paper_spec, cache=store).from_cache is None
    assert len(searches) == 2 and blocked.read_text() == "not a folder"


def test_a_run_that_was_interrupted_stores_nothing(paper_spec, tmp_path, monkeypatch):
    """A Ctrl-C swallowed on its way (a finalizer, a C callback) may have cut the search short:
    its result is returned to the caller, who stops, but never kept for the next run."""
    from fi_design import interrupts

    store = SearchStore(tmp_path)
    monkeypatch.setattr(interrupts, "received", lambda: (2,))
    assert store.put(paper_spec, _result(paper_spec)) is None
    assert list(tmp_path.iterdir()) == []
    monkeypatch.undo()
    assert store.put(paper_spec, _result(paper_spec)) == store.entry(paper_spec)
    assert store.get(paper_spec).advice == "build it"


def test_the_cache_argument_takes_a_store_a_folder_true_or_nothing(tmp_path, monkeypatch):
    monkeypatch.setenv("FI_DESIGN_CACHE_DIR", str(tmp_path / "root"))
    store = SearchStore(tmp_path)
    assert open_store(store) is store
    assert open_store(tmp_path).directory == tmp_path
    assert open_store(str(tmp_path)).directory == tmp_path
    assert open_store(True).directory == tmp_path / "root" / "recommend"
    assert open_store(None) is None and open_store(False) is None
    # a file, or a path into one, is no folder: refused, not logged and searched anyway
    (tmp_path / "f.yaml").write_text("a file")
    for wrong in (tmp_path / "f.yaml", str(tmp_path / "f.yaml" / "sub")):
        with pytest.raises(ArgumentError, match="cache must be a folder"):
            open_store(wrong)
    with pytest.raises(ArgumentError, match="a folder's path or a SearchStore, got int 5"):
        open_store(5)
