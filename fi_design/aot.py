"""Ahead-of-time build of the simulation kernel into an extension module.

Installing the package runs :func:`build` (from the build hook ``hatch_build.py``):
numba's ahead-of-time compiler (``numba.pycc``) compiles the kernel's source
(:mod:`fi_design.kernel` and :mod:`fi_design.equations`) into
``fi_design/_kernel_aot``, a plain extension module that needs neither
numba nor a compile at run time. It exports the integrator and the
equations the reference path and the replay call from Python, plus the
digest of the sources it was built from, so that :mod:`fi_design.compiled`
uses it only while it matches them (an edited kernel falls back to numba's
JIT of the new source).

Run ``python -m fi_design.aot`` to rebuild it in place after editing the
kernel (the install does it once).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

#: Name of the extension module, inside the package.
MODULE = "_kernel_aot"


def _exports() -> dict:
    """Return type of every exported function (the argument types come with the functions)."""
    from numba import types as t

    f8 = t.float64
    return {"integrate": t.int64, "rhs": t.void, "jacobian": t.void, "natural_modes": t.void,
            "drive_force": f8, "controller_output": f8, "actuator": t.UniTuple(f8, 2),
            "static_friction": f8, "stribeck": t.UniTuple(f8, 3),
            "feedforward": t.UniTuple(f8, 2)}


def build(output_dir: str | os.PathLike | None = None) -> Path:
    """Compile the kernel into the extension module; returns its path.

    Parameters
    ----------
    output_dir : path, optional
        Where to write it; default the package folder.

    Must run in a process that has not imported the kernel yet (the
    functions are compiled lazily, by the extension compiler alone).
    """
    from ._jit import AOT_BUILD_ENV

    if "fi_design.kernel" in sys.modules and not os.environ.get(AOT_BUILD_ENV):
        raise RuntimeError("build() needs a fresh process: the kernel is already JIT-compiled")
    os.environ[AOT_BUILD_ENV] = "1"
    from numba.pycc import CC

    from . import equations, kernel
    from ._jit import SIGNATURES
    from .compiled import source_digest

    out = Path(output_dir) if output_dir is not None else Path(__file__).resolve().parent
    cc = CC(MODULE)
    cc.output_dir = str(out)
    cc.verbose = False
    for name, returns in _exports().items():
        fn = getattr(kernel, name, None) or getattr(equations, name)
        cc.export(name, returns(*SIGNATURES[name]))(fn.py_func)
    digest = source_digest()

    @cc.export("source_digest", "i8()")
    def _digest():
        return digest

    cc.compile()
    built = sorted(out.glob(MODULE + ".*"))
    if not built:
        raise RuntimeError(f"the ahead-of-time build wrote no {MODULE} module into {out}")
    return built[-1]


def main() -> None:
    """``python -m fi_design.aot [DIR]``: build the extension (into the package by default)."""
    path = build(sys.argv[1] if len(sys.argv) > 1 else None)
    print(f"built {path}")


if __name__ == "__main__":
    main()
