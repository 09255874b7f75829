"""Errors: one base class, each subclass also the matching builtin, messages that name the place."""

from __future__ import annotations

import inspect

import pytest

from fi_design import errors
from fi_design.errors import (ArgumentError, DataError, FiDesignError, OutputError, ReportError,
                              SpecError)

from conftest import EXAMPLES


def _error_classes():
    return [obj for _, obj in inspect.getmembers(errors, inspect.isclass)
            if issubclass(obj, Exception) and obj.__module__ == errors.__name__]


@pytest.mark.parametrize("cls", _error_classes(), ids=lambda c: c.__name__)
def test_every_error_derives_from_the_base_and_a_builtin(cls):
    assert issubclass(cls, FiDesignError)
    if cls is not FiDesignError:
        builtins = [b for b in cls.__mro__ if b.__module__ == "builtins"
                    and b not in (Exception, BaseException, object)]
        assert builtins, f"{cls.__name__} inherits no builtin error besides Exception"


def test_messages_name_the_place():
    assert str(SpecError("must be positive", path="stage.mass", line=3, source="s.yaml")) == \
        "s.yaml:3: stage.mass: must be positive"
    assert str(SpecError("empty", source="s.yaml")) == "s.yaml: empty"
    assert str(DataError("not a number", column="position_m", row=7, source="m.csv")) == \
        "m.csv: column 'position_m': row 7: not a number"


def test_misuse_raises_library_errors():
    from fi_design.controller.pid import pid_gains
    from fi_design.plots import figure_bytes

    with pytest.raises(SpecError, match="positive"):
        pid_gains(-1.0, 8.0)
    with pytest.raises(ArgumentError, match="svg or png"):
        figure_bytes(object(), "jpg")
    assert issubclass(ArgumentError, ValueError) and issubclass(ReportError, TypeError)
    assert issubclass(OutputError, OSError)


# --------------------------------------------------------------------------- library misuse


class _NoWork:
    """An executor that fails the test if a study starts any work: a size must be refused first."""

    def submit(self, fn, *args, **kwargs):
        raise AssertionError("the study started work it should have refused up front")


def _calls():
    """(id, call(spec, measured), library error class, words of the message)."""
    import fi_design
    from fi_design.studies import make_axis, paper_study, robustness, sweep
    from fi_design.studies.scatter import Scatter

    scatter = [Scatter(path="friction.static", spread=0.1, relative=True)]
    return [
        ("sweep-text-values", lambda s, m: sweep(s, ("stage.mass", ["1 kg", "2 kg"])),
         SpecError, ["stage.mass", "'1 kg'", "numbers"]),
        ("sweep-too-many-points", lambda s, m: sweep(
            s, make_axis("controller.crossover", [5.0, 6.0]),
            make_axis("stage.mass", [1.0 + 1e-5 * i for i in range(60_000)]), executor=_NoWork()),
         SpecError, ["120000 points", "at most 100000"]),
        ("axis-too-many-values", lambda s, m: make_axis("stage.mass", [1.0] * 100_001),
         SpecError, ["100001 values", "at most 100000"]),
        ("simulate-crossover-text", lambda s, m: fi_design.simulate(s, crossover="5 Hz"),
         ArgumentError, ["crossover", "'5 Hz'"]),
        ("simulate-duration-without-bound", lambda s, m: fi_design.simulate(s, duration=1e9),
         ArgumentError, ["duration", "output samples", "at most 4000000"]),
        ("simulate-spec-none", lambda s, m: fi_design.simulate(None),
         ArgumentError, ["spec must be a Spec", "NoneType"]),
        ("resolve-number", lambda s, m: fi_design.resolve(5.0),
         ArgumentError, ["spec must be a Spec, a path to a YAML spec or a mapping", "float"]),
        ("load-spec-none", lambda s, m: fi_design.load_spec(None),
         ArgumentError, ["source must be a path to a YAML spec or a mapping", "NoneType"]),
        ("load-spec-number", lambda s, m: fi_design.load_spec(5), ArgumentError, ["got int"]),
        ("load-spec-list", lambda s, m: fi_design.load_spec([1, 2]), ArgumentError, ["got list"]),
        ("load-spec-bytes", lambda s, m: fi_design.load_spec(b"name: x"),
         ArgumentError, ["got bytes", "write the YAML to a file"]),
        # YAML text where a path belongs was read as a file name: 'TEXT...: no such file', or
        # an OSError (File name too long) from the file system
        ("load-spec-yaml-text", lambda s, m: fi_design.load_spec(
            (EXAMPLES / "paper_setup.yaml").read_text(encoding="utf-8") * 100),
         ArgumentError, ["looks like YAML text", "not a path", "parse_yaml(text.encode"]),
        ("load-spec-yaml-mapping-line", lambda s, m: fi_design.load_spec("stage: {mass: 1 kg}"),
         ArgumentError, ["looks like YAML text ('stage: {mass: 1 kg}')"]),
        ("replay-window-picoseconds", lambda s, m: fi_design.simulate(
            s, record=m, drive="force", window=1e-12),
         ArgumentError, ["window = 1\u00a0×\u00a010⁻¹² s", "fewer than 10 samples"]),
        ("identify-unknown-form", lambda s, m: fi_design.identify(m, form="bogus"),
         ArgumentError, ["form", "'bogus'", "'symmetric'"]),
        ("identify-not-a-record", lambda s, m: fi_design.identify("trace.csv"),
         ArgumentError, ["measured must be a Measurement", "str"]),
        ("robustness-too-many-samples", lambda s, m: robustness(
            s, scatter, samples=1_000_000, executor=_NoWork()),
         SpecError, ["samples = 1000000", "at most 100000"]),
        ("paper-study-too-fine", lambda s, m: paper_study(s, 1000, executor=_NoWork()),
         ArgumentError, ["resolution", "at most 150"]),
        ("reconcile-max-effects-text", lambda s, m: fi_design.reconcile(s, m, max_effects="2"),
         ArgumentError, ["max_effects", "whole number"]),
        # a TypeError, an AttributeError, and warnings logged on a file given as the cache
        ("recommend-cache-number", lambda s, m: fi_design.recommend(s, cache=5),
         ArgumentError, ["cache must be None, True or False, a folder's path", "int 5"]),
        ("design-executor-number", lambda s, m: fi_design.design(s, executor=5),
         ArgumentError, ["executor must be None or a concurrent.futures-style executor",
                         "int 5"]),
        ("sweep-executor-number", lambda s, m: sweep(s, ("controller.crossover", [8.0]),
                                                     executor=5),
         ArgumentError, ["executor must be None"]),
        ("recommend-cache-file", lambda s, m: fi_design.recommend(s, cache=TRACE),
         ArgumentError, ["cache must be a folder", f"{TRACE} is a file"]),
        ("design-cache-file", lambda s, m: fi_design.design(s, cache=TRACE, executor=_NoWork()),
         ArgumentError, ["cache must be a folder"]),
        # AttributeErrors: type object 'float' has no attribute 'model_fields', 'list' object
        # has no attribute 'items'
        # TypeErrors ('expected str, bytes or os.PathLike object, not float'), and an
        # OSError 'File name too long' for the CSV text itself
        ("load-measurement-number", lambda s, m: fi_design.load_measurement(5.0),
         ArgumentError, ["path must be the path of a CSV file", "got float",
                         "measurement_from_arrays"]),
        ("load-measurement-csv-text", lambda s, m: fi_design.load_measurement(
            TRACE_TEXT * 2), ArgumentError, ["looks like CSV text", "not a path"]),
        ("with-values-number", lambda s, m: fi_design.with_values(5.0, {"stage.mass": 1.0}),
         ArgumentError, ["spec must be a Spec, a path to a YAML spec or a mapping", "float"]),
        ("with-values-pairs", lambda s, m: fi_design.with_values(s, [("stage.mass", 1.0)]),
         ArgumentError, ["values must be a mapping of dotted path to value", "got list"]),
    ]


#: A file, not a folder, given as a cache.
TRACE = str(EXAMPLES / "measured_trace.csv")
#: The start of its text (a path's length runs out at 4096 bytes).
TRACE_TEXT = (EXAMPLES / "measured_trace.csv").read_text(encoding="utf-8")[:3000]


@pytest.mark.parametrize("case", range(len(_calls())), ids=[c[0] for c in _calls()])
def test_library_calls_raise_library_errors(case):
    """Misuse raises a FiDesignError subclass (also the builtin), never numpy's ValueError,
    an AttributeError, an OverflowError or a MemoryError, and before any work starts."""
    import fi_design

    from conftest import EXAMPLES

    spec = fi_design.load_spec(EXAMPLES / "measured_stage.yaml")
    measured = fi_design.load_measurement(EXAMPLES / "measured_trace.csv")
    _, call, cls, words = _calls()[case]
    with pytest.raises(cls) as err:
        call(spec, measured)
    assert isinstance(err.value, FiDesignError) and isinstance(err.value, ValueError)
    for word in words:
        assert word in str(err.value), str(err.value)


def test_identify_takes_the_spec_mapping_design_takes():
    """identify(record, mapping) reads the mapping as design(mapping) does (it was an
    AttributeError: 'dict' object has no attribute 'controller')."""
    import yaml

    import fi_design

    from conftest import EXAMPLES

    raw = yaml.safe_load((EXAMPLES / "measured_stage.yaml").read_text())
    measured = fi_design.load_measurement(EXAMPLES / "measured_trace.csv")
    from_mapping = fi_design.identify(measured, raw)
    from_spec = fi_design.identify(measured, fi_design.load_spec(raw))
    assert from_mapping.value("mass") == from_spec.value("mass")
    assert from_mapping.spec == from_spec.spec


def test_with_values_takes_the_spec_mapping_and_path_design_takes():
    """with_values(mapping or path, values) reads the spec as design(mapping) does (it was an
    AttributeError: type object 'dict' has no attribute 'model_fields')."""
    import yaml

    import fi_design

    from conftest import EXAMPLES

    path = EXAMPLES / "measured_stage.yaml"
    raw = yaml.safe_load(path.read_text())
    for given in (raw, path, str(path)):
        assert fi_design.with_values(given, {"friction.static": "3 N"}).friction.static == 3.0
    assert raw["friction"]["static"] != "3 N"  # the mapping is not changed
