"""Shared fixtures: repository paths and the reference specs."""

from __future__ import annotations

import contextlib
import functools
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: Scripts of the virtual environment running the tests (fi-design, lint-imports).
BIN = Path(sys.executable).parent


# --------------------------------------------------------------------------- order of the files

#: The files that take longest (minutes of CPU between them), longest first: pytest-xdist
#: hands files to its processes in collection order (--dist loadfile, --no-loadscope-reorder),
#: and a long file started last keeps one process busy after the other has finished. Only an
#: order: a file missing here runs after these, in its usual place.
LONGEST_FIRST = (
    "test_reconciliation.py", "test_report.py", "test_reconciliation_independent.py",
    "test_reconciliation_emps.py", "test_console.py", "test_identify_dynamic.py",
    "test_pools.py", "test_verdict.py", "test_docs.py", "test_identify.py",
    "test_statements.py", "test_independent.py", "test_cli.py", "test_recommend.py",
    "test_filters.py", "test_guideline.py", "test_handoff.py",
)


def pytest_collection_modifyitems(session, config, items):
    """The longest files first (:data:`LONGEST_FIRST`); each file's tests in their order."""
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The repository root."""
    return ROOT


@pytest.fixture(scope="session")
def paper_spec_path() -> Path:
    """examples/paper_setup.yaml: the paper-like stage with a friction isolator."""
    return EXAMPLES / "paper_setup.yaml"


@pytest.fixture(scope="session")
def paper_spec(paper_spec_path):
    """The validated :class:`~fi_design.spec.Spec` of examples/paper_setup.yaml."""
    from fi_design.spec.file import load_spec

    return load_spec(paper_spec_path)


# --------------------------------------------------------------------------- real records

#: Environment variable naming the folder of real measured records (``.ci/run`` sets it to
#: the absolute path beside the original checkout, because CI tests a copy of the repository).
REALDATA_ENV = "FI_DESIGN_REALDATA"


def realdata_dir() -> Path:
    """Folder of the real records: ``$FI_DESIGN_REALDATA``, else ``../shared/realdata``."""
    import os

    given = os.environ.get(REALDATA_ENV)
    return Path(given) if given else ROOT.parent / "shared" / "realdata"


@pytest.fixture(scope="session")
def emps_path() -> Path:
    """The EMPS estimation record (a real ball-screw axis under PD control, not redistributable).

    Skips with the reason when the record is absent (a clone of the repository alone), but
    fails under CI (``CI`` set), where the record must be found.
    """
    import os

    path = realdata_dir() / "emps" / "emps_estimation.csv"
    if not path.is_file():
        reason = (f"the real EMPS record is not at {path} (set {REALDATA_ENV} to the folder "
                  "holding emps/emps_estimation.csv); it is not part of the repository")
        if os.environ.get("CI"):
            pytest.fail(reason)
        pytest.skip(reason)
    return path


@pytest.fixture(scope="session")
def emps_record(emps_path):
    """The EMPS estimation record as a :class:`~fi_design.measured.Measurement`."""
    from fi_design.measured import load_measurement

    return load_measurement(emps_path)


# --------------------------------------------------------------------------- signal handling


def _signal_state() -> tuple:
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return ()
    import sys

    from fi_design.interrupts import SIGNALS

    module = sys.modules["fi_design.interrupts"]
    state = module._STATE
    return (tuple(signal.getsignal(s) for s in SIGNALS),
            frozenset(signal.pthread_sigmask(signal.SIG_BLOCK, [])),
            (id(module), state.make, state.depth, tuple(state.pending), tuple(state.received)))


@pytest.fixture(autouse=True)
def _signal_handling_left_as_found():
    """A test that leaves a signal handler or the thread's signal mask changed fails at its
    teardown, with both restored: otherwise a later test of the same process that relies on
    the default Ctrl-C handler (tests/cli/test_interrupts.py) fails in its place."""
    import signal

    before = _signal_state()
    yield
    after = _signal_state()
    if after == before:
        return
    from fi_design.interrupts import SIGNALS

    for s, handler in zip(SIGNALS, before[0]):
        signal.signal(s, handler if handler is not None else signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_SETMASK, before[1])
    pytest.fail(f"the test left the signal handling changed: handlers {before[0]} -> "
                f"{after[0]}, blocked {sorted(before[1])} -> {sorted(after[1])}")


# --------------------------------------------------------------------------- parameter studies


@pytest.fixture(autouse=True, scope="session")
def _private_result_cache(tmp_path_factory):
    """Point the caches (FI_DESIGN_CACHE_DIR: sweep results, drawn equations) at a temporary directory.

    No test ever reads or writes the user's cache; tests that need an empty
    cache of their own pass ``cache=tmp_path`` or set the variable again.
    """
    import os

    old = os.environ.get("FI_DESIGN_CACHE_DIR")
    os.environ["FI_DESIGN_CACHE_DIR"] = str(tmp_path_factory.mktemp("fi_design_cache"))
    yield
    if old is None:
        os.environ.pop("FI_DESIGN_CACHE_DIR", None)
    else:
        os.environ["FI_DESIGN_CACHE_DIR"] = old


# --------------------------------------------------------------------------- reports


#: Designs and design searches computed in this process, by kind, spec file and content.
_SHARED: dict[tuple, object] = {}


def _spec_key(spec) -> tuple | None:
    """(resolved path or None, SHA-256 of the file, the validated values) of a spec read by
    load_spec; None for anything else."""
    from fi_design.spec import Spec
    from fi_design.spec.file import origin

    found = origin(spec) if isinstance(spec, Spec) else None
    if found is None:
        return None
    return (str(Path(found.path).resolve()) if found.path is not None else None, found.sha256,
            spec.model_dump_json())


def remember(kind: str, spec, result, *extra) -> None:
    """Keep a result computed elsewhere for :func:`shared` (unless one is kept already)."""
    key = _spec_key(spec)
    if key is not None:
        _SHARED.setdefault((kind, *key, *extra), result)


def shared(kind: str, spec, compute, *extra):
    """``compute()`` once in the run for this kind of result of this spec (file and content):
    once per process, and across pytest-xdist's processes through :data:`_ACROSS`.

    Computed in the repository's root, whichever test asks first: a result names its spec's
    path relative to the working directory (the next step's command), so one first asked for
    by a test working in a temporary folder named it absolute for every test after it."""
    import contextlib

    key = _spec_key(spec)
    if key is None:
        return compute()
    key = (kind, *key, *extra)
    if key not in _SHARED:
        with contextlib.chdir(ROOT):
            _SHARED[key] = compute() if _ACROSS is None else _computed_once(key, compute)
    return _SHARED[key]


# --------------------------------------------------------------------------- across processes

#: The folder this run's processes share (pytest-xdist hands the controller's to its
#: workers), where :func:`shared` keeps what one of them computed for the others; None in a
#: run of one process, which its own :data:`_SHARED` serves.
_ACROSS: Path | None = None
#: How long a process waits for another to compute a shared result before it computes the
#: result itself [s] (a guard: shared results do not nest, so none waits for itself).
WAIT_FOR_OTHERS = 900.0


def pytest_configure(config):
    """The controller of a pytest-xdist run makes the folder :func:`shared` keeps results in;
    each worker reads it from its input."""
    import tempfile

    global _ACROSS
    given = getattr(config, "workerinput", {}).get("fi_design_shared")
    if given is not None:
        _ACROSS = Path(given)
    elif getattr(config.option, "numprocesses", None):
        config._fi_design_shared = tempfile.mkdtemp(prefix="fi_design_shared-")


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """pytest-xdist's hook on the controller, for each worker it starts."""
    folder = getattr(node.config, "_fi_design_shared", None)
    if folder is not None:
        node.workerinput["fi_design_shared"] = folder


def pytest_unconfigure(config):
    import shutil

    folder = getattr(config, "_fi_design_shared", None)
    if folder is not None:
        shutil.rmtree(folder, ignore_errors=True)


def _computed_once(key: tuple, compute):
    """``compute()`` in the first process that asks, kept in :data:`_ACROSS` under a lock the
    others wait on; they read it back (a design is a function of its spec, so which process
    computed it does not change what the tests read)."""
    import fcntl
    import hashlib
    import os
    import pickle
    import time

    name = hashlib.sha256(repr(key).encode()).hexdigest()[:32]
    path = _ACROSS / f"{name}.pickle"
    with open(_ACROSS / f"{name}.lock", "w") as lock:
        deadline = time.monotonic() + WAIT_FOR_OTHERS
        while True:
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    return compute()
                time.sleep(0.05)
        if path.exists():
            return pickle.loads(path.read_bytes())
        result = compute()
        part = path.with_suffix(".part")
        part.write_bytes(pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL))
        os.replace(part, path)
        return result


def design_options(confirm: bool, kwargs: dict) -> tuple:
    """The options of a design as a key, the defaults filled in: ``evaluate(spec)`` and
    ``evaluate(spec, fe_check=False)`` are one design (the executor and the progress change
    where and how visibly it runs, not what it gives)."""
    import inspect

    from fi_design.guideline.evaluate import evaluate  # a wrapper here follows __wrapped__

    given = dict(kwargs)
    for name, p in inspect.signature(evaluate).parameters.items():
        if p.kind is p.KEYWORD_ONLY and name not in ("confirm", "executor", "progress"):
            given.setdefault(name, p.default)
    return (confirm, *sorted(given.items()))


@contextlib.contextmanager
def sharing_designs():
    """The guideline's design and the design search computed once per spec and process.

    For tests of what the command line or a documented example does with a design (prints,
    writes, exits with), not of how it is computed: ``fi_design.guideline.evaluate.evaluate`` and
    ``fi_design.recommend.recommend`` return the result an earlier call on the same spec file
    (same path, same bytes) computed in this process, as the design command would compute it
    again (a design is a function of its spec; the executor changes where it runs, not what it
    gives). The first call computes, with the caller's executor and progress; later calls do
    not report progress. Calls with other arguments (a grid, a spec that is no file) compute.
    """
    import importlib

    from fi_design.guideline import evaluate as guideline

    search = importlib.import_module("fi_design.recommend")  # the package, not the function
    real_design, real_recommend = guideline.evaluate, search.recommend

    @functools.wraps(real_design)
    def design(spec, *, confirm=True, executor=None, progress=None, **kwargs):
        return shared("design", spec, lambda: real_design(
            spec, confirm=confirm, executor=executor, progress=progress, **kwargs),
            *design_options(confirm, kwargs))

    def recommend(spec, *, executor=None, progress=None, cache=None, **kwargs):
        # the cache changes where a search comes from, not what it finds
        if kwargs:
            return real_recommend(spec, executor=executor, progress=progress, cache=cache,
                                  **kwargs)
        return shared("recommend", spec, lambda: real_recommend(
            spec, executor=executor, progress=progress))

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(guideline, "evaluate", design)
        patch.setattr(search, "recommend", recommend)
        yield


@pytest.fixture
def shared_designs():
    """:func:`sharing_designs` for the test."""
    with sharing_designs():
        yield


@pytest.fixture(scope="session")
def paper_confirmed_design(paper_spec):
    """The design of examples/paper_setup.yaml with its simulated confirmation, computed once
    (and shared with the tests that use :func:`shared_designs`)."""
    from fi_design.guideline.evaluate import evaluate as design

    return shared("design", paper_spec, lambda: design(paper_spec), *design_options(True, {}))


#: The robustness requirement examples/industrial_axis.yaml is read with by the tests of its
#: documents (test_console, test_statements): its robustness study (100 samples of 49 moves,
#: with and without the rule's isolator) is most of its design. 20 samples, all of which
#: settle, within a limit raised to 20 % (the Wilson interval of 0 of 20 reaches 16.1 %): its
#: documents state what the example's do (PASS, nothing to review, the same rows) with 20
#: samples and 20 % for 100 and 5 %.
INDUSTRIAL_ROBUSTNESS = {"samples": 20, "hunting_probability": 0.2}


@pytest.fixture(scope="session")
def industrial_quick(tmp_path_factory) -> Path:
    """examples/industrial_axis.yaml with :data:`INDUSTRIAL_ROBUSTNESS`, at one path for the
    whole run (in the folder its processes share, when they are several), so that its design
    is computed once (:func:`shared`)."""
    import os

    import yaml

    folder = _ACROSS / "industrial" if _ACROSS is not None else \
        tmp_path_factory.mktemp("industrial")
    folder.mkdir(exist_ok=True)
    raw = yaml.safe_load((EXAMPLES / "industrial_axis.yaml").read_text(encoding="utf-8"))
    raw.setdefault("requirements", {})["robustness"] = INDUSTRIAL_ROBUSTNESS
    path = folder / "industrial_axis.yaml"
    part = folder / f"industrial_axis.{os.getpid()}.part"  # the same bytes from every process
    part.write_text(yaml.safe_dump(raw), encoding="utf-8")
    os.replace(part, path)
    return path


def variant(spec, **paths):
    """The spec re-read from its YAML mapping with dotted paths replaced.

    ``variant(spec, **{"friction.static": "3 N", "isolator": None})``: a value
    replaces (or adds) the key, None removes it; values are written as in the
    YAML file (SI numbers or strings with units). Unlike
    :func:`fi_design.spec.file.with_values` it may add or drop whole sections.
    """
    import copy

    from fi_design.spec.file import load_spec, origin

    raw = copy.deepcopy(origin(spec).raw)
    for path, value in paths.items():
        node = raw
        *head, last = path.split(".")
        for key in head:
            node = node.setdefault(key, {})
        if value is None:
            node.pop(last, None)
        else:
            node[last] = value
    return load_spec(raw)


def edited_trace(tmp_path, name: str, edit) -> Path:
    """examples/measured_trace.csv with each data row's cells passed through ``edit`` (a list
    of strings in, a list out: time_s, reference_m, position_m, force_N, deflection_m),
    written to ``tmp_path / name``; comments and the header kept."""
    lines = (EXAMPLES / "measured_trace.csv").read_text().splitlines()
    out = [line if line.startswith(("#", "time_s")) else ",".join(edit(line.split(",")))
           for line in lines]
    path = tmp_path / name
    path.write_text("\n".join(out) + "\n")
    return path
