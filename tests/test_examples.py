"""Every example runs: examples/*.py as scripts, examples/*.yaml and the init template load."""

from __future__ import annotations

import subprocess
import sys

import pytest

from fi_design import load_spec

from conftest import EXAMPLES, ROOT

SCRIPTS = sorted(EXAMPLES.glob("*.py"))
SPECS = sorted(EXAMPLES.glob("*.yaml"))


def test_examples_exist():
    assert SCRIPTS and SPECS


@pytest.mark.parametrize("spec", SPECS, ids=[p.name for p in SPECS])
def test_example_spec_loads(spec):
    loaded = load_spec(spec)
    assert loaded.name


def test_init_template_loads():
    loaded = load_spec(ROOT / "fi_design" / "example_spec.yaml")
    assert loaded.has_isolator


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.name for p in SCRIPTS])
def test_example_script_runs(script, tmp_path):
    p = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                       timeout=600, cwd=tmp_path)
    assert p.returncode == 0, p.stdout + p.stderr
    assert p.stdout.strip(), "an example should print what it computed"


def test_the_trace_script_keeps_an_existing_file(tmp_path):
    """examples/make_measured_trace.py OUT replaced OUT (a spec, a user's record) without a
    word; it now keeps it unless --force is given."""
    out = tmp_path / "mine.csv"
    out.write_text("a user's record\n")
    p = subprocess.run([sys.executable, str(EXAMPLES / "make_measured_trace.py"), str(out)],
                       capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert p.returncode != 0 and "file exists; give --force" in p.stderr, p.stderr
    assert out.read_text() == "a user's record\n"
