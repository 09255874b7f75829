"""Errors: one base class, each subclass also the matching builtin, messages that name the place."""

from __future__ import annotations

import inspect

import pytest

from fi_design import errors
from fi_design.errors import (ArgumentError, DataError, FiDesignError, OutputError, ReportError,
                              SpecError)


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
    from fi_design.pid import pid_gains
    from fi_design.plots import figure_bytes

    with pytest.raises(SpecError, match="positive"):
        pid_gains(-1.0, 8.0)
    with pytest.raises(ArgumentError, match="svg or png"):
        figure_bytes(object(), "jpg")
    assert issubclass(ArgumentError, ValueError) and issubclass(ReportError, TypeError)
    assert issubclass(OutputError, OSError)
