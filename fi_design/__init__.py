"""fi_design: design guideline, simulation and reports for friction isolators.

A friction isolator is a compliant flexure joint between an actuated stage and
the cart of a rolling or sliding bearing, with stroke limiters. Near standstill
the controller feels the smooth flexure instead of the friction discontinuity,
and friction-induced hunting disappears. This package implements the four-step
design guideline of the paper (friction gap, crossover, drive stiffness, PID
gains), confirms it with a nonlinear LuGre simulation, and renders sign-off
reports.

The public API (imported lazily, so ``import fi_design`` stays fast):

- :func:`load_spec` -- read and validate a YAML spec or a mapping;
- :func:`with_values` -- the spec with values replaced at dotted paths, validated again;
- :func:`design` -- the four guideline steps, the simulated confirmation and
  the sign-off verdict, with a recommendation that passes when it fails;
- :func:`recommend` -- search the isolator and crossover for a design that passes;
- :func:`resolve` -- the spec resolved once into a :class:`Model` (every
  default filled in; ``model.varied({path: value})`` varies it, ``model.at(...)``
  is the fast form for its physical values);
- :func:`simulate` -- one nonlinear simulation;
- :func:`sweep`, :func:`robustness` -- parameter studies;
- :func:`load_measurement`, :func:`reconcile` -- compare with measured data;
- :func:`identify` -- mass and friction from a measured record (guideline step 1);
- :func:`render_report` -- HTML or PDF report.

All values are SI floats; units are stated in the docstrings.

These names are stable: ``fi_design.recommend`` is the package of the design
search, called as the search itself (``fi_design.recommend(spec)``), however
it was imported; its submodules are its attributes; and a subpackage such as
``fi_design.report`` is imported on first use (``fi_design.report.build_context``
after a plain ``import fi_design``).
"""

from __future__ import annotations

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version as _version
from importlib.util import find_spec

try:
    __version__ = _version("fi_design")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

_API = {
    "load_spec": "fi_design.spec.file",
    "with_values": "fi_design.spec.file",
    "Spec": "fi_design.spec",
    "design": "fi_design.signoff",
    "recommend": "fi_design.recommend",
    "resolve": "fi_design.model",
    "Model": "fi_design.model",
    "DesignResult": "fi_design.results.design",
    "simulate": "fi_design.simulation.run",
    "SimulationResult": "fi_design.results.simulation",
    "sweep": "fi_design.studies",
    "robustness": "fi_design.studies",
    "load_measurement": "fi_design.measured",
    "reconcile": "fi_design.reconciliation",
    "identify": "fi_design.identification",
    "IdentificationResult": "fi_design.identification",
    "render_report": "fi_design.report",
    "FiDesignError": "fi_design.errors",
    "SpecError": "fi_design.errors",
    "UnitError": "fi_design.errors",
    "SpecFileError": "fi_design.errors",
    "DataError": "fi_design.errors",
    "ArgumentError": "fi_design.errors",
    "ReportError": "fi_design.errors",
    "OutputError": "fi_design.errors",
    "CacheError": "fi_design.errors",
    "SimulationError": "fi_design.errors",
}

__all__ = sorted(_API) + ["__version__"]


#: Public names that are a subpackage called as its own function (the package's
#: ``__call__``): the name and the package are one object.
_CALLED_PACKAGES = {"recommend"}


def __getattr__(name: str):
    if name in _CALLED_PACKAGES:
        return import_module(f"{__name__}.{name}")
    if name in _API:
        return getattr(import_module(_API[name]), name)
    if not name.startswith("_") and find_spec(f"{__name__}.{name}") is not None:
        return import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'fi_design' has no attribute {name!r}")


def __dir__() -> list[str]:
    return __all__
