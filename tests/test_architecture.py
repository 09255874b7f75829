"""Architecture: the import-linter contracts hold, and the light paths stay light."""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys

import pytest

from conftest import ROOT

#: Libraries that take a second or more to import; never needed for --help or `import fi_design`.
HEAVY = ("control", "scipy", "matplotlib", "numba")


def test_import_linter_contracts():
    """`lint-imports` with the contracts in pyproject.toml (layers one way, physics library-free)."""
    code = ("import sys; from importlinter.cli import lint_imports; "
            "sys.exit(lint_imports(no_cache=True, no_logo=True))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                       timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr


def _loaded_after(code: str) -> set[str]:
    probe = (f"import sys, json\n{code}\n"
             "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules})), file=sys.stderr)")
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=60,
                       cwd=ROOT)
    assert p.returncode == 0, p.stderr
    return set(json.loads(p.stderr.strip().splitlines()[-1]))


def test_import_fi_design_is_light():
    loaded = _loaded_after("import fi_design; fi_design.__version__; dir(fi_design)")
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))
    assert "pydantic" not in loaded and "numpy" not in loaded


@pytest.mark.parametrize("argv", [["--help"], ["--version"], ["schema", "--help"],
                                  ["design", "--help"], ["init", "--help"]])
def test_cli_help_is_light(argv):
    code = ("sys.argv = ['fi-design'] + " + repr(argv) + "\n"
            "from fi_design.cli.app import main\n"
            "import contextlib, io\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    try:\n"
            "        main()\n"
            "    except SystemExit as e:\n"
            "        assert e.code in (0, None), e.code\n")
    loaded = _loaded_after(code)
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))


def test_cli_module_imports_no_library_at_top_level():
    loaded = _loaded_after("import fi_design.cli.app")
    assert not loaded & (set(HEAVY) | {"pydantic", "numpy", "pint", "rich"}), sorted(loaded)


def test_public_functions_stay_callable_after_their_modules_are_imported():
    """``fi_design.simulate`` etc. are functions, whatever was imported before."""
    code = ("import fi_design.simulation.run, fi_design.studies, fi_design.reconciliation, "
            "fi_design.guideline.steps, fi_design.report, fi_design.measured\n"
            "import fi_design\n"
            "names = ['simulate', 'sweep', 'robustness', 'reconcile', 'design', 'load_spec',\n"
            "         'load_measurement', 'render_report']\n"
            "bad = [n for n in names if not callable(getattr(fi_design, n))]\n"
            "assert not bad, bad\n")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


#: After ``design()`` or its import: every public name calls what its module defines.
_STABLE = ("import fi_design, importlib\n"
           "from fi_design.errors import ArgumentError\n"
           "try:\n"
           "    fi_design.recommend(42)\n"
           "except ArgumentError as exc:\n"
           "    assert 'spec must be' in str(exc), exc\n"
           "else:\n"
           "    raise AssertionError('recommend accepted a number for a spec')\n"
           "for name, module in fi_design._API.items():\n"
           "    want = importlib.import_module(module)\n"
           "    if name not in fi_design._CALLED_PACKAGES:\n"
           "        want = getattr(want, name)\n"
           "    assert getattr(fi_design, name) is want, name\n"
           "import fi_design.recommend.search as s, fi_design.recommend as r, inspect\n"
           "from fi_design import recommend\n"
           "assert r is recommend is fi_design.recommend and s.recommend is r.recommend\n"
           "assert list(inspect.signature(recommend).parameters)[:2] == ['spec', 'executor']\n")


def _stable_after(code: str) -> None:
    p = subprocess.run([sys.executable, "-c", code + _STABLE], capture_output=True, text=True,
                       cwd=ROOT, timeout=300)
    assert p.returncode == 0, p.stderr


def test_public_names_are_stable_after_their_modules_are_imported():
    """`fi_design.recommend` became the module of that name once `design()` had imported it
    (``from .recommend import recommend``): TypeError, 'module' object is not callable; then,
    kept the function, ``import fi_design.recommend.search as s`` failed ("cannot import name
    'search' from 'recommend'"): the package is now called as the search. And
    `fi_design.report.build_context` needed an explicit import of the subpackage."""
    _stable_after("import fi_design\n"
                  "assert fi_design.report.build_context.__name__ == 'build_context'\n"
                  "spec = fi_design.load_spec('examples/paper_setup.yaml')\n"
                  "from fi_design.recommend import recommend\n"  # what design() runs on a FAIL
                  "import fi_design.recommend\n")


@pytest.mark.slow
def test_recommend_is_callable_after_a_failing_design_run():
    """The issue's case as a user meets it: a design run that fails recommends (about 15 s)."""
    _stable_after("import fi_design, sys\n"
                  "spec = fi_design.load_spec('examples/no_isolator.yaml')\n"
                  "assert fi_design.design(spec).recommendation is not None\n"
                  "assert 'fi_design.recommend' in sys.modules\n")


# --------------------------------------------------------------------------- module sizes


def _lines(path) -> int:
    return len(path.read_text(encoding="utf-8").splitlines())


#: The one module allowed above :data:`MAX_LINES`: the kernel's integrator (one compiled loop).
LONG_MODULES = {"fi_design/kernel/integrator.py"}
MAX_LINES = 800
#: Modules of the presentation packages stay smaller still: one result family each.
MAX_FAMILY_LINES = 600


@pytest.mark.parametrize("package", ["plots", "console"])
def test_presentation_is_a_package_by_result_family(package):
    """plots and console served every result family from one module each (1,400 and 1,150
    lines); they are packages with one module per family, re-exported by name."""
    folder = ROOT / "fi_design" / package
    assert (folder / "__init__.py").is_file(), f"fi_design/{package} is not a package"
    assert not (ROOT / "fi_design" / f"{package}.py").exists()
    modules = sorted(folder.glob("*.py"))
    assert len(modules) >= 5, [m.name for m in modules]
    long = {m.name: _lines(m) for m in modules if _lines(m) > MAX_FAMILY_LINES}
    assert not long, long
    init = (folder / "__init__.py").read_text(encoding="utf-8")
    assert "import *" not in init


def test_no_module_is_over_800_lines_but_the_integrator():
    sizes = {str(p.relative_to(ROOT)): _lines(p) for p in (ROOT / "fi_design").rglob("*.py")}
    long = {p: n for p, n in sizes.items() if n > MAX_LINES and p not in LONG_MODULES}
    assert not long, long


# --------------------------------------------------------------------------- private names

#: Packages whose modules use each other through public names only (a private name is a
#: module's own business: what a sibling needs is named without the underscore).
SEALED_PACKAGES = ("stage", "guideline", "loop", "controller", "simulation", "spec", "cli", "mechanism",
                   "recommend", "studies", "results", "plots", "console", "report")


def _private_imports(source: str, module: str, package: str, *,
                     is_package: bool = False) -> list[str]:
    """``name (line)`` of each private name ``module`` takes from another module of
    ``package`` (both dotted, e.g. ``fi_design.stage.judge``, ``fi_design.stage``): a
    ``from ... import _name``, or ``sibling._name`` on a sibling module it imported.
    ``is_package``: ``module`` is a package's ``__init__`` (``.`` is the package itself)."""
    import ast

    tree = ast.parse(source)
    parts = module.split(".") + ([""] if is_package else [])
    found, siblings = [], set()

    def resolve(node: ast.ImportFrom) -> str:
        if node.level == 0:
            return node.module or ""
        base = parts[:len(parts) - node.level]
        return ".".join(base + ([node.module] if node.module else []))

    def inside(name: str) -> bool:
        return (name == package or name.startswith(package + ".")) and name != module

    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            source_module = resolve(node)
            for alias in node.names:
                full = f"{source_module}.{alias.name}"
                if inside(source_module) or inside(full):
                    if alias.name.startswith("_") and not alias.name.startswith("__"):
                        found.append(f"{alias.name} from {source_module} (line {node.lineno})")
                    elif inside(full):  # `from . import sibling`
                        siblings.add(alias.asname or alias.name)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if inside(alias.name) and alias.asname:
                    siblings.add(alias.asname)
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                and node.value.id in siblings and node.attr.startswith("_")
                and not node.attr.startswith("__")):
            found.append(f"{node.value.id}.{node.attr} (line {node.lineno})")
    return found


def test_the_private_name_check_finds_each_form():
    """The check below sees the three ways a module reaches a sibling's private name, and
    leaves public names, other packages and private aliases alone."""
    bad = ("from .moves import _Run, watch\n"
           "from fi_design.stage.cycle import _ro\n"
           "from . import runs as r\n"
           "x = r._integrate\n")
    fine = ("from .runs import kernel_run\n"
            "from .. import spec as _spec\n"
            "from ..results import _private_elsewhere\n"
            "from __future__ import annotations\n"
            "from .settings import __all__\n")
    got = _private_imports(bad, "fi_design.stage.judge", "fi_design.stage")
    assert [g.split(" ")[0] for g in got] == ["_Run", "_ro", "r._integrate"], got
    assert _private_imports(fine, "fi_design.stage.judge", "fi_design.stage") == []
    init = _private_imports("from .judge import _boundary\nfrom .. import _x\n",
                            "fi_design.stage", "fi_design.stage", is_package=True)
    assert [g.split(" ")[0] for g in init] == ["_boundary"], init


@pytest.mark.parametrize("package", SEALED_PACKAGES)
def test_no_module_imports_a_private_name_of_its_package(package):
    """A package's modules use each other through public names only (stage/ once imported six
    private helpers across its modules); each offers what the others use under a public name."""
    folder = ROOT / "fi_design" / package
    bad = {}
    for path in sorted(folder.rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("")
        module = ".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        found = _private_imports(path.read_text(encoding="utf-8"), module,
                                 f"fi_design.{package}", is_package=rel.name == "__init__")
        if found:
            bad[str(path.relative_to(ROOT))] = found
    assert not bad, bad


def test_tests_mirror_the_packages():
    """Each folder of tests/ is named after a package of fi_design, and the tests of the
    top level (the architecture, the model, the docs, the examples) stay at the top."""
    folders = {p.name for p in (ROOT / "tests").iterdir()
               if p.is_dir() and any(p.glob("test_*.py"))}
    packages = {p.parent.name for p in (ROOT / "fi_design").glob("*/__init__.py")}
    assert folders, "no test folders"
    assert folders <= packages, sorted(folders - packages)
    top = sorted(p.name for p in (ROOT / "tests").glob("test_*.py"))
    assert len(top) <= 8, top


# --------------------------------------------------------------------------- the model as currency

#: The functions that take a spec or its model: the entry points, which resolve a spec once at
#: their edge (fi_design.model.as_model). Every analysis below them takes a Model only.
SPEC_OR_MODEL_ENTRY_POINTS = {
    ("guideline/evaluate.py", "evaluate"),     # fi_design.design's steps, confirmation, verdict
    ("simulation/run.py", "simulate"),         # fi_design.simulate
    ("stage/judge.py", "stage_hunting"),       # the stage-level answer
    ("stage/moves.py", "stage_hunts"),         # every move of the family
    ("recommend/search.py", "recommend"),      # fi_design.recommend
    ("studies/points.py", "study_model"),      # the studies' edge: a spec resolved once
    ("studies/sweeps.py", "sweep"),            # fi_design.studies.sweep
    ("studies/paper.py", "paper_study"),       # the paper's four maps
    ("studies/scatter.py", "robustness"),      # the probability of hunting under scatter
    ("studies/sensitivity.py", "crossover_sensitivity"),  # the crossover over sigma0, sigma1, vs
}


def _names(node: ast.AST) -> set[str]:
    """The names a type annotation mentions (``_spec.Spec`` as ``Spec``)."""
    out = set()
    for sub in ast.walk(node):
        if isinstance(sub, ast.Name):
            out.add(sub.id)
        elif isinstance(sub, ast.Attribute):
            out.add(sub.attr)
        elif isinstance(sub, ast.Constant) and isinstance(sub.value, str):
            out |= set(re.findall(r"[A-Za-z_]\w*", sub.value))
    return out


def spec_or_model_signatures(package) -> set[tuple[str, str]]:
    """(module path, function) of every function with a parameter annotated with both a Model
    and a Spec (``Model | Spec``, ``Spec | Model | str``, ...), by an AST scan."""
    found = set()
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            a = node.args
            for arg in a.posonlyargs + a.args + a.kwonlyargs:
                if arg.annotation is not None and {"Model", "Spec"} <= _names(arg.annotation):
                    found.add((path.relative_to(package).as_posix(), node.name))
    return found


def test_only_the_entry_points_take_a_spec_or_a_model():
    """The analyses take a Model; a spec is resolved once at the entry points (issue 32)."""
    found = spec_or_model_signatures(ROOT / "fi_design")
    assert found == SPEC_OR_MODEL_ENTRY_POINTS, (
        f"take Model | Spec but are no entry point: {sorted(found - SPEC_OR_MODEL_ENTRY_POINTS)}; "
        f"entry points that no longer do: {sorted(SPEC_OR_MODEL_ENTRY_POINTS - found)}")


def test_an_analysis_refuses_a_spec_with_a_clear_message(paper_spec):
    from fi_design.errors import ArgumentError
    from fi_design.guideline.steps import step2_crossover
    from fi_design.loop import linear
    from fi_design.model import resolve

    assert step2_crossover(resolve(paper_spec)).desired == 8.0
    for call in (lambda: step2_crossover(paper_spec), lambda: linear.analyse(paper_spec)):
        with pytest.raises(ArgumentError, match="expected a Model, got Spec.*resolve"):
            call()


#: The modules outside spec/ and model/ that write values into a spec by dotted path
#: (fi_design.spec.paths.with_values), and why: a spec as an output, never a design varied for an
#: analysis (that is Model.varied, or its fast form Model.at).
SPEC_EDITS = {
    "identification/specwrite.py",   # the identified values written into the spec file's spec
    "recommend/constraints.py",      # the reserve's requirements validated as the spec takes them
}


def _calls(tree: ast.AST, name: str) -> list[int]:
    """Lines of the calls of a function or method called ``name``."""
    return [node.lineno for node in ast.walk(tree) if isinstance(node, ast.Call) and (
        (isinstance(node.func, ast.Name) and node.func.id == name)
        or (isinstance(node.func, ast.Attribute) and node.func.attr == name))]


def test_a_design_is_varied_by_the_model_only():
    """A study axis, a robustness draw, a sensitivity step, an added isolator: each is
    Model.varied (or Model.at) of a model resolved once; the spec is written by dotted path only
    in spec/, model/ and the spec outputs of SPEC_EDITS (issue 32)."""
    package = ROOT / "fi_design"
    found = {}
    for path in sorted(package.rglob("*.py")):
        rel = path.relative_to(package).as_posix()
        if rel.startswith(("spec/", "model/")):
            continue
        lines = _calls(ast.parse(path.read_text(encoding="utf-8")), "with_values")
        if lines:
            found[rel] = lines
    assert set(found) == SPEC_EDITS, (
        f"vary a Model (Model.varied / Model.at), not its spec: {sorted(set(found) - SPEC_EDITS)}; "
        f"no longer edit a spec: {sorted(SPEC_EDITS - set(found))}")


def test_the_studies_points_take_a_model():
    """Every point, draw and sensitivity step of the studies is a Model varied: the functions
    that run one take the base Model (first parameter annotated Model), and refuse a spec."""
    import inspect

    from fi_design.errors import ArgumentError
    from fi_design.stage.confirm import with_isolator
    from fi_design.studies import axes, paper, points, sensitivity

    for fn in (points.evaluate_point, points.run_chunk, points.evaluate, sensitivity._fold,
               axes.design_value, axes.held_damping_note, paper.paper_axes, with_isolator):
        first = next(iter(inspect.signature(fn).parameters.values()))
        assert first.annotation == "Model", (fn.__qualname__, first.annotation)
    src = (ROOT / "fi_design" / "studies" / "points.py").read_text(encoding="utf-8")
    assert _calls(ast.parse(src), "varied"), "a point is the base model varied"
    from fi_design.spec.file import load_spec

    spec = load_spec(ROOT / "examples" / "paper_setup.yaml")
    for call in (lambda: points.evaluate_point(spec, {}, True),
                 lambda: points.evaluate(spec, []),
                 lambda: with_isolator(spec, 3e-4, 5000.0)):
        with pytest.raises(ArgumentError, match="expected a Model, got Spec"):
            call()


def test_every_library_error_is_a_public_name():
    """docs/library.md names ArgumentError and OutputError as the errors a script catches;
    `fi_design.ArgumentError` raised AttributeError (only fi_design.errors had it)."""
    import inspect

    import fi_design
    from fi_design import errors

    kinds = {name for name, obj in vars(errors).items()
             if inspect.isclass(obj) and issubclass(obj, errors.FiDesignError)}
    assert kinds <= set(fi_design.__all__), kinds - set(fi_design.__all__)
    assert all(getattr(fi_design, name) is getattr(errors, name) for name in kinds)
