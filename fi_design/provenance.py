"""Which code made a result: the version, the git commit of a checkout, a digest of the code.

A review board signs a document, not a version number: ``0.1.0`` built from
two different trees gives two different tools. :func:`current_source`
therefore records three things:

- ``version``: the installed distribution's version (``fi_design.__version__``);
- ``commit``: the git commit the package was run from, when it runs from a
  git checkout that tracks it (an editable install, ``python -m fi_design``
  in the repository), with ``modified`` telling whether the package's files
  (``fi_design/`` and ``templates/``) differ from that commit, untracked files
  included; None for an installed wheel;
- ``code_sha256``: the SHA-256 over the package's source files, always. It
  covers every ``*.py``, ``*.yaml``, ``*.jinja`` and ``*.css`` file of the
  package and its report templates (compiled kernels and caches left out),
  each named by its path inside the installed package
  (``fi_design/report/meta.py``, ``fi_design/templates/report.css``), so a
  source tree and the wheel built from it give the same digest. The digest is
  the SHA-256 of the lines ``PATH<NUL>SHA256-OF-THE-FILE<LF>`` in path order.

:func:`header` is the provenance every JSON result opens with
(``fi_design_version``, ``fi_design_source`` and, for a result of one spec,
``spec_sha256``), :func:`json_sha256` the one digest of JSON data (the spec
hashes itself with it: :meth:`fi_design.spec.Spec.sha256`).

Nothing here imports the rest of the package: every layer may record its source.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["Source", "current_source", "code_digest", "code_files", "git_commit", "header",
           "json_sha256", "CODE_SUFFIXES"]

#: Files of the package that make up its code (the compiled kernel is built from them).
CODE_SUFFIXES = (".py", ".yaml", ".jinja", ".css")

#: The package directory (``fi_design/``).
PACKAGE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Source:
    """The code that produced a result.

    Attributes
    ----------
    version : str
        The fi_design version.
    commit : str or None
        Full git commit hash of the checkout the package ran from; None when it
        did not run from a git checkout (an installed wheel).
    modified : bool or None
        True when the package's files differ from ``commit`` (local changes
        or untracked files); None without a commit.
    code_sha256 : str
        SHA-256 over the package's source files (:func:`code_digest`).
    """

    version: str
    commit: str | None
    modified: bool | None
    code_sha256: str

    def to_dict(self) -> dict:
        """The JSON form: ``commit``, ``modified``, ``code_sha256`` (the version is kept
        beside it as ``fi_design_version``).

        Returns
        -------
        dict
        """
        return {"commit": self.commit, "modified": self.modified,
                "code_sha256": self.code_sha256}

    @property
    def revision(self) -> str:
        """The source in words: ``git commit 3f3a...`` (with local changes) or the digest.

        Returns
        -------
        str
        """
        if self.commit is None:
            return f"code SHA-256 {self.code_sha256} (not run from a git checkout)"
        return f"git commit {self.commit}" + (" with local changes" if self.modified else "")

    @property
    def short(self) -> str:
        """A short form for page footers: ``commit 3f3a27b1c2d4`` or ``code 1a2b3c4d5e6f``.

        Returns
        -------
        str
        """
        if self.commit is None:
            return f"code {self.code_sha256[:12]}"
        return f"commit {self.commit[:12]}" + ("+modified" if self.modified else "")


def json_sha256(data: Any) -> str:
    """SHA-256 of JSON data in canonical form (keys sorted, ``str`` for what JSON lacks).

    Parameters
    ----------
    data : dict, list or scalar
        Plain data.

    Returns
    -------
    str
        Hex digest; equal for equal data whatever its key order. An integer beyond
        Python's decimal conversion limit (``sys.get_int_max_str_digits``) enters in
        hexadecimal, which has no limit, so such data still has a digest (the spec's
        validation then names the field).
    """
    try:
        text = json.dumps(data, sort_keys=True, default=str)
    except ValueError:  # an integer too long for decimal text
        text = json.dumps(_hex_huge(data), sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _hex_huge(data: Any) -> Any:
    """``data`` with every integer longer than decimal text allows written as ``"int:0x..."``."""
    if isinstance(data, dict):
        return {k: _hex_huge(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [_hex_huge(v) for v in data]
    if isinstance(data, int) and not isinstance(data, bool) and data.bit_length() > 4000:
        return f"int:{hex(data)}"
    return data


def header(version: str | None = None, source: Source | None = None,
           spec: Any = None) -> dict:
    """The provenance a JSON result writes: which code made it, from which spec.

    Parameters
    ----------
    version : str, optional
        The fi_design version that made the result; default this one.
    source : Source, optional
        The code that made it; default :func:`current_source`.
    spec : fi_design.spec.Spec or str, optional
        The spec of a result of one spec, or its digest taken when the result was
        made; its :meth:`~fi_design.spec.Spec.sha256` is written as ``spec_sha256``.

    Returns
    -------
    dict
        ``fi_design_version``, ``fi_design_source`` (:meth:`Source.to_dict`) and,
        with a spec, ``spec_sha256``.
    """
    if version is None:
        from . import __version__ as version
    out = {"fi_design_version": version,
           "fi_design_source": (source if source is not None else current_source()).to_dict()}
    if spec is not None:
        out["spec_sha256"] = spec if isinstance(spec, str) else spec.sha256()
    return out


def _templates(package: Path) -> Path | None:
    """The report templates: inside an installed package, or beside it in a source tree."""
    for candidate in (package / "templates", package.parent / "templates"):
        if (candidate / "report.html.jinja").is_file():
            return candidate
    return None


def code_files(package: Path | None = None) -> dict[str, Path]:
    """The files :func:`code_digest` covers, by their path inside the installed package.

    Parameters
    ----------
    package : pathlib.Path, optional
        The ``fi_design`` package directory; default this one.

    Returns
    -------
    dict of str to pathlib.Path
        ``"fi_design/report/meta.py"`` (POSIX path, as in the wheel) to the file.
    """
    package = Path(package) if package is not None else PACKAGE
    files: dict[str, Path] = {}
    templates = _templates(package)
    for path in package.rglob("*"):
        rel = path.relative_to(package)
        if "__pycache__" in rel.parts or not path.is_file() or path.suffix not in CODE_SUFFIXES:
            continue
        if templates is not None and templates == package / "templates" and \
                rel.parts[0] == "templates":
            continue  # added below, the same way from either place
        files["fi_design/" + rel.as_posix()] = path
    if templates is not None:
        for path in templates.iterdir():
            if path.is_file() and path.suffix in CODE_SUFFIXES:
                files[f"fi_design/templates/{path.name}"] = path
    return dict(sorted(files.items()))


def code_digest(package: Path | None = None) -> str:
    """SHA-256 over the package's source files, the same for a source tree and its wheel.

    Parameters
    ----------
    package : pathlib.Path, optional
        The ``fi_design`` package directory; default this one.

    Returns
    -------
    str
        64 hex digits: SHA-256 of ``PATH<NUL>SHA256<LF>`` per file of
        :func:`code_files`, in path order.
    """
    outer = hashlib.sha256()
    for name, path in code_files(package).items():
        inner = hashlib.sha256(path.read_bytes()).hexdigest()
        outer.update(f"{name}\0{inner}\n".encode())
    return outer.hexdigest()


def _git(args: list[str], cwd: Path) -> str | None:
    env = {k: v for k, v in os.environ.items() if not k.startswith("GIT_")}
    env["GIT_OPTIONAL_LOCKS"] = "0"  # `git status` must not write the index
    try:
        done = subprocess.run(["git", *args], cwd=cwd, env=env, capture_output=True, text=True,
                              timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout if done.returncode == 0 else None


def git_commit(package: Path | None = None) -> tuple[str | None, bool | None]:
    """The git commit the package runs from, and whether its files differ from it.

    Only a checkout that tracks the package counts: a package installed into
    some other repository's tree has no commit.

    Parameters
    ----------
    package : pathlib.Path, optional
        The ``fi_design`` package directory; default this one.

    Returns
    -------
    commit : str or None
        Full hash of ``HEAD``; None outside a git checkout, without git, or
        when the checkout does not track ``fi_design/__init__.py``.
    modified : bool or None
        Whether ``git status`` lists changes (untracked files included) under
        ``fi_design/`` or ``templates/``; None without a commit.
    """
    package = Path(package) if package is not None else PACKAGE
    if _git(["ls-files", "--error-unmatch", "__init__.py"], package) is None:
        return None, None
    head = _git(["rev-parse", "HEAD"], package)
    if head is None or len(head.strip()) < 40:
        return None, None
    paths = [package.name] + (["templates"] if (package.parent / "templates").is_dir() else [])
    status = _git(["status", "--porcelain", "--", *paths], package.parent)
    return head.strip(), None if status is None else bool(status.strip())


@functools.lru_cache(maxsize=1)
def current_source() -> Source:
    """The :class:`Source` of the running package (computed once per process).

    Returns
    -------
    Source
    """
    from . import __version__

    commit, modified = git_commit()
    return Source(__version__, commit, modified, code_digest())
