"""The sign-off: the design, and when it fails, a design that passes.

:func:`design` is the library's and the design command's entry point: the
four guideline steps, the simulated confirmation and the verdict
(:func:`fi_design.guideline.evaluate.evaluate`), and, when the verdict fails, the design
search of :func:`fi_design.recommend.recommend` as the result's
``recommendation``: what to build, found by the same computation that signs
a design off.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from .guideline import evaluate as guideline
from .results.design import DesignResult
from .spec import Spec

__all__ = ["design"]


def design(spec: Spec | str | Path | Mapping[str, Any], *, confirm: bool = True,
           executor: Any = None, progress: Callable[[str], None] | None = None,
           recommend: bool = True, fe_check: bool = False,
           sensitivity: bool = False, cache: Any = None) -> DesignResult:
    """Run the guideline on a spec, confirm it by simulation, and recommend when it fails.

    Parameters
    ----------
    spec : Spec, Model, path or mapping
        A validated spec, its resolved model, or a YAML path or mapping.
    confirm : bool, optional
        Simulate (see :func:`fi_design.guideline.evaluate.evaluate`). Default True; a
        design that was not simulated is never recommended on.
    executor : concurrent.futures-style executor, optional
        Runs the simulations (the confirmation, the robustness samples and
        the design search's evaluations); None runs them here. The library
        creates no pool.
    progress : callable, optional
        ``progress(text)`` as the work proceeds.
    recommend : bool, optional
        When the simulated verdict is FAIL, search the design space for a
        design that passes (:func:`fi_design.recommend.recommend`: seconds to
        a minute) and return it as ``recommendation``. Default True.
    fe_check : bool, optional
        Also check the flexure guide with a finite-element model (see
        :func:`fi_design.guideline.evaluate.evaluate`). Default False.
    sensitivity : bool, optional
        Also find how the hunting-free crossover moves with the unidentified
        LuGre values sigma0, sigma1 and vs (see
        :func:`fi_design.guideline.evaluate.evaluate`; a few seconds). Default False;
        the design command runs it for a report.
    cache : bool, path or fi_design.recommend.stored.SearchStore, optional
        Where design searches are kept (see :func:`fi_design.recommend.recommend`):
        None or False (default) none, True the user cache folder, a path that
        folder; the design command keeps them there, so its next step
        (``fi-design recommend``) reads the search back.

    Returns
    -------
    DesignResult

    Raises
    ------
    fi_design.errors.SpecError
        When ``spec`` is a path or mapping that does not validate.
    fi_design.errors.ArgumentError
        ``executor`` is no executor, or ``cache`` none of the above (a file's
        path), before any work.
    """
    from .recommend.stored import open_store

    store = open_store(cache) if recommend else None  # a bad cache refused before the work
    result = guideline.evaluate(spec, confirm=confirm, executor=executor, progress=progress,
                                fe_check=fe_check, sensitivity=sensitivity)
    if not (recommend and result.simulation is not None and result.verdict.status == "FAIL"):
        return result
    from .recommend import recommend as search
    from .guideline.verdict import recommendation

    if progress is not None:
        progress("searching for a design that passes ...")
    found = search(result.spec, executor=executor, progress=progress, cache=store)
    return replace(result, recommendation=recommendation(found))
