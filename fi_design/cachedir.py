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
    """The cache a computation was asked to use: ``cache`` itself when it is a ``kind``,
    None for None or False, ``kind()`` (its default folder) for True, else ``kind(cache)``
    (a folder's path)."""
    if cache is None or cache is False:
        return None
    if isinstance(cache, kind):
        return cache
    return kind() if cache is True else kind(cache)
