"""Documentation meta-tests: README covers the CLI and the schema, the API is documented.

Like sqlite-utils' tests/test_docs.py (every command and option in the docs)
and python-control's docstrings_test.py (every public parameter documented).
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import re

import pytest
from typer.main import get_command

import fi_design
from fi_design import docs
from fi_design.cli import DEFAULT_COMMAND, app

from conftest import ROOT

README = ROOT / "README.md"
COMMANDS = get_command(app).commands  # type: ignore[attr-defined]


@pytest.fixture(scope="module")
def readme() -> str:
    return README.read_text(encoding="utf-8")


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_documented(readme, name):
    if name == DEFAULT_COMMAND:
        assert "fi-design SPEC.yaml" in readme or f"fi-design {name}" in readme
    else:
        assert f"fi-design {name}" in readme, f"`fi-design {name}` is not described in README.md"


@pytest.mark.parametrize("name,option", sorted(
    (name, opt) for name, cmd in COMMANDS.items() for p in cmd.params
    for opt in getattr(p, "opts", []) if opt.startswith("--")))
def test_every_option_documented(readme, name, option):
    assert option in readme, f"option {option} of `fi-design {name}` is not in README.md"


def test_group_options_documented(readme):
    for opt in ("--version", "--debug", "FI_DESIGN_DEBUG"):
        assert opt in readme


def test_exit_codes_documented(readme):
    section = readme.lower()
    assert "exit code" in section
    for code in ("0", "1", "2"):
        assert re.search(rf"\|\s*`?{code}`?\s*\|", readme), f"exit code {code} missing"


@pytest.mark.parametrize("name", ["README.md", "docs/interfaces.md", "docs/effects.md"])
def test_generated_reference_tables_match_the_code(name):
    assert docs.update_readme(README.parent / name, check=True), (
        f"the reference tables in {name} are out of date with the code; regenerate them with "
        f"`python -m fi_design.docs {name}`")


def test_readme_commands_marked(readme):
    for marker in ("<!-- test-command -->", "<!-- run-command -->"):
        assert marker in readme
        after = readme.split(marker, 1)[1].lstrip()
        assert after.startswith("```"), f"{marker} must be followed by a code block"


def test_readme_run_command_succeeds_on_every_run(readme, tmp_path, monkeypatch):
    """The documented first command failed when run a second time: the report existed."""
    import shlex

    from typer.testing import CliRunner

    block = readme.split("<!-- run-command -->", 1)[1].split("```sh\n", 1)[1].split("```")[0]
    command = shlex.split(block.strip().split("&&")[-1])
    assert command[0].endswith("fi-design")
    args = [str(ROOT / a) if a.startswith("examples/") else a for a in command[1:]]
    monkeypatch.chdir(tmp_path)
    for run in (1, 2):
        r = CliRunner().invoke(app, args)
        assert r.exit_code == 0, (run, r.output)
    assert (tmp_path / "report.html").is_file()


#: Files allowed to cite the developers' design document: none.
_CITING_ELSEWHERE: set[str] = set()


def test_the_documentation_stands_alone():
    """README, docs/, docstrings, templates and --help cited DESIGN.md, which a user does not
    have; the project's own pages (docs/model.md, effects.md, interfaces.md) say it."""
    from typer.testing import CliRunner

    files = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")),
             *sorted((ROOT / "fi_design").rglob("*.py")),
             *sorted((ROOT / "fi_design").rglob("*.yaml")),
             *sorted((ROOT / "templates").glob("*")), *sorted((ROOT / "examples").glob("*"))]
    citing = [str(f.relative_to(ROOT)) for f in files if f.is_file()
              and "DESIGN.md" in f.read_text(encoding="utf-8", errors="replace")]
    assert set(citing) <= _CITING_ELSEWHERE, citing
    for page in ("model.md", "effects.md", "interfaces.md"):
        assert f"docs/{page}" in (ROOT / "README.md").read_text(encoding="utf-8")
    for name in [None] + sorted(get_command(app).commands):
        r = CliRunner().invoke(app, ([name] if name else []) + ["--help"],
                               env={"COLUMNS": "200"})
        assert r.exit_code == 0 and "DESIGN.md" not in r.output, (name, r.output)


def test_readme_python_example_runs(readme, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", readme, flags=re.DOTALL)
    assert blocks, "README.md should show the library API in a ```python block"
    monkeypatch.chdir(ROOT)
    for code in blocks:
        exec(compile(code, "README.md", "exec"), {"__name__": "readme_example"})


# --------------------------------------------------------------------------- docstrings

_SECTION = re.compile(r"^\s*(Parameters|Attributes)\s*\n\s*-{3,}\s*$", re.MULTILINE)
_HEADER = re.compile(r"^\s*[A-Z][A-Za-z ]+\n\s*-{3,}\s*$", re.MULTILINE)


def documented_names(doc: str, section: str = "Parameters") -> set[str]:
    """Names listed in a numpydoc section (``name : type`` or ``a, b : type``)."""
    names: set[str] = set()
    for m in _SECTION.finditer(doc):
        if m.group(1) != section:
            continue
        body = doc[m.end():]
        nxt = _HEADER.search(body)
        body = body[: nxt.start()] if nxt else body
        lines = body.splitlines()
        indent = min((len(ln) - len(ln.lstrip()) for ln in lines if ln.strip()), default=0)
        for ln in lines:
            if ln.strip() and len(ln) - len(ln.lstrip()) == indent:
                head = ln.strip().split(" : ")[0].rstrip(":")
                names.update(n.strip().lstrip("*") for n in head.split(","))
    return names


def _public_objects():
    for name in sorted(fi_design._API):
        yield name, fi_design._API[name]


@pytest.mark.parametrize("name,module", list(_public_objects()))
def test_public_api_documented(name, module):
    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name == module:
            pytest.skip(f"{module} is not implemented yet (public name {name!r} reserved)")
        raise
    obj = getattr(mod, name, None)
    if obj is None:
        pytest.skip(f"{module}.{name} is not implemented yet")
    doc = inspect.getdoc(obj) or ""
    assert doc.strip(), f"fi_design.{name} has no docstring"
    if inspect.isfunction(obj):
        params = [p for p, v in inspect.signature(obj).parameters.items()
                  if p not in ("self", "cls")]
        missing = set(params) - documented_names(doc)
        assert not missing, f"fi_design.{name}: parameters {sorted(missing)} not documented"
        assert "Returns" in doc or "Yields" in doc, f"fi_design.{name}: no Returns section"
    elif dataclasses.is_dataclass(obj):
        fields = {f.name for f in dataclasses.fields(obj) if f.repr}
        missing = fields - documented_names(doc, "Attributes")
        assert not missing, f"fi_design.{name}: fields {sorted(missing)} not in Attributes"
    elif isinstance(obj, type) and issubclass(obj, Exception):
        own_init = obj.__dict__.get("__init__")
        if own_init is not None:
            params = [p for p in inspect.signature(own_init).parameters if p != "self"]
            missing = set(params) - documented_names(doc)
            assert not missing, f"fi_design.{name}: parameters {sorted(missing)} not documented"


def test_documented_names_parser():
    doc = """Summary.

    Parameters
    ----------
    a : float
        First [m].
    b, c : int, optional
        More.
    **kwargs
        Rest.

    Returns
    -------
    x : float
    """
    assert documented_names(inspect.cleandoc(doc)) == {"a", "b", "c", "kwargs"}
