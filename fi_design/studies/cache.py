"""The result cache of the parameter studies: one SQLite file of point outcomes.

Every point's outcome is stored under a key that hashes everything that
decides it (:func:`point_key`): the spec's values, the point's values, the
plant, the fi_design version, a digest of the package's code
(:func:`code_digest`) and the solver method. A repeated study, or one resumed
after an interruption, takes finished points from here.
"""

from __future__ import annotations

import hashlib
import json
import os
import sqlite3
import time as _time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .. import provenance
from ..cachedir import CACHE_ENV, cache_dir, opened
from ..errors import CacheError

__all__ = ["CACHE_ENV", "METHOD", "PointCache", "default_cache_dir", "open_cache", "code_digest",
           "point_key"]

#: Environment variable naming the cache directory (tests and CI point it at a temporary one).
#: Solver method the studies use (part of the cache key).
METHOD = "fast"


def default_cache_dir() -> Path:
    """The cache directory of the studies: :func:`fi_design.cachedir.cache_dir` ``("studies")``.

    Returns
    -------
    pathlib.Path
        ``$FI_DESIGN_CACHE_DIR/studies`` when the variable is set, else
        ``platformdirs.user_cache_dir("fi_design") / "studies"``.
    """
    return cache_dir("studies")


class PointCache:
    """Content-addressed store of point outcomes: one SQLite file in a directory.

    Keys are SHA-256 digests of everything that decides a point's outcome (see
    :func:`point_key`); values are the outcomes as JSON. Outcomes are written
    per finished chunk, in one transaction, so an interrupted sweep keeps all
    chunks that finished. Only the calling process reads and writes the file;
    SQLite's locking keeps two concurrent sweeps on one cache consistent.

    Parameters
    ----------
    directory : str or os.PathLike, optional
        Where the cache lives; default :func:`default_cache_dir`. Created on
        first write.
    """

    FILE = "points.sqlite"

    def __init__(self, directory: str | os.PathLike | None = None) -> None:
        self.directory = Path(directory) if directory is not None else default_cache_dir()
        self._conn: sqlite3.Connection | None = None

    @property
    def path(self) -> Path:
        """The SQLite file."""
        return self.directory / self.FILE

    def _connect(self, create: bool) -> sqlite3.Connection | None:
        if self._conn is not None:
            return self._conn
        if not create and not self.path.exists():
            return None
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            conn = sqlite3.connect(self.path, timeout=30.0, check_same_thread=False)
            conn.execute("CREATE TABLE IF NOT EXISTS points (key TEXT PRIMARY KEY, "
                         "outcome TEXT NOT NULL, created REAL NOT NULL)")
            conn.commit()
        except (OSError, sqlite3.Error) as exc:
            raise CacheError(f"cannot open the result cache {self.path}: {exc}; use --no-cache "
                             f"or set {CACHE_ENV} to a writable directory") from None
        self._conn = conn
        return conn

    def get_many(self, keys: Sequence[str]) -> dict[str, dict]:
        """Outcomes stored under ``keys`` (missing keys are left out).

        Parameters
        ----------
        keys : sequence of str
            Point keys.

        Returns
        -------
        dict
            Key to outcome.
        """
        conn = self._connect(create=False)
        if conn is None or not keys:
            return {}
        out: dict[str, dict] = {}
        keys = list(keys)
        try:
            for i in range(0, len(keys), 500):
                part = keys[i:i + 500]
                rows = conn.execute(f"SELECT key, outcome FROM points WHERE key IN "
                                    f"({','.join('?' * len(part))})", part).fetchall()
                out.update((k, json.loads(v)) for k, v in rows)
        except (sqlite3.Error, ValueError) as exc:
            raise CacheError(f"cannot read the result cache {self.path}: {exc}; use --no-cache "
                             "or delete the file") from None
        return out

    def put_many(self, items: Mapping[str, dict]) -> None:
        """Store outcomes (one transaction).

        Parameters
        ----------
        items : mapping of str to dict
            Key to outcome (JSON-able).
        """
        if not items:
            return
        conn = self._connect(create=True)
        now = _time.time()
        try:
            with conn:
                conn.executemany("INSERT OR REPLACE INTO points (key, outcome, created) "
                                 "VALUES (?, ?, ?)",
                                 [(k, json.dumps(v), now) for k, v in items.items()])
        except sqlite3.Error as exc:
            raise CacheError(f"cannot write the result cache {self.path}: {exc}; use "
                             "--no-cache") from None

    def __len__(self) -> int:
        conn = self._connect(create=False)
        if conn is None:
            return 0
        return int(conn.execute("SELECT COUNT(*) FROM points").fetchone()[0])

    def clear(self) -> None:
        """Delete every stored outcome."""
        conn = self._connect(create=False)
        if conn is not None:
            with conn:
                conn.execute("DELETE FROM points")

    def close(self) -> None:
        """Close the database connection (it reopens on the next use)."""
        if self._conn is not None:
            self._conn.close()
            self._conn = None

    def __getstate__(self) -> dict:  # picklable: the connection stays behind
        return {"directory": self.directory, "_conn": None}

    def __repr__(self) -> str:
        return f"PointCache({str(self.directory)!r})"


_CODE_DIGEST: str | None = None


def code_digest() -> str:
    """SHA-256 over every source file of the package (:func:`fi_design.provenance.code_digest`).

    Part of every cache key, so editing the model, the solver, the metric or
    anything they read never reuses outcomes computed by older code (even
    without a version bump). No hand-kept list of the modules that matter: a
    new or renamed module is covered as it is. Computed once per process.

    Returns
    -------
    str
        Hex digest.
    """
    global _CODE_DIGEST
    if _CODE_DIGEST is None:
        _CODE_DIGEST = provenance.code_digest()
    return _CODE_DIGEST


def point_key(spec_hash: str, values: Sequence[tuple[str, Any]], isolated: bool,
              measure: str = "move") -> str:
    """The cache key of one point.

    Parameters
    ----------
    spec_hash : str
        :meth:`~fi_design.spec.Spec.content_sha256` of the base spec.
    values : sequence of (path, value)
        The point's values.
    isolated : bool
        The plant simulated.
    measure : {"move", "stage"}
        What a point measures (the spec's move, or the stage over its moves).

    Returns
    -------
    str
        SHA-256 hex digest over the spec, the values (exact float repr), the
        plant, the measure, the fi_design version, :func:`code_digest` and the
        solver method.
    """
    from .. import __version__

    payload = json.dumps({"spec": spec_hash, "values": [[p, v] for p, v in values],
                          "isolated": bool(isolated), "version": __version__,
                          "code": code_digest(), "method": METHOD, "measure": measure},
                         sort_keys=True, default=str)
    return hashlib.sha256(payload.encode()).hexdigest()


def open_cache(cache: PointCache | str | os.PathLike | bool | None) -> PointCache | None:
    """The cache a study was asked to use.

    Parameters
    ----------
    cache : PointCache, path, bool or None
        A cache; a directory path for one; True for the default directory
        (:func:`default_cache_dir`); None or False for none.

    Returns
    -------
    PointCache or None
    """
    return opened(PointCache, cache)
