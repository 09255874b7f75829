"""The command line through typer's CliRunner, plus the installed entry point."""

from __future__ import annotations

import functools
import json
import os
import shutil
import subprocess
import sys

import pytest
from typer.testing import CliRunner

from fi_design import __version__
from fi_design.cli.app import app

from conftest import BIN, ROOT, sharing_designs

runner = CliRunner()

#: The JSON contract of `fi-design SPEC --json` (docs/interfaces.md and the guideline).
CONTRACT = {
    "friction_gap": ("gap", "threshold", "hunting_risk"),
    "pid": ("drive", "rule", "source"),
    "crossover": ("desired", "achievable", "limited_by", "cases"),
    "stiffness": ("maximum", "chosen"),
}
TOP_KEYS = ("flexure", "checks", "fi_design_version", "spec_sha256")


@pytest.fixture(scope="module")
def design_run(tmp_path_factory, paper_spec_path):
    """One default-command run on the paper spec with --json (shared: the design takes a while;
    the design and its search are those of the session when computed already)."""
    out = tmp_path_factory.mktemp("design") / "result.json"
    with sharing_designs():
        result = runner.invoke(app, [str(paper_spec_path), "--json", str(out)])
    return result, out


def test_default_command_prints_summary(design_run):
    result, _ = design_run
    assert result.exit_code == 0, result.output
    out = result.stdout
    for word in ("Checks", "PID gains", "kp [N/m]", "Conclusion"):
        assert word in out
    assert any(s in out for s in ("PASS", "FAIL", "WARN", "INFO"))
    assert "Traceback" not in result.output


def test_json_contract(design_run, paper_spec_path):
    result, out = design_run
    assert result.exit_code == 0, result.output
    data = json.loads(out.read_text())
    for section, keys in CONTRACT.items():
        assert section in data, section
        for key in keys:
            assert key in data[section], f"{section}.{key}"
    for key in TOP_KEYS:
        assert key in data, key
    assert isinstance(data["crossover"]["cases"], list)
    drive = data["pid"]["drive"]  # the one gain set a drive takes, frequencies in Hz
    assert {"kp", "ki", "kd", "roll_off", "filters", "units"} <= set(drive)
    assert drive["units"]["roll_off"] == "Hz" and data["pid"]["rule"]["tuning_mass"] == 2.0
    assert data["fi_design_version"] == __version__
    import hashlib

    assert data["spec_sha256"] == hashlib.sha256(paper_spec_path.read_bytes()).hexdigest()
    for check in data["checks"]:
        assert {"name", "passed", "value", "limit", "unit", "message", "status"} <= set(check)
    # no temporary files left next to the output
    assert sorted(p.name for p in out.parent.iterdir()) == ["result.json"]


def test_the_design_command_and_recommend_share_the_search_in_the_cache(
        tmp_path, monkeypatch, caplog, design_run, paper_spec_path):
    """The design command on a failing spec keeps its design search in the result cache; its
    next step (`fi-design recommend`) and the same command again read it back, their JSON
    that of the search computed; --no-cache neither reads nor writes it; a damaged entry is
    computed again, a cache that cannot be written is a warning. The design and the search are
    the session's (computed once, :func:`shared`), the search counted where it runs."""
    import importlib
    import logging
    import pickle

    from fi_design.guideline import evaluate as guideline

    from conftest import design_options, shared

    search = importlib.import_module("fi_design.recommend.search")
    real_search, real_design = search._searched, guideline.evaluate
    runs = []

    def searched(model, executor, say, start):
        runs.append(model.spec.name)
        return shared("recommend", model.spec, lambda: real_search(model, executor, say, start))

    @functools.wraps(real_design)
    def evaluate(spec, *, confirm=True, executor=None, progress=None, **kwargs):
        return shared("design", spec, lambda: real_design(
            spec, confirm=confirm, executor=executor, progress=progress, **kwargs),
            *design_options(confirm, kwargs))

    monkeypatch.setattr(search, "_searched", searched)
    monkeypatch.setattr(guideline, "evaluate", evaluate)
    monkeypatch.setenv("FI_DESIGN_CACHE_DIR", str(tmp_path / "cache"))
    folder, spec = tmp_path / "cache" / "recommend", str(paper_spec_path)

    def run(*args):  # the output, and the output without line breaks (a long path folds)
        r = runner.invoke(app, [*args, "--force"])
        assert r.exit_code == 0, r.output
        return " ".join(r.stdout.split()), "".join(r.stdout.split())

    def read(name):
        return json.loads((tmp_path / name).read_text())

    # the design command on a failing spec searches and keeps the search
    out, _ = run(spec, "--json", str(tmp_path / "a.json"))
    assert len(runs) == 1 and "from the cache" not in out
    [entry] = folder.iterdir()
    kept = (entry.stat().st_ino, entry.stat().st_mtime_ns, entry.read_bytes())
    # its next step reads it back, and so does the same command again
    out, joined = run("recommend", spec, "--json", str(tmp_path / "r.json"), "-j", "1")
    assert len(runs) == 1 and "The design search: from the cache (" in out
    assert f"({folder})" in joined
    out, joined = run(spec, "--json", str(tmp_path / "b.json"))
    assert len(runs) == 1 and "The design search: from the cache (" in out
    assert f"({folder})" in joined
    computed, again, alone = read("a.json"), read("b.json"), read("r.json")
    assert computed["recommendation"].pop("from_cache") is None
    assert again["recommendation"].pop("from_cache") == str(entry)
    assert again == computed
    assert alone.pop("from_cache") == str(entry)
    assert alone == {k: v for k, v in computed["recommendation"].items() if k != "text"}
    # --no-cache: the search runs, the entry is neither read nor written
    run(spec, "--json", str(tmp_path / "c.json"), "--no-cache")
    out, _ = run("recommend", spec, "-j", "1", "--no-cache")
    assert len(runs) == 3 and "from the cache" not in out
    assert list(folder.iterdir()) == [entry]
    assert (entry.stat().st_ino, entry.stat().st_mtime_ns, entry.read_bytes()) == kept
    # a damaged entry is computed again and replaced, never an error
    entry.write_bytes(b"not a pickle")
    with caplog.at_level(logging.WARNING, logger="fi_design.recommend.stored"):
        out, _ = run("recommend", spec, "-j", "1")
    assert len(runs) == 4 and "from the cache" not in out and "runs again" in caplog.text
    assert pickle.loads(entry.read_bytes())["key"] == entry.stem
    # a cache that cannot be written: a warning; the command does its work
    blocked = tmp_path / "blocked"
    blocked.write_text("")
    monkeypatch.setenv("FI_DESIGN_CACHE_DIR", str(blocked))
    with caplog.at_level(logging.WARNING, logger="fi_design.recommend.stored"):
        run("recommend", spec, "--json", str(tmp_path / "d.json"), "-j", "1")
    assert len(runs) == 5 and "was not cached" in caplog.text
    assert read("d.json") == {**alone, "from_cache": None}


def test_options_before_spec_and_explicit_command(tmp_path, paper_spec_path, monkeypatch):
    calls = []
    _fake_design(monkeypatch, calls)
    out = tmp_path / "a.json"
    r = runner.invoke(app, ["--json", str(out), str(paper_spec_path)])
    assert r.exit_code == 0, r.output
    assert out.exists()
    r = runner.invoke(app, ["design", str(paper_spec_path)])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["--debug", str(paper_spec_path)])
    assert r.exit_code == 0, r.output
    assert len(calls) == 3


def test_refuses_existing_output_without_force(tmp_path, paper_spec_path, monkeypatch):
    calls = []
    _fake_design(monkeypatch, calls)
    out = tmp_path / "out.json"
    out.write_text("old")
    r = runner.invoke(app, [str(paper_spec_path), "--json", str(out)])
    assert r.exit_code == 2
    assert "exists" in r.stderr and "--force" in r.stderr
    assert out.read_text() == "old"
    assert calls == [], "the output must be refused before the work starts"
    r = runner.invoke(app, [str(paper_spec_path), "--json", str(out), "--force"])
    assert r.exit_code == 0, r.output
    assert json.loads(out.read_text())["fi_design_version"] == __version__


def test_refuses_spec_as_output_even_with_force(tmp_path, paper_spec_path):
    spec = tmp_path / "spec.json"  # YAML is read whatever the suffix
    shutil.copy(paper_spec_path, spec)
    before = spec.read_bytes()
    hard = tmp_path / "hard.json"
    os.link(spec, hard)
    soft = tmp_path / "soft.json"
    soft.symlink_to(spec)
    for target in (spec, hard, soft):
        r = runner.invoke(app, [str(spec), "--json", str(target), "--force"])
        assert r.exit_code == 2, (target, r.output)
        assert "refusing to overwrite the input" in r.stderr
    r = runner.invoke(app, [str(paper_spec_path), "--json", str(paper_spec_path), "--force"])
    assert r.exit_code == 2
    assert spec.read_bytes() == before


def test_wrong_extension_and_missing_directory(tmp_path, paper_spec_path):
    r = runner.invoke(app, [str(paper_spec_path), "--json", str(tmp_path / "out.txt")])
    assert r.exit_code == 2 and ".json" in r.stderr
    r = runner.invoke(app, [str(paper_spec_path), "--json", str(tmp_path / "nope" / "o.json")])
    assert r.exit_code == 2 and "does not exist" in r.stderr


def test_internal_error_exit_1_without_traceback(paper_spec_path, monkeypatch):
    import fi_design.guideline.evaluate

    def boom(spec, **kwargs):
        raise RuntimeError("kaboom")

    monkeypatch.setattr(fi_design.guideline.evaluate, "evaluate", boom)
    monkeypatch.delenv("FI_DESIGN_DEBUG", raising=False)
    r = runner.invoke(app, [str(paper_spec_path)])
    assert r.exit_code == 1
    assert "internal error: RuntimeError: kaboom" in r.stderr
    assert "--debug" in r.stderr and "FI_DESIGN_DEBUG" in r.stderr
    assert "Traceback" not in r.output
    r = runner.invoke(app, [str(paper_spec_path), "--debug"])
    assert r.exit_code == 1
    assert "Traceback" in r.stderr
    r = runner.invoke(app, [str(paper_spec_path)], env={"FI_DESIGN_DEBUG": "1"})
    assert r.exit_code == 1
    assert "Traceback" in r.stderr


def test_schema_prints_json_schema():
    r = runner.invoke(app, ["schema"])
    assert r.exit_code == 0, r.output
    schema = json.loads(r.stdout)
    assert schema["type"] == "object"
    assert schema["additionalProperties"] is False
    for key in ("stage", "cart", "friction", "controller", "motion"):
        assert key in schema["required"]
    assert {"isolator", "requirements", "effects"} <= set(schema["properties"])
    for name, sub in schema["$defs"].items():  # every reference resolves
        assert sub.get("type") == "object", name
    refs = [p for p in _walk_refs(schema)]
    assert refs and all(r.split("/")[-1] in schema["$defs"] for r in refs)


def test_schema_markdown():
    r = runner.invoke(app, ["schema", "--markdown"])
    assert r.exit_code == 0
    assert "| `friction.static` | N | required |" in r.stdout


def test_init_writes_a_spec_that_loads(tmp_path, monkeypatch):
    from fi_design import load_spec

    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, ["init"])
    assert r.exit_code == 0, r.output
    spec = load_spec(tmp_path / "bearing.yaml")
    assert spec.has_isolator
    r = runner.invoke(app, ["init", "other.yml"])
    assert r.exit_code == 0, r.output
    assert load_spec(tmp_path / "other.yml").friction.static == 4.0


def test_init_refuses_to_overwrite(tmp_path):
    path = tmp_path / "mine.yaml"
    path.write_text("name: mine\n")
    r = runner.invoke(app, ["init", str(path)])
    assert r.exit_code == 2
    assert "exists" in r.stderr
    assert path.read_text() == "name: mine\n"
    r = runner.invoke(app, ["init", str(path), "--force"])
    assert r.exit_code == 0
    assert "friction" in path.read_text()
    r = runner.invoke(app, ["init", str(tmp_path / "x.json")])
    assert r.exit_code == 2 and ".yaml" in r.stderr


def test_version_and_help():
    r = runner.invoke(app, ["--version"])
    assert r.exit_code == 0 and r.stdout.strip() == f"fi-design {__version__}"
    r = runner.invoke(app, ["--help"])
    assert r.exit_code == 0
    for name in ("design", "schema", "init"):
        assert name in r.stdout
    r = runner.invoke(app, [])
    assert "Usage" in r.output


def test_mistyped_command_gets_a_hint(paper_spec_path):
    r = runner.invoke(app, ["shcema"])
    assert r.exit_code == 2
    assert "no such command 'shcema'; did you mean 'schema'?" in r.stderr
    # with the command's arguments after it: not design's "unexpected extra argument"
    r = runner.invoke(app, ["recomend", str(paper_spec_path)])
    assert r.exit_code == 2 and "extra argument" not in r.stderr
    assert "no such command 'recomend'; did you mean 'recommend'?" in r.stderr
    # a spec argument of another command still gets its hint
    r = runner.invoke(app, ["sweep", "recomend", "--x", "controller.crossover=1,2"])
    assert r.exit_code == 2 and "did you mean 'fi-design recommend'" in r.stderr


def test_a_spec_and_a_record_in_either_command_order(tmp_path):
    """identify takes the spec first as reconcile does (it was 'Got unexpected extra
    argument'); a record where a spec belongs, or a spec where a record belongs, says so."""
    from conftest import EXAMPLES

    spec, record = str(EXAMPLES / "measured_stage.yaml"), str(EXAMPLES / "measured_trace.csv")
    out = tmp_path / "id.json"
    r = runner.invoke(app, ["identify", spec, record, "--json", str(out)])
    assert r.exit_code == 0, r.output
    notes = json.loads(out.read_text())["notes"]  # the spec's joint separates the two masses
    assert any("k = 6667 N/m from the spec" in n for n in notes), notes
    for args in (["identify", record, record], ["identify", spec, record, record],
                 ["identify", "--spec", spec, spec, record]):
        r = runner.invoke(app, args)
        assert r.exit_code == 2 and "one record only" in r.stderr, r.output
    r = runner.invoke(app, ["identify", spec])
    assert r.exit_code == 2
    assert "this is a YAML file (a spec?), not a measured record" in r.stderr, r.stderr
    r = runner.invoke(app, ["reconcile", record, spec])
    assert r.exit_code == 2
    assert "this is a CSV file (a measured record?), not a spec" in " ".join(r.stderr.split())


def test_installed_entry_point(tmp_path, paper_spec_path):
    """The console script in a process of its own, simulation included; the design search
    (--no-recommend here) runs in this file's CliRunner run and in test_console's."""
    exe = BIN / "fi-design"
    assert exe.exists(), f"{exe}: the package is not installed (pip install -e .)"
    out = tmp_path / "r.json"
    p = subprocess.run([str(exe), str(paper_spec_path), "--json", str(out), "--no-recommend"],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "Conclusion" in p.stdout
    assert json.loads(out.read_text())["spec_sha256"]
    p = subprocess.run([str(exe), str(tmp_path / "missing.yaml")], capture_output=True,
                       text=True, timeout=60)
    assert p.returncode == 2
    assert "no such file" in p.stderr and "Traceback" not in p.stderr


def test_a_reader_that_stops_reading_leaves_the_files_whole(tmp_path, paper_spec_path):
    """``fi-design SPEC --json r.json | head -1``: the closed pipe raised BrokenPipeError at
    the console's next print, the run ended with exit 1 and wrote no r.json. The console is
    a summary; the run writes its files and ends as it would have."""
    out = tmp_path / "r.json"
    with subprocess.Popen([str(BIN / "fi-design"), str(paper_spec_path), "--no-simulation",
                           "--no-recommend", "--json", str(out)], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, cwd=tmp_path) as p:
        assert p.stdout.readline()  # the heading; then the reader leaves
        p.stdout.close()
        code = p.wait(timeout=300)
        err = p.stderr.read().decode()
    assert code == 0, err
    assert "Traceback" not in err and "error" not in err, err
    assert json.loads(out.read_text())["spec_sha256"]


_FROZEN_AT_EXIT = """\
import atexit, gc, sys
atexit.register(lambda: print("frozen", gc.get_freeze_count(), flush=True))
from fi_design.cli.app import main
sys.argv = ["fi-design"] + sys.argv[1:]
main()
"""


@pytest.mark.parametrize("args,code", [(["--no-simulation", "--json", "r.json"], 0),
                                       (["--json", "r.yaml"], 2)])
def test_the_run_is_frozen_before_the_interpreter_exits(tmp_path, paper_spec_path, args, code):
    """The interpreter's last garbage collection over the whole heap (0.35 s after a design
    run, 0.6 s after a PDF report) is skipped: the run's objects are frozen when the command
    has ended, well or not, and its output is whole."""
    p = subprocess.run([sys.executable, "-c", _FROZEN_AT_EXIT, str(paper_spec_path), *args],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert p.returncode == code, p.stderr
    frozen = [int(line.split()[1]) for line in p.stdout.splitlines()
              if line.startswith("frozen ")]
    assert frozen and frozen[0] > 10_000, p.stdout
    if code == 0:
        assert json.loads((tmp_path / "r.json").read_text())["spec_sha256"]


_REPORT_GARBAGE = """\
import atexit, gc, json, sys
import fi_design.report as report
seen = {}
real = report.render_report
def spy(*args, **kwargs):
    seen["during"] = [gc.isenabled(), gc.get_freeze_count()]
    out = real(*args, **kwargs)
    seen["written"] = out.stat().st_size
    return out
report.render_report = spy
def after():
    seen["after"] = [gc.isenabled(), gc.get_freeze_count()]
atexit.register(lambda: print("seen", json.dumps(seen), flush=True))
import fi_design.cli.parts as parts
real_freeze = parts._spare_the_last_collection
def at_end():
    after()
    real_freeze()
parts._spare_the_last_collection = at_end
from fi_design.cli.app import main
sys.argv = ["fi-design"] + sys.argv[1:]
main()
"""


def test_the_report_garbage_is_frozen_not_collected(tmp_path, paper_spec_path):
    """In the console script's process, the report is made with the cyclic collector paused
    and what it built is frozen after it, not collected (the command ends with it): the
    collector is enabled again, the report whole. A caller of the same steps in its own
    process (CliRunner) keeps its collector as it was."""
    import json

    p = subprocess.run([sys.executable, "-c", _REPORT_GARBAGE, str(paper_spec_path),
                        "--no-simulation", "--report", "r.html"],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path, check=False)
    assert p.returncode == 0, p.stderr
    seen = json.loads(next(line[5:] for line in p.stdout.splitlines()
                           if line.startswith("seen ")))
    assert seen["during"] == [False, 0], seen
    assert seen["after"][0] is True and seen["after"][1] > 10_000, seen
    assert seen["written"] > 10_000 and "</html>" in (tmp_path / "r.html").read_text()

    import gc

    from fi_design import report

    states = []
    real = report.render_report

    def spy(*args, **kwargs):
        states.append((gc.isenabled(), gc.get_freeze_count()))
        return real(*args, **kwargs)

    before = gc.get_freeze_count()
    try:
        report.render_report = spy
        r = runner.invoke(app, [str(paper_spec_path), "--no-simulation", "--report",
                                str(tmp_path / "in.html")])
    finally:
        report.render_report = real
    assert r.exit_code == 0, r.output
    assert states == [(True, before)] and gc.isenabled() and gc.get_freeze_count() == before


def test_python_dash_m(tmp_path):
    p = subprocess.run([sys.executable, "-m", "fi_design", "--version"], capture_output=True,
                       text=True, timeout=60, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == f"fi-design {__version__}"
    p = subprocess.run([sys.executable, "-m", "fi_design", "init", str(tmp_path / "b.yaml")],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "b.yaml").exists()


# --------------------------------------------------------------------------- helpers


def _walk_refs(node):
    if isinstance(node, dict):
        for k, v in node.items():
            if k == "$ref":
                yield v
            else:
                yield from _walk_refs(v)
    elif isinstance(node, list):
        for v in node:
            yield from _walk_refs(v)


class _FakeResult:
    checks = ()
    conclusion = "fake"
    warnings = ()

    isolator_advice = None

    def to_dict(self):
        return {"fi_design_version": __version__}



def _fake_design(monkeypatch, calls):
    """Replace the (slow) design and simulations by stubs: these tests are about plumbing."""
    import fi_design.cli.app
    import fi_design.signoff

    def fake(spec, **kwargs):
        calls.append(spec)
        return _FakeResult()

    monkeypatch.setattr(fi_design.signoff, "design", fake)


def test_init_derives_what_it_can_and_names_its_file(tmp_path):
    """init wrote the 2 kg example's bristle damping, stiffness and joint damping as given
    values, which stayed when the user changed the masses; and its header named bearing.yaml
    whatever the file was called."""
    import re

    from fi_design import load_spec
    from fi_design import spec as sp

    path = tmp_path / "stage42.yaml"
    r = runner.invoke(app, ["init", str(path)])
    assert r.exit_code == 0, r.output
    text = path.read_text()
    assert f"fi-design {path}" in text and "bearing.yaml" not in text
    spec = load_spec(path)
    assert spec.friction.bristle_damping is None and spec.isolator.stiffness is None
    assert spec.isolator.damping is None
    heavier = tmp_path / "heavier.yaml"
    heavier.write_text(re.sub(r"mass: 1\.6 kg", "mass: 16 kg", text, count=1))
    big = load_spec(heavier)
    assert sp.bristle_damping(big) == pytest.approx((1e6 * 16.4) ** 0.5)
    assert sp.joint_damping(big) > sp.joint_damping(spec)


@pytest.mark.parametrize("name", [None, "design", "simulate", "schema", "init", "sweep",
                                  "study", "robustness", "reconcile", "identify"])
def test_help_shows_no_type_labels_or_markup(name):
    """--help showed '<bool>' beside every flag, '<path>' beside SPEC.yaml and RST or Markdown
    markup (``window``, `fi-design init`)."""
    import re

    r = runner.invoke(app, ([name] if name else []) + ["--help"], env={"COLUMNS": "200"})
    assert r.exit_code == 0, r.output
    assert not re.search(r"<(bool|path|str|int|float|text|integer)\b[^>]*>", r.output), r.output
    for mark in ("`", ":func:", ":class:", ":mod:"):
        assert mark not in r.output, (mark, r.output)
