"""A recommendation the tool itself would sign off: the search, its objective and constraints.

The guideline's steps bound the design (k_max = Fs / stroke, the parasitic
limit on the crossover); the user's question is what to build.
:func:`recommend` searches buildable leaf-spring guides, their stroke and
the loop's crossover for the stiffest joint that keeps the hunting margin
(``requirements.hunting_margin``) with its reserves
(``requirements.reserve``) and passes the sign-off, and the least change of
the spec that passes:

- :mod:`.space`: the design space (the base spec, the envelope of strokes, a
  candidate as spec values);
- :mod:`.constraints`: what a design must meet (the crossover's cap, a guide
  from stock, the loop with its reserve, the stage's answer, the reserve
  corners);
- :mod:`.objective`: the stiffest joint first, what binds, the trade-off;
- :mod:`.search`: the search itself;
- :mod:`.least`: the least change of the spec that passes;
- :mod:`.write`: the design written into the user's spec;
- :mod:`.stored`: the searches kept on disk, read back for the same spec and
  code (``recommend(..., cache=True)``).
"""

from __future__ import annotations

import inspect
import sys
import types

from .search import recommend
from .write import recommended_spec_text, recommended_values

__all__ = ["recommend", "recommended_values", "recommended_spec_text"]


class _Searching(types.ModuleType):
    """This package, called as its search: ``fi_design.recommend(spec, ...)`` runs
    :func:`recommend`, whether the name was reached as the package's attribute, by
    ``import fi_design.recommend`` or by ``from fi_design import recommend``; its
    submodules stay attributes (``import fi_design.recommend.search as s``)."""

    def __call__(self, *args, **kwargs):
        return self.recommend(*args, **kwargs)


sys.modules[__name__].__class__ = _Searching
#: What :func:`inspect.signature` and ``help`` show for the package called: the search's.
__signature__ = inspect.signature(recommend)
