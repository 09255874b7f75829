"""Output files: checked before the work starts, written atomically.

Every command that writes a file (JSON, report, CSV, a fixed spec) does two
things with it:

1. :func:`check_output` (:func:`check_outputs` for several, :func:`check_output_dir`
   for a directory of them) before any long computation, so a run never spends a
   minute and then fails on a path it could have refused at once. It refuses
   an existing file without ``force``, the spec itself (even with ``force``, and
   also when reached through a symlink or a hard link), a wrong extension, a
   directory and a missing parent directory.
2. :func:`write_atomic` (or :func:`atomic_path` for writers that want a file
   name) to write it: the data goes to a temporary file in the same directory,
   is flushed to disk and moved into place with :func:`os.replace`. A failure
   leaves the old file untouched and no temporary file behind; a reader never
   sees half a file. SIGINT, SIGTERM and SIGHUP are held while the temporary
   file is made and removed (:func:`fi_design.interrupts.held`), so an
   interruption (translated into an exception, as the command line does)
   always removes it; and a run interrupted before the move never makes it,
   even when the interruption's exception was swallowed on its way
   (:func:`fi_design.interrupts.raise_received`).

The check also *claims* the path for the run (in the current
:mod:`contextvars` context; the command line runs every command in a context
of its own): it notes the file found there, or that there was none. The
write then replaces only that file. A file that appeared during the run is
not replaced without ``force``, and a file that another run wrote after the
check is not replaced at all: of two runs writing one path, the first to
finish writes it and the other raises :class:`~fi_design.errors.OutputError`
saying so. Writers of one directory take turns (an exclusive ``flock`` on
it) while they compare and move. A path nobody checked is replaced as before.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import tempfile
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

from . import interrupts
from .errors import OutputError


@dataclass(frozen=True)
class Claim:
    """An output path as a run checked it.

    Attributes
    ----------
    force : bool
        Whether the run may replace a file found at the check.
    found : tuple or None
        Identity of the file found then (device, inode, size, mtime in ns), None: no file.
    """

    force: bool
    found: tuple | None


#: The outputs the current run checked, by resolved path (see the module docstring).
_CLAIMS: contextvars.ContextVar[dict | None] = contextvars.ContextVar("fi_design_output_claims",
                                                                     default=None)
#: The files the current run has written, in order.
_WRITTEN: contextvars.ContextVar[tuple] = contextvars.ContextVar("fi_design_output_written",
                                                                 default=())


def check_output(path: str | os.PathLike, *, force: bool = False,
                 protect: Iterable[str | os.PathLike | None] = (),
                 extensions: Iterable[str] = (), force_flag: str = "--force") -> Path:
    """Refuse an output path before the work starts.

    Parameters
    ----------
    path : str or os.PathLike
        The file the command is asked to write.
    force : bool, optional
        Allow overwriting an existing file. Default False.
    protect : iterable of path, optional
        Files that must never be overwritten, even with ``force`` (the spec,
        the measured data, another output of the same run). ``None`` entries
        are ignored. Compared by resolved path and, for existing files, with
        :func:`os.path.samefile` (which also catches hard links).
    extensions : iterable of str, optional
        Allowed suffixes, e.g. ``(".json",)`` or ``(".html", ".pdf")``;
        compared case-insensitively. Empty: any suffix.
    force_flag : str, optional
        How the caller allows overwriting, for the messages: ``"--force"`` (the
        command line), ``"force=True"`` (a library function).

    Returns
    -------
    pathlib.Path
        ``path`` as a :class:`~pathlib.Path`.

    Raises
    ------
    OutputError
        The path is refused; the message says why and what to do.
    """
    out = Path(path)
    exts = tuple(e.lower() if e.startswith(".") else "." + e.lower() for e in extensions)
    for other in protect:
        if other is None:
            continue
        if _same_file(out, Path(other)):
            raise OutputError(f"{out}: refusing to overwrite the input file {other} "
                              f"(not even with {force_flag}); choose another output name")
    if out.is_dir():
        raise OutputError(f"{out}: is a directory; give a file name")
    if exts and out.suffix.lower() not in exts:
        want = " or ".join(exts)
        raise OutputError(f"{out}: output file name must end with {want}")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.exists():
        raise OutputError(f"{out}: directory {parent} does not exist")
    if not parent.is_dir():
        raise OutputError(f"{out}: {parent} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"{out}: directory {parent} is not writable")
    if out.exists() or out.is_symlink():
        if not force:
            raise OutputError(f"{out}: file exists; use {force_flag} to overwrite it")
        if out.exists() and not out.is_file():
            raise OutputError(f"{out}: exists and is not a regular file")
    _claim(out, force)
    return out


def claimed(path: str | os.PathLike) -> bool:
    """Whether the current run has checked ``path`` (:func:`check_output`) and so owns it.

    A library function that writes a file checks it itself unless its caller
    (the command line) did, with the user's ``--force``; the claim then
    decides at the move what may be replaced.

    Parameters
    ----------
    path : str or os.PathLike
        The output file.

    Returns
    -------
    bool
    """
    return os.path.realpath(path) in (_CLAIMS.get() or {})


def _claim(out: Path, force: bool) -> None:
    """Note, for this run, the file found at ``out`` now (see the module docstring)."""
    _set_claim(os.path.realpath(out), Claim(force=force, found=_identity(out)))


def _set_claim(key: str, claim: Claim) -> None:
    """Record a claim in a new mapping: a copied context never shares another run's claims."""
    _CLAIMS.set({**(_CLAIMS.get() or {}), key: claim})


def _identity(path: Path) -> tuple | None:
    """Device, inode, size and modification time of a file; None when there is none."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


def check_outputs(inputs: Iterable[str | os.PathLike], *, force: bool = False,
                  **paths: tuple[str | os.PathLike | None, tuple[str, ...]]) -> dict:
    """Refuse several output paths of one run before the work starts.

    Parameters
    ----------
    inputs : iterable of path
        The run's input files: never overwritten (see :func:`check_output`).
    force : bool, optional
        Allow overwriting existing files.
    **paths : (path or None, extensions)
        Each output by name, with its allowed extensions; None when not asked.
        The names are those the error message gives (the command line passes
        its options', ``"--json"``).

    Returns
    -------
    dict
        Name to the checked :class:`~pathlib.Path` (None for outputs not asked).

    Raises
    ------
    OutputError
        A path is refused, or two outputs name the same file.
    """
    out: dict = {}
    protect = tuple(inputs)
    for name, (path, exts) in paths.items():
        if path is None:
            out[name] = None
            continue
        for other, seen in out.items():
            if seen is not None and _same_file(Path(path), seen):
                raise OutputError(f"{path}: {other} and {name} name the same file; give each "
                                  "output its own file")
        out[name] = check_output(path, force=force, protect=protect, extensions=exts)
    return out


def check_output_dir(directory: str | os.PathLike, names: Iterable[str], *,
                     force: bool = False,
                     protect: Iterable[str | os.PathLike | None] = (),
                     stale: Iterable[str] = (), force_flag: str = "--force") -> dict:
    """Refuse a directory of outputs before the work starts (it may not exist yet).

    Parameters
    ----------
    directory : str or os.PathLike
        Where the files go; created by the caller when missing (its parent
        must exist).
    names : iterable of str
        The file names inside it.
    force : bool, optional
        Allow overwriting existing files.
    protect : iterable of path, optional
        Files never overwritten.
    stale : iterable of str, optional
        Names of files the command writes there in other runs but not in this
        one (a study's maps left out): one found there would lie beside
        outputs it does not belong to, so it is refused without ``force``
        and, with ``force``, claimed for :func:`remove_output` once the new
        files are written.
    force_flag : str, optional
        How the caller allows overwriting, for the messages: ``"--force"`` (the
        command line), ``"force=True"`` (a library function); as for
        :func:`check_output`.

    Returns
    -------
    dict
        File name to its :class:`~pathlib.Path` in ``directory`` (``names`` only).

    Raises
    ------
    OutputError
        ``directory`` is a file, its parent is missing, or a file is refused.
    """
    out = Path(directory)
    if out.exists() and not out.is_dir():
        raise OutputError(f"{out}: exists and is not a directory")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise OutputError(f"{out}: directory {parent} does not exist")
    targets = {}
    for name in names:
        if out.is_dir():
            check_output(out / name, force=force, protect=protect, force_flag=force_flag)
        else:
            _claim(out / name, force)
        targets[name] = out / name
    for name in stale:
        old = out / name
        if name in targets or not (old.exists() or old.is_symlink()):
            continue
        if not force:
            raise OutputError(f"{old}: file exists, an output of an earlier run that this one "
                              f"does not write; use {force_flag} to remove it, or choose "
                              "another directory")
        check_output(old, force=True, protect=protect, force_flag=force_flag)
    return targets


def remove_output(path: str | os.PathLike) -> bool:
    """Remove a stale output that the run checked with ``force`` (:func:`check_output_dir`).

    Only the file found at the check goes: one written there since (by
    another run) is kept, and so is a path the run did not check with
    ``force``. An interrupted run removes nothing.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    bool
        Whether it was removed.
    """
    out = Path(path)
    key = os.path.realpath(out)
    claim = (_CLAIMS.get() or {}).get(key)
    if claim is None or not claim.force or claim.found is None:
        return False
    interrupts.raise_received()
    parent = out.parent if str(out.parent) else Path(".")
    with _directory_lock(parent):
        if _identity(out) != claim.found:
            return False
        try:
            os.unlink(out)
        except OSError as exc:
            raise OutputError(f"{out}: cannot remove ({exc.strerror or exc})") from None
    _set_claim(key, Claim(force=True, found=None))
    return True


def _same_file(a: Path, b: Path) -> bool:
    try:
        if os.path.realpath(a) == os.path.realpath(b):
            return True
    except (OSError, ValueError):
        pass
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Give a temporary file name that becomes ``path`` when the block succeeds.

    For writers that want a file name (weasyprint's ``write_pdf``,
    ``Figure.savefig``, ``csv``). The temporary file lies in the same directory
    as ``path`` (so the final :func:`os.replace` is atomic), is fsynced, gets
    the permissions a new file would get (or those of the file it replaces),
    and is removed if the block raises.

    Parameters
    ----------
    path : str or os.PathLike
        The final file name.

    Yields
    ------
    pathlib.Path
        The temporary file to write (it exists, empty).

    Raises
    ------
    OutputError
        The temporary file cannot be created or moved into place.
    """
    out = Path(path)
    parent = out.parent if str(out.parent) else Path(".")
    made: list[Path] = []
    try:
        with interrupts.held():  # a signal meanwhile comes at the end, the file then known
            try:
                fd, tmp_name = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".tmp",
                                                dir=parent)
            except OSError as exc:
                raise OutputError(f"{out}: cannot create a file in {parent} ({exc.strerror})") \
                    from None
            made.append(Path(tmp_name))
            os.close(fd)
        tmp = made[0]
        yield tmp
        _fsync_file(tmp)
        os.chmod(tmp, _mode_for(out))
        interrupts.raise_received()  # an interrupted run never writes, whatever swallowed it
        _move(tmp, out, parent)
    except OSError as exc:
        _remove_held(made)
        if isinstance(exc, OutputError):
            raise
        raise OutputError(f"{out}: cannot write ({exc.strerror or exc})") from None
    except BaseException:
        _remove_held(made)
        raise
    _WRITTEN.set((*_WRITTEN.get(), out))
    _fsync_dir(parent)


def _remove_held(made: list[Path]) -> None:
    """Remove the temporary file (if made) with the signals held, then let them through."""
    with interrupts.held():
        for tmp in made:
            _remove(tmp)


def written() -> tuple[Path, ...]:
    """The files this run has moved into place (in the current :mod:`contextvars` context,
    since :func:`begin_run`).

    Returns
    -------
    tuple of pathlib.Path
        In the order they were written.
    """
    return _WRITTEN.get()


def begin_run() -> None:
    """Start the list of :func:`written` files afresh in the current context.

    A copied context starts with the values of the one it was copied from:
    the command line calls this at the start of every command, in the
    command's own context, so that its files are the command's only.
    """
    _WRITTEN.set(())


def _move(tmp: Path, out: Path, parent: Path) -> None:
    """Move the finished temporary file into place, as the run's claim on ``out`` allows."""
    claims = _CLAIMS.get() or {}
    key = os.path.realpath(out)
    claim = claims.get(key)
    if claim is None:
        os.replace(tmp, out)
        return
    with _directory_lock(parent):
        now = _identity(out)
        if now != claim.found:
            if claim.found is None and not claim.force:
                raise OutputError(f"{out}: the file appeared while this run worked; it was not "
                                  "replaced (use --force to overwrite it)")
            raise OutputError(f"{out}: was written by another run after this one checked it; "
                              "that file is kept and this run's result was not written")
        if claim.found is None:
            os.link(tmp, out)  # fails if anyone created the file meanwhile: never clobbers
            os.unlink(tmp)
        else:
            os.replace(tmp, out)
        _set_claim(key, Claim(force=True, found=_identity(out)))  # the run's own file now


@contextlib.contextmanager
def _directory_lock(directory: Path) -> Iterator[None]:
    """Hold an exclusive lock on a directory (writers of one directory take turns)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    fd = os.open(directory, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


def write_atomic(path: str | os.PathLike, data: str | bytes) -> Path:
    """Write ``data`` to ``path`` atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write; check it first with :func:`check_output`.
    data : str or bytes
        The content; text is written as UTF-8.

    Returns
    -------
    pathlib.Path
        ``path`` as a :class:`~pathlib.Path`.

    Raises
    ------
    OutputError
        The file cannot be written; the old file (if any) is untouched and no
        temporary file is left behind.
    """
    payload = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(payload)
    return Path(path)


def _fsync_file(path: Path) -> None:
    with open(path, "rb+") as fh:
        fh.flush()
        os.fsync(fh.fileno())


def _fsync_dir(directory: Path) -> None:
    """Make the rename durable (POSIX); harmless where directories cannot be opened."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _mode_for(out: Path) -> int:
    """Permissions of the file being replaced, else 0o666 minus the umask."""
    try:
        return out.stat().st_mode & 0o7777
    except OSError:
        pass
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def _remove(path: Path) -> None:
    with contextlib.suppress(OSError):
        path.unlink()
