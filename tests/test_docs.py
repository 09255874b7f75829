"""Documentation meta-tests: the generated pages cover the CLI and the schema, the API is
documented, the README and the architecture page say what a newcomer needs.

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
from fi_design.cli.app import DEFAULT_COMMAND, app

from conftest import ROOT

README = ROOT / "README.md"
CLI_PAGE = ROOT / "docs" / "cli.md"
COMMANDS = get_command(app).commands  # type: ignore[attr-defined]


@pytest.fixture(scope="module")
def readme() -> str:
    return README.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def cli_page() -> str:
    return CLI_PAGE.read_text(encoding="utf-8")


def test_the_generated_pages_match_the_code():
    """docs/cli.md is the command-line app as --help gives it, and docs/spec.md and
    docs/effects.md hold the tables of the schema and the catalogue: regenerated, they are
    what the repository holds."""
    from fi_design import docpages

    assert CLI_PAGE.read_text(encoding="utf-8") == docpages.cli_reference(), (
        "docs/cli.md is out of date with the command line; regenerate it with "
        "`python -m fi_design.docpages`")
    assert docpages.update(ROOT, check=True) == []


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_documented(cli_page, readme, name):
    assert f"## fi-design {name}\n" in cli_page, f"`fi-design {name}` is not in docs/cli.md"
    head = "fi-design SPEC.yaml" if name == DEFAULT_COMMAND else f"fi-design {name}"
    assert head in readme, f"`{head}` is not in the README's commands in brief"
    assert COMMANDS[name].help and COMMANDS[name].help.strip(), f"{name} has no help text"


@pytest.mark.parametrize("name,option", sorted(
    (name, opt) for name, cmd in COMMANDS.items() for p in cmd.params
    for opt in getattr(p, "opts", []) if opt.startswith("--")))
def test_every_option_documented(cli_page, name, option):
    """Every option is in its command's section of docs/cli.md, with a help text of its own."""
    section = cli_page.split(f"## fi-design {name}\n", 1)[1].split("\n## ", 1)[0]
    row = next((ln for ln in section.splitlines() if ln.startswith("| `") and
                re.search(rf"(^|[ ,`]){re.escape(option)}([ ,`]|$)", ln.split("|")[1])), None)
    assert row, f"option {option} of `fi-design {name}` is not in docs/cli.md"
    assert row.split("|")[2].strip(), f"option {option} of `fi-design {name}` has no help"


def test_group_options_documented(cli_page):
    for opt in ("--version", "--debug", "FI_DESIGN_DEBUG"):
        assert opt in cli_page


def test_exit_codes_documented(readme):
    commands = (ROOT / "docs" / "commands.md").read_text(encoding="utf-8")
    assert "exit code" in commands.lower() and "exit codes" in readme.lower()
    for code in ("0", "1", "2", "3", "130"):
        assert re.search(rf"\|\s*`?{code}`?[ ,|]", commands), f"exit code {code} missing"


@pytest.mark.parametrize("name", ["docs/spec.md", "docs/effects.md"])
def test_generated_reference_tables_match_the_code(name):
    assert docs.update_readme(README.parent / name, check=True), (
        f"the reference tables in {name} are out of date with the code; regenerate them with "
        f"`python -m fi_design.docs {name}`")


def test_the_spec_table_names_what_a_list_of_values_holds():
    """The table called the sensor's [y, z] offset '[min, max] in m', and a leaf dimension
    (one value or bounds) 'array or None'."""
    kinds = {row.split(" | ")[0].strip("| `"): row.split(" | ")[1]
             for row in docs.spec_table().splitlines() if row.startswith("| `")}
    assert kinds["stage.sensor_offset"] == "pair in m"
    assert kinds["stage.size"] == "3 values in m"
    assert kinds["stage.inertia"] == "3 values in kg m^2"
    assert kinds["isolator.flexure.length"] == "m or [min, max] in m"
    assert kinds["requirements.recommend.stroke"] == "[min, max] in m"
    assert kinds["controller.filters[type=notch].damping"] == "pair of numbers"


def test_readme_commands_marked(readme):
    for marker in ("<!-- test-command -->", "<!-- run-command -->"):
        assert marker in readme
        after = readme.split(marker, 1)[1].lstrip()
        assert after.startswith("```"), f"{marker} must be followed by a code block"


def test_readme_run_command_succeeds_on_every_run(readme, tmp_path, monkeypatch,
                                                  shared_designs):
    """The documented first command failed when run a second time: the report existed.

    Both runs write the report; the design is computed once (:func:`shared_designs`)."""
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
    for page in ("model.md", "effects.md", "interfaces.md", "spec.md", "cli.md",
                 "commands.md", "library.md", "architecture.md"):
        assert f"docs/{page}" in (ROOT / "README.md").read_text(encoding="utf-8")
    for name in [None] + sorted(get_command(app).commands):
        r = CliRunner().invoke(app, ([name] if name else []) + ["--help"],
                               env={"COLUMNS": "200"})
        assert r.exit_code == 0 and "DESIGN.md" not in r.output, (name, r.output)


@pytest.mark.parametrize("page", ["README.md", "docs/library.md", "docs/measured.md",
                                  "docs/paper_reproduction.md"])
def test_python_examples_run(page, monkeypatch, shared_designs):
    """Every ```python block runs; one followed by "prints" and a ```text block prints that
    text (the sweep example promised a boundary in Hz and printed nan)."""
    import contextlib
    import io

    text = (ROOT / page).read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```((?:(?!```python).)*)", text, flags=re.DOTALL)
    assert blocks, f"{page} should show the library API in a ```python block"
    monkeypatch.chdir(ROOT)
    for code, after in blocks:
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(code, page, "exec"), {"__name__": "readme_example"})
        shown = re.match(r"\s*\n[^`]*\bprints\b[^`]*```text\n(.*?)```", after, flags=re.DOTALL)
        if shown:
            assert out.getvalue().strip() == shown.group(1).strip(), out.getvalue()


def test_the_interfaces_page_names_every_command():
    table = (ROOT / "docs" / "interfaces.md").read_text(encoding="utf-8").split(
        "## Commands and exit codes", 1)[1]
    for name in COMMANDS:
        if name in ("design",):
            continue
        assert re.search(rf"`(fi-design )?{name}\b", table), name


def test_the_documented_commands_name_files_that_exist():
    """A documented example named a record that is not in the repository."""
    for page in ("README.md", "docs/commands.md", "docs/measured.md"):
        text = (ROOT / page).read_text(encoding="utf-8")
        for block in re.findall(r"```sh\n(.*?)```", text, flags=re.DOTALL):
            for path in re.findall(r"(?<![\w/])(examples/[\w.-]+)", block):
                assert (ROOT / path).exists(), (page, path)


def test_the_readme_is_what_a_newcomer_needs(readme):
    """The README had grown to 1,200 lines; it says what the tool is, the two commands, the
    commands and the library in brief, hunting as a property of the stage, and links the
    rest."""
    assert len(readme.splitlines()) <= 250
    heads = re.findall(r"^## (.+)$", readme, flags=re.MULTILINE)
    for head in ("Quick start", "The commands in brief", "Hunting as a property of the stage",
                 "The library in brief", "Documentation"):
        assert head in heads, head
    assert "docs/figures/" in readme
    for link in re.findall(r"\]\((docs/[^)#]+)", readme):
        if link not in ("docs/examples.md",):  # written beside this work, merged with it
            assert (ROOT / link).exists(), link


def test_the_architecture_page_names_every_layer():
    """docs/architecture.md draws the layers that import-linter keeps: every module of the
    exhaustive layers contract is named on the page, in the order of the contract."""
    import tomllib

    contracts = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    layers = next(c for c in contracts["tool"]["importlinter"]["contracts"]
                  if c.get("containers") == ["fi_design"] and c["type"] == "layers")["layers"]
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    diagram = page.split("```\n", 2)[1]
    assert len(diagram.splitlines()) <= 12
    # the modules only: no layer names in the left column, no remarks in parentheses
    diagram = "\n".join(re.sub(r"\([^)]*\)", "", ln[15:]) for ln in diagram.splitlines())
    positions = []
    for layer in layers:
        for module in (m.strip() for m in layer.split("|")):
            found = re.search(rf"(?<![\w.]){re.escape(module)}(?![\w.])", diagram)
            assert found, f"{module} is not in the diagram of docs/architecture.md"
            positions.append(found.start())
    assert positions == sorted(positions), "the diagram lists the layers out of order"


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


def test_the_spec_keys_the_pages_name_exist():
    """A page named a spec key the schema no longer has, or described one by what it once did:
    every `section.key` path written in README.md and docs/ is a key of docs/spec.md's
    tables (an index [0] reads as the table's [], a [type=NAME] as written there, a study's
    CSV column, the path and its unit, `controller.crossover_Hz`, as its path)."""
    from fi_design.spec.units import KNOWN_UNITS

    keys = {re.sub(r"\[\d+\]", "[]", row.split(" | ")[0].strip("| `"))
            for row in docs.spec_table().splitlines() if row.startswith("| `")}
    unit = re.compile(r"_(?:%s)$" % "|".join(re.escape(u) for u in KNOWN_UNITS))
    tops = sorted({re.split(r"[.\[]", k)[0] for k in keys})
    path = re.compile(r"`((?:%s)(?:\.[A-Za-z_]\w*|\[[^\]`]*\])+)" % "|".join(tops))
    skipped = ("spec.md", "cli.md", "effects.md", "architecture.md")  # generated; modules
    unknown = []
    for page in [README, *sorted((ROOT / "docs").glob("*.md"))]:
        if page.name in skipped:
            continue
        for m in path.finditer(page.read_text(encoding="utf-8")):
            p = unit.sub("", re.sub(r"\[\d+\]", "[]", m.group(1)))
            if not any(k == p or k.startswith((p + ".", p + "[")) for k in keys):
                unknown.append((page.name, m.group(1)))
    assert not unknown, f"spec paths not in the schema: {sorted(set(unknown))}"
