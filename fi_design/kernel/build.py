"""How the kernel's source becomes machine code, and which build runs: the one seam.

Two builds of one source (:mod:`~fi_design.kernel.integrator` and
:mod:`~fi_design.kernel.equations`):

- ``aot``: an extension module, :data:`MODULE` inside this package, compiled
  when the package is installed (the build hook ``hatch_build.py`` runs
  ``python -m fi_design.kernel.build``) by numba's ahead-of-time compiler
  ``numba.pycc``. It loads in a fraction of a millisecond and needs neither
  numba nor a compile at run time, so a first run is as fast as any other.
- ``jit``: numba compiles the source at first use (10-15 s once, then about
  0.5 s a process to load from numba's on-disk cache).

:func:`compiled` takes the extension when it exists and was built from the
package's files as they are now (:func:`source_digest` is compiled into it),
and numba's JIT otherwise: after an edit of any file of the package, without
a C compiler at install, or when ``FI_DESIGN_KERNEL=jit`` asks for it. Both
run the same code at the same speed.

Everything that knows ``numba.pycc`` is in this module: replacing it (numba
has marked it for deprecation) changes this file alone. BENCHMARKS.md
("Building the kernel") gives the measured cost of each way to build.

Run ``python -m fi_design.kernel.build`` to rebuild the extension in place
after editing the kernel (the install does it once).
"""

from __future__ import annotations

import functools
import hashlib
import logging
import os
import sys
from pathlib import Path
from types import SimpleNamespace

from ..provenance import CODE_SUFFIXES

log = logging.getLogger(__name__)

#: Name of the extension module, inside this package.
MODULE = "_aot"
#: ``jit`` forces numba's JIT of the source even when the extension is current.
BACKEND_ENV = "FI_DESIGN_KERNEL"
#: The package folder: its source files are the kernel's source.
PACKAGE = Path(__file__).resolve().parent
#: The functions both builds provide to Python, and where they are defined.
FUNCTIONS = {
    "integrate": "integrator", "rhs": "equations", "jacobian": "equations",
    "natural_modes": "equations", "drive_force": "equations", "controller_output": "equations", "actuator": "equations",
    "static_friction": "equations", "stribeck": "equations", "feedforward": "equations",
    "breakaway": "equations", "switch_mode": "equations", "sample_filters": "equations",
    "local_maxima": "metric", "select_peaks": "metric", "one_per_plateau": "metric",
    "extremes": "metric", "step_range": "metric", "last_outside": "metric",
}


def source_files(package: Path | None = None) -> list[Path]:
    """Every source file of the kernel package, in name order.

    Parameters
    ----------
    package : pathlib.Path, optional
        The package folder; default this one.

    Returns
    -------
    list of pathlib.Path
        The package's files with a code suffix (``CODE_SUFFIXES`` of
        :mod:`fi_design.provenance`): every module, whatever its name, so a
        new module is covered without being listed anywhere.
    """
    package = Path(package) if package is not None else PACKAGE
    return sorted((p for p in package.iterdir() if p.is_file() and p.suffix in CODE_SUFFIXES),
                  key=lambda p: p.name)


def source_digest(package: Path | None = None) -> int:
    """A 60-bit digest of the kernel package's files (:func:`source_files`) [-].

    Parameters
    ----------
    package : pathlib.Path, optional
        The package folder; default this one.

    Returns
    -------
    int
        The first 60 bits of SHA-256 over ``NAME<NUL>CONTENT`` of every file
        of :func:`source_files` (a renamed file changes it too).
    """
    h = hashlib.sha256()
    for path in source_files(package):
        h.update(path.name.encode() + b"\0")
        h.update(path.read_bytes())
    return int(h.hexdigest()[:15], 16)


@functools.lru_cache(maxsize=1)
def compiled() -> SimpleNamespace:
    """The compiled functions (:data:`FUNCTIONS`), ``backend`` (``"aot"`` or ``"jit"``) and,
    for the JIT, the ``reason`` it runs.

    Returns
    -------
    types.SimpleNamespace
    """
    reason = f"asked for by {BACKEND_ENV}=jit"
    if os.environ.get(BACKEND_ENV, "").lower() != "jit":
        try:
            from . import _aot as aot  # type: ignore[attr-defined]
        except ImportError:
            reason = "no extension built at install (no C compiler then?)"
        else:
            if aot.source_digest() == source_digest():
                return SimpleNamespace(backend="aot", reason="",
                                       **{n: getattr(aot, n) for n in FUNCTIONS})
            reason = ("the extension was built from other sources "
                      "(rebuild: python -m fi_design.kernel.build)")
    log.info("simulation kernel: numba's JIT (%s)", reason)
    return SimpleNamespace(backend="jit", reason=reason, **_source_functions())


def _source_functions() -> dict:
    """The kernel's functions from the source (numba compiles them, or loads its cache)."""
    from . import equations, integrator, metric

    where = {"integrator": integrator, "equations": equations, "metric": metric}
    return {n: getattr(where[m], n) for n, m in FUNCTIONS.items()}


def backend() -> str:
    """``"aot"`` (the extension built at install) or ``"jit"`` (numba at first use).

    Returns
    -------
    str
    """
    return compiled().backend


# --------------------------------------------------------------------------- the build


def _returns() -> dict:
    """Return type of every exported function (the argument types come with the functions)."""
    from numba import types as t

    f8 = t.float64
    return {"integrate": t.int64, "rhs": t.void, "jacobian": t.void, "natural_modes": t.void,
            "drive_force": f8, "controller_output": f8, "actuator": t.UniTuple(f8, 2),
            "static_friction": f8, "stribeck": t.UniTuple(f8, 3),
            "feedforward": t.UniTuple(f8, 2), "breakaway": f8, "switch_mode": t.void,
            "sample_filters": f8, "local_maxima": t.int64, "select_peaks": t.int64,
            "one_per_plateau": t.int64, "extremes": t.UniTuple(f8, 2),
            "step_range": t.UniTuple(f8, 2), "last_outside": t.int64}


def built(output_dir: str | os.PathLike | None = None) -> list[Path]:
    """The files a build wrote into ``output_dir`` (default this package).

    Returns
    -------
    list of pathlib.Path
    """
    out = Path(output_dir) if output_dir is not None else PACKAGE
    return sorted(out.glob(MODULE + ".*"))


def build(output_dir: str | os.PathLike | None = None) -> list[Path]:
    """Compile the kernel into the extension module; returns the files written.

    Parameters
    ----------
    output_dir : path, optional
        Where to write it; default the package folder (older builds there
        are removed first).

    Returns
    -------
    list of pathlib.Path
        The files to ship with the package (one extension module).

    Must run in a process that has not imported the kernel's source yet
    (the functions are compiled lazily, by the extension compiler alone).
    """
    from .jit import AOT_BUILD_ENV

    if any(f"{__package__}.{m}" in sys.modules for m in ("integrator", "equations", "metric")) \
            and not os.environ.get(AOT_BUILD_ENV):
        raise RuntimeError("build() needs a fresh process: the kernel is already JIT-compiled")
    os.environ[AOT_BUILD_ENV] = "1"
    from numba.pycc import CC

    from .jit import SIGNATURES

    functions = _source_functions()
    out = Path(output_dir) if output_dir is not None else PACKAGE
    for old in built(out):
        old.unlink()
    cc = CC(MODULE)
    cc.output_dir = str(out)
    cc.verbose = False
    for name, returns in _returns().items():
        cc.export(name, returns(*SIGNATURES[name]))(functions[name].py_func)
    digest = source_digest()

    @cc.export("source_digest", "i8()")
    def _digest():
        return digest

    cc.compile()
    files = built(out)
    if not files:
        raise RuntimeError(f"the ahead-of-time build wrote no {MODULE} module into {out}")
    return files


def main() -> None:
    """``python -m fi_design.kernel.build [DIR]``: build the extension (into the package by
    default) and print the path of every file written, one a line. ``-h`` or ``--help``
    prints the usage; any other option, or more than one DIR, is refused (exit code 2)."""
    args = sys.argv[1:]
    usage = ("usage: python -m fi_design.kernel.build [DIR]\n"
             "Build the compiled simulation kernel into DIR (default: the installed package).")
    if args and args[0] in ("-h", "--help"):
        print(usage)
        return
    if len(args) > 1 or (args and args[0].startswith("-")):
        print(f"{usage}\nerror: unexpected argument {args[-1] if len(args) > 1 else args[0]!r}",
              file=sys.stderr)
        raise SystemExit(2)
    for path in build(args[0] if args else None):
        print(path)


if __name__ == "__main__":
    main()
