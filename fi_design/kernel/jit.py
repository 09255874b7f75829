"""How the kernel's functions are compiled by numba, and their signature types.

Normally every kernel function gets an explicit signature: numba compiles it
once, at import, with no literal or layout re-specialisation, and caches it on
disk. While :mod:`fi_design.kernel.build` builds the ahead-of-time
extension (the variable :data:`AOT_BUILD_ENV` is set), the functions stay
lazy instead: the extension compiler types them from the signatures
recorded in :data:`SIGNATURES` and compiles them into the extension, so
nothing is compiled twice.
"""

from __future__ import annotations

import os

from numba import njit
from numba import types as _nt

#: Set while the ahead-of-time extension is built.
AOT_BUILD_ENV = "FI_DESIGN_AOT_BUILD"

f8 = _nt.float64
i8 = _nt.int64
b1 = _nt.boolean
A1 = _nt.float64[::1]
A2 = _nt.float64[:, ::1]
I1 = _nt.int64[::1]


#: Argument types of every kernel function, by name (what the ahead-of-time build exports).
SIGNATURES: dict[str, tuple] = {}


def kernel_function(signature, *, refcounted: bool = False, inline: bool = False):
    """numba's ``njit`` for a kernel function with its explicit ``signature`` (argument types).

    ``refcounted`` keeps numba's reference counting (a function that
    allocates arrays); the helpers go without it, since counting the array
    arguments of every call was half the kernel's run time. ``inline``
    inlines the function into its callers (numba's ``inline="always"``): a
    caller that passes a constant size gets loops of a constant length,
    which the compiler unrolls. An inlined function is compiled on its own
    only if Python calls it (a test): its callers need only its source.
    """
    options = dict(error_model="numpy")
    if not refcounted:
        options["_nrt"] = False
    if inline:
        options["inline"] = "always"
    lazy = bool(os.environ.get(AOT_BUILD_ENV)) or inline

    def decorate(fn):
        SIGNATURES[fn.__name__] = tuple(signature)
        return njit(**options)(fn) if lazy else njit(signature, cache=True, **options)(fn)

    return decorate
