"""Where fi_design keeps what it can compute again: one user cache folder per kind.

``$FI_DESIGN_CACHE_DIR`` names the root when set (tests point it at a temporary
folder); otherwise the user cache directory of the platform
(``platformdirs.user_cache_dir("fi_design")``). Everything in it can be
deleted at any time: it is only ever read back as a shortcut to a result the
code would compute anyway.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

#: Environment variable naming the cache root.
CACHE_ENV = "FI_DESIGN_CACHE_DIR"


def cache_dir(kind: str) -> Path:
    """The cache folder of one kind (``"studies"``, ``"equations"``); not created here."""
    root = os.environ.get(CACHE_ENV, "").strip()
    if root:
        return Path(root).expanduser() / kind
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("fi_design")) / kind


def opened(kind: type, cache: Any) -> Any:
    """The cache a computation was asked to use.

    Parameters
    ----------
    kind : type
        The cache's class (``PointCache``, ``SearchStore``): built from a
        folder's path, or without one for its default folder, and holding it
        as ``directory``.
    cache : kind, bool, str, os.PathLike or None
        ``cache`` itself when it is a ``kind``; None or False for none; True
        for the default folder; a folder's path (created when missing).

    Returns
    -------
    kind or None

    Raises
    ------
    fi_design.errors.ArgumentError
        ``cache`` is none of these, or a path to a file (or into one), not a folder.
    """
    from .errors import ArgumentError

    if cache is None or cache is False:
        return None
    if isinstance(cache, kind):
        return cache
    if cache is True:  # the user's folder: one that cannot be made is the cache's to report
        return kind()
    if not isinstance(cache, (str, os.PathLike)):
        raise ArgumentError(f"cache must be None, True or False, a folder's path or a "
                            f"{kind.__name__}, got {type(cache).__name__} {cache!r}")
    blocker = _file_in_the_way(Path(cache))
    if blocker is not None:
        raise ArgumentError(f"cache must be a folder (created when missing), but {blocker} is "
                            "a file")
    return kind(cache)


def _file_in_the_way(folder: Path) -> Path | None:
    """The file at ``folder`` or at the nearest of its parents that exists; None when that
    is a folder."""
    for path in (folder, *folder.parents):
        if path.exists():
            return None if path.is_dir() else path
    return None
