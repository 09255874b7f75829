"""The design search's results kept on disk: the same spec searched again is read back.

The search (:func:`fi_design.recommend.recommend`) is a function of the spec
and the code: the executor changes where its candidates run, the progress
callback what is said meanwhile, never what it finds. Yet it runs again and
again on one spec: the design command searches when its verdict is FAIL, its
next step (``fi-design recommend SPEC --write-spec OUT.yaml``) searches again,
and so does a second report of the same spec (HTML, then PDF) or a CI job.
:class:`SearchStore` keeps each result in one file of a folder,
``<folder>/<key>.pickle``, and gives it back to the next search of the same
spec:

- the key (:func:`search_key`) is a SHA-256 over everything the result depends
  on: the spec's validated values (:meth:`fi_design.spec.Spec.content_sha256`),
  the form it was written in (the least change of the spec is worded in the
  units the spec file wrote), the fi_design version, the digest of the
  package's source (:func:`fi_design.studies.cache.code_digest`: any edit of the
  code misses) and the versions of Python and of the numerical libraries;
- an entry is written whole (a temporary file in the folder, moved into place
  with :func:`os.replace`), never by a run that was interrupted;
- an entry that cannot be read (cut short, corrupt, from another build of a
  library) is ignored and the search runs again; a folder that cannot be
  written costs the entry and a logged warning, never the result.

The entries are pickles of :class:`~fi_design.results.recommend.RecommendResult`
(without the spec, which the caller's takes the place of): a cache of the
user's own results, in the user's cache folder
(:func:`fi_design.cachedir.cache_dir` ``("recommend")``); any of them may be
deleted at any time.
"""

from __future__ import annotations

import contextlib
import functools
import logging
import os
import pickle
import platform
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import Any

from .. import interrupts
from ..cachedir import cache_dir, opened
from ..provenance import json_sha256
from ..results.recommend import RecommendResult

log = logging.getLogger(__name__)

__all__ = ["FORMAT", "KIND", "LIBRARIES", "SearchStore", "open_store", "search_key"]

#: The cache folder's kind (:func:`fi_design.cachedir.cache_dir`).
KIND = "recommend"
#: Layout of an entry (part of the key): bump it when the entry's form changes.
FORMAT = 1
#: The distributions whose code computes the search besides fi_design's own (part of the key).
LIBRARIES = ("numpy", "scipy", "control", "numba")


@functools.lru_cache(maxsize=1)
def _environment() -> tuple[tuple[str, str | None], ...]:
    """Python's version and those of :data:`LIBRARIES` (None: not installed)."""
    from importlib.metadata import PackageNotFoundError, version

    found: list[tuple[str, str | None]] = [("python", platform.python_version())]
    for name in LIBRARIES:
        try:
            found.append((name, version(name)))
        except PackageNotFoundError:
            found.append((name, None))
    return tuple(found)


def search_key(spec: Any) -> str:
    """The key of a spec's design search: what the result depends on, hashed.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec searched from.

    Returns
    -------
    str
        SHA-256 hex digest over the spec's validated values, its written form
        (the mapping as the file wrote it, units included; None for a spec
        built in code), the fi_design version, the package's code digest, the
        versions of Python and of :data:`LIBRARIES`, and :data:`FORMAT`.
    """
    from .. import __version__
    from ..spec.file import origin
    from ..studies.cache import code_digest

    org = origin(spec)
    return json_sha256({"format": FORMAT, "spec": spec.content_sha256(),
                        "written": None if org is None else json_sha256(org.raw),
                        "version": __version__, "code": code_digest(),
                        "environment": [list(x) for x in _environment()]})


class SearchStore:
    """The design searches' results in a folder, one file per search.

    Parameters
    ----------
    directory : str or os.PathLike, optional
        The folder; default :func:`fi_design.cachedir.cache_dir` ``("recommend")``
        (``$FI_DESIGN_CACHE_DIR/recommend`` when the variable is set). Created on
        the first write.
    """

    SUFFIX = ".pickle"

    def __init__(self, directory: str | os.PathLike | None = None) -> None:
        self.directory = Path(directory) if directory is not None else cache_dir(KIND)

    def entry(self, spec: Any) -> Path:
        """The file that holds (or would hold) the search of ``spec``."""
        return self.directory / f"{search_key(spec)}{self.SUFFIX}"

    def get(self, spec: Any) -> RecommendResult | None:
        """The stored search of ``spec``, or None.

        Parameters
        ----------
        spec : fi_design.spec.Spec
            The spec searched from; the result returned holds it.

        Returns
        -------
        RecommendResult or None
            The result as the search computed it, with ``spec`` the one given
            and ``from_cache`` the entry's path; None when there is no entry,
            or one that cannot be read (logged; the search then runs again).
        """
        path = self.entry(spec)
        try:
            with open(path, "rb") as fh:
                data = pickle.load(fh)
        except FileNotFoundError:
            return None
        except Exception as exc:  # noqa: BLE001 -- anything unpickling raises: compute again
            log.warning("the design search's cache entry %s cannot be read (%s: %s); the search "
                        "runs again", path, type(exc).__name__, exc)
            return None
        result = data.get("result") if isinstance(data, dict) else None
        if not isinstance(result, RecommendResult) or data.get("key") != path.stem:
            log.warning("the design search's cache entry %s is not one; the search runs again",
                        path)
            return None
        return replace(result, spec=spec, from_cache=str(path))

    def put(self, spec: Any, result: RecommendResult) -> Path | None:
        """Store the search of ``spec`` (a run that was interrupted stores nothing).

        Parameters
        ----------
        spec : fi_design.spec.Spec
            The spec searched from.
        result : RecommendResult
            Its search, as computed.

        Returns
        -------
        pathlib.Path or None
            The entry written; None when nothing was (an interrupted run, or a
            folder that cannot be written: logged as a warning).
        """
        if interrupts.received():  # a result an interruption may have cut short is not kept
            return None
        path = self.entry(spec)
        data = {"key": path.stem, "result": replace(result, spec=None, from_cache=None)}
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            with interrupts.held():  # made, written and moved, or removed: never left behind
                fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp",
                                           dir=self.directory)
                try:
                    with os.fdopen(fd, "wb") as fh:
                        pickle.dump(data, fh, protocol=pickle.HIGHEST_PROTOCOL)
                    os.replace(tmp, path)
                except BaseException:
                    with contextlib.suppress(OSError):
                        os.unlink(tmp)
                    raise
        except Exception as exc:  # noqa: BLE001 -- the cache never fails the search
            log.warning("the design search's result was not cached in %s (%s: %s)",
                        self.directory, type(exc).__name__, exc)
            return None
        return path

    def __repr__(self) -> str:
        return f"SearchStore({str(self.directory)!r})"


def open_store(cache: SearchStore | str | os.PathLike | bool | None) -> SearchStore | None:
    """The store a search was asked to use.

    Parameters
    ----------
    cache : SearchStore, path, bool or None
        A store; a folder's path for one; True for the default folder
        (:func:`fi_design.cachedir.cache_dir` ``("recommend")``); None or False
        for none.

    Returns
    -------
    SearchStore or None
    """
    return opened(SearchStore, cache)
