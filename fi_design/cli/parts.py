"""The shell of the command line: the application and what its commands share.

- ``app``, a typer application of class :class:`DefaultCommandGroup`:
  ``fi-design SPEC.yaml`` runs the default command, and every command's
  errors become exit codes in one place; ``--version`` and ``--debug``;
- the options several commands take (``SpecArg``, ``Force``, the study
  executor's ``Jobs`` ... ``NoCache``, :func:`output_option`);
- the steps of a command around its one library call: :func:`check_outputs`
  before any work, :func:`load`, :func:`write_outputs` and :func:`write_report`
  after it, and for the studies :func:`study_pool` and :func:`run_study`
  (executor, progress bar, Ctrl-C).

The commands themselves are in :mod:`fi_design.cli.app`.
"""

from __future__ import annotations

import contextlib
import difflib
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer
from typer.core import TyperArgument, TyperCommand, TyperGroup, TyperOption

from ..errors import FiDesignError

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console

DEBUG_ENV = "FI_DESIGN_DEBUG"
#: Command run when the first argument is not a command name.
DEFAULT_COMMAND = "design"

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2
#: Exit code of a design whose verdict is at or below the level of ``--fail-on``.
EXIT_VERDICT = 3
#: Exit code of a study interrupted with Ctrl-C (128 + SIGINT, as shells report it).
EXIT_INTERRUPTED = 130


def _debug_requested(ctx: typer.Context | None = None) -> bool:
    if os.environ.get(DEBUG_ENV, "").strip().lower() not in ("", "0", "false", "no"):
        return True
    return bool(ctx is not None and ctx.params.get("debug"))


class _HelpOption(TyperOption):
    """An option whose help shows its metavar only: no ``<bool>`` beside a flag."""

    def display_type_rich(self, ctx: Any) -> str | None:
        return None if self.is_flag else super().display_type_rich(ctx)


class _HelpArgument(TyperArgument):
    """An argument named by its metavar (``SPEC.yaml``), without ``<path>`` beside it."""

    def display_type_rich(self, ctx: Any) -> str | None:
        return None if self.metavar else super().display_type_rich(ctx)


def plain_help(params: list) -> list:
    """The parameters of a command, made to show their help without type labels (in place)."""
    for param in params:
        if type(param) is TyperOption:
            param.__class__ = _HelpOption
        elif type(param) is TyperArgument:
            param.__class__ = _HelpArgument
    return params


class HelpCommand(TyperCommand):
    """A command whose ``--help`` names each option by its metavar, flags plainly."""

    def get_params(self, ctx: Any) -> list:
        return plain_help(super().get_params(ctx))


class DefaultCommandGroup(TyperGroup):
    """A command group that runs :data:`DEFAULT_COMMAND` when no command is named.

    ``fi-design SPEC.yaml --json out.json`` is read as ``fi-design design
    SPEC.yaml --json out.json``; ``fi-design schema`` still runs ``schema``.
    The group's own flags (``--version``, ``--debug``, ``--help``) may come
    first; ``--debug`` is also accepted anywhere before ``--``. A spec file
    whose name equals a command name can be given as ``./NAME``; a first
    argument that is no file but close to a command's name (``recomend``) is
    refused as a mistyped command (exit 2), not read as a spec.

    The group also translates errors for every command: a
    :class:`~fi_design.errors.FiDesignError` exits 2 with its message, any
    other exception exits 1 with a short "internal error" note (the traceback
    with ``--debug`` or ``FI_DESIGN_DEBUG=1``); SIGTERM and SIGHUP become
    :class:`Terminated` in the main thread, so that temporary files are
    removed and worker processes stopped as after Ctrl-C, and exit with 128
    plus the signal's number; Ctrl-C exits 130. A signal is never lost: held
    while a worker pool starts or a temporary file is made, and raised again
    before any output is written when its first exception was swallowed
    (:mod:`fi_design.interrupts`); an error raised on the way out of an
    interruption reports the interruption. Every command runs in a
    :mod:`contextvars` context of its own (the outputs it claims,
    :mod:`fi_design.output`).
    """

    default_command = DEFAULT_COMMAND

    def get_params(self, ctx: Any) -> list:
        return plain_help(super().get_params(ctx))

    def get_command(self, ctx: Any, cmd_name: str) -> Any:
        command = super().get_command(ctx, cmd_name)
        if type(command) is TyperCommand:  # every command's help without type labels
            command.__class__ = HelpCommand
        return command

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        args = list(args)
        end = args.index("--") if "--" in args else len(args)
        if "--debug" in args[1:end]:
            head = [a for a in args[:end] if a != "--debug"]
            args = ["--debug"] + head + args[end:]
        i = self._skip_group_options(ctx, args)
        if i < len(args) and args[i] != "--" and args[i] not in self.commands:
            close = close_command(Path(args[i]), list(self.commands))
            if close:  # a mistyped command, not a spec: its arguments would confuse design's
                ctx.fail(f"no such command '{args[i]}'; did you mean '{close}'?")
            args.insert(i, self.default_command)
        return super().parse_args(ctx, args)

    def _skip_group_options(self, ctx: Any, args: list[str]) -> int:
        """Index of the first argument that is not one of the group's own options."""
        flags: set[str] = set()
        valued: set[str] = set()
        for param in self.get_params(ctx):
            names = list(getattr(param, "opts", [])) + list(getattr(param, "secondary_opts", []))
            if getattr(param, "is_flag", False) or getattr(param, "count", False):
                flags.update(names)
            else:
                valued.update(n for n in names if n.startswith("-"))
        i = 0
        while i < len(args):
            name = args[i].split("=", 1)[0]
            if name in flags:
                i += 1
            elif name in valued:
                i += 1 if "=" in args[i] else 2
            else:
                break
        return i

    def main(self, *args: Any, **kwargs: Any) -> Any:
        # signals become exceptions before the arguments are parsed (a fifth of a second of
        # building the commands); typer turns an interruption there into a silent exit 130
        from ..interrupts import signals_to_exceptions

        try:
            with signals_to_exceptions(_signal_exception):
                return super().main(*args, **kwargs)
        except SystemExit as exc:
            cause = _interruption(exc)
            if cause is not None:  # not said yet: parsing, or the command had returned
                _say_interrupted(cause, "outside the command")
            raise

    def invoke(self, ctx: Any) -> Any:
        import contextvars

        return contextvars.copy_context().run(self._invoke, ctx)

    def _invoke(self, ctx: Any) -> Any:
        from ..interrupts import signals_to_exceptions
        from ..output import begin_run

        begin_run()
        try:
            with signals_to_exceptions(_signal_exception):
                return super().invoke(ctx)
        except KeyboardInterrupt as exc:  # Ctrl-C, or Terminated (SIGTERM, SIGHUP)
            raise _interrupted(exc) from None
        except (typer.Exit, typer.Abort, typer.TyperException, BrokenPipeError):
            raise  # usage errors, explicit exits, `fi-design ... | head`
        except Exception as exc:  # noqa: BLE001 -- the one place that turns errors into codes
            cause = _interruption(exc)
            if cause is not None:  # an error on the way out of an interruption is not one
                raise _interrupted(cause) from None
            debug = _debug_requested(ctx)
            if debug:
                import traceback

                traceback.print_exc(file=sys.stderr)
            if isinstance(exc, FiDesignError):
                typer.echo(f"error: {exc}", err=True)
                raise typer.Exit(EXIT_BAD_INPUT) from None
            note = "" if debug else (
                f"\nThis is a bug in fi-design, not in your input. Run again with --debug (or "
                f"set {DEBUG_ENV}=1) to see the traceback, and please report it with the spec "
                "file.")
            typer.echo(f"internal error: {type(exc).__name__}: {exc}{note}", err=True)
            raise typer.Exit(EXIT_INTERNAL) from None


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised in the main thread like Ctrl-C's KeyboardInterrupt.

    Attributes
    ----------
    signum : int
        The signal's number.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _signal_exception(signum: int) -> KeyboardInterrupt:
    """The exception of a signal: KeyboardInterrupt for Ctrl-C, :class:`Terminated` else."""
    import signal

    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated(signum)


def _interruption(exc: BaseException) -> KeyboardInterrupt | None:
    """The interruption an error was raised on the way out of, if any.

    An interruption inside the import of a compiled module becomes
    ``ImportError: initialization failed``; stopping an interrupted worker pool
    can fail on a pipe its own thread closed meanwhile. Either error carries
    the KeyboardInterrupt as its cause or context.
    """
    seen: set[int] = set()
    node: BaseException | None = exc
    while node is not None and id(node) not in seen:
        if isinstance(node, KeyboardInterrupt):
            return node
        seen.add(id(node))
        # `raise ... from None` ends the chain: the interruption was handled there
        node = node.__cause__ or (None if node.__suppress_context__ else node.__context__)
    return None


def _interrupted(exc: KeyboardInterrupt) -> typer.Exit:
    """Say that the run was interrupted and what it wrote; the exit (128 + the signal)."""
    _say_interrupted(exc)
    return typer.Exit(128 + exc.signum if isinstance(exc, Terminated) else EXIT_INTERRUPTED)


def run_app(application: typer.Typer) -> None:
    """Run the application as ``fi-design``, signals turned into exceptions from the first
    instant (typer builds the commands before :meth:`DefaultCommandGroup.main` runs).

    Parameters
    ----------
    application : typer.Typer
        The application (:data:`app` with its commands).
    """
    from ..interrupts import signals_to_exceptions

    global _PROCESS_ENDS_WITH_COMMAND
    _PROCESS_ENDS_WITH_COMMAND = True
    if sys.stdout is not None:
        sys.stdout = _ReaderMayLeave(sys.stdout)
    try:
        try:
            with signals_to_exceptions(_signal_exception):
                application(prog_name="fi-design")
        except KeyboardInterrupt as exc:  # before the command began, or as it ended
            _say_interrupted(exc, "outside the command")
            raise SystemExit(128 + exc.signum if isinstance(exc, Terminated) else
                             EXIT_INTERRUPTED) from None
    except SystemExit as exc:
        if exc.code in _INTERRUPTED_CODES:
            _end_without_stuck_threads(exc.code)
        raise
    finally:
        _spare_the_last_collection()


class _ReaderMayLeave:
    """Standard output whose reader may stop reading (``fi-design SPEC --json r.json | head``).

    A closed pipe raised BrokenPipeError from the console's next print, in the middle of
    the command: the run ended with exit 1 and without the files it was asked for. The
    console is a summary of those files; once its reader has gone, the rest of it goes to
    the null device, and the run writes its files and ends as it would have.
    """

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._to_null()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._to_null()

    def _to_null(self) -> None:
        """Point the stream's file descriptor at the null device; what it holds goes there."""
        null = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(null, self._stream.fileno())
        finally:
            os.close(null)
        with contextlib.suppress(OSError):
            self._stream.flush()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


#: The exit codes of an interrupted run: 128 + SIGHUP, SIGINT or SIGTERM.
_INTERRUPTED_CODES = (129, EXIT_INTERRUPTED, 143)
#: How long an interrupted run waits for its threads before it ends without them [s].
THREADS_GRACE = 2.0


def _end_without_stuck_threads(code: int) -> None:
    """End an interrupted run now (``os._exit``) when a thread it would wait for at exit has
    not ended within :data:`THREADS_GRACE`; return when none is left.

    A worker process ended while it wrote its result to its pool (a chunk of points, a
    figure) leaves part of it in the pool's pipe, and the pool's manager thread, a thread
    the interpreter joins at exit, waits for the rest for ever: an interrupted design run
    then never ended (once in 30 Ctrl-Cs into a report's run). By now the run is over:
    its outputs are written or removed, its message is out, its workers are stopped.
    """
    import threading
    import time

    me = threading.current_thread()
    deadline = time.monotonic() + THREADS_GRACE
    for thread in threading.enumerate():
        if thread is me or thread.daemon:
            continue
        thread.join(max(0.0, deadline - time.monotonic()))
        if thread.is_alive():
            for stream in (sys.stdout, sys.stderr):
                with contextlib.suppress(Exception):
                    stream.flush()
            os._exit(code)


#: True in the process :func:`run_app` runs (the console script): it ends when its command
#: has, so what the report leaves behind need not be collected (:func:`write_report`).
_PROCESS_ENDS_WITH_COMMAND = False


@contextlib.contextmanager
def _report_garbage_kept() -> Iterator[None]:
    """Python's cyclic garbage collector paused while a report is made, and what the report
    built frozen after it (:func:`gc.freeze`) instead of collected, in the process of
    :func:`run_app` only: the command ends with its report.

    A PDF's layout leaves some 2 x 10^5 objects in reference cycles (WeasyPrint's boxes and
    styles); the collector paused in :func:`fi_design.report.render.write_document` went
    through them when it was enabled again (0.1 s), and once more over the whole heap
    while WeasyPrint was imported (0.1 s). The process's end frees them all at once
    (:func:`_spare_the_last_collection`). Elsewhere (a test's CliRunner, a library
    caller) the collector is left alone.
    """
    import gc

    if not _PROCESS_ENDS_WITH_COMMAND or not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        gc.enable()


def _spare_the_last_collection() -> None:
    """Freeze what the run built (:func:`gc.freeze`): the interpreter's exit then skips its
    last garbage collection over the whole heap, which took 0.35 s after a design run and
    0.6 s after a PDF report (WeasyPrint's objects, collected nowhere else). The outputs
    are written and closed by then (:mod:`fi_design.output`), and the atexit handlers
    still run."""
    import gc

    gc.freeze()


def _say_interrupted(exc: KeyboardInterrupt, where: str = "") -> None:
    """Print what interrupted the run and which outputs it had written (stderr)."""
    from ..output import written

    files = written()
    what = (f"terminated by signal {exc.signum}" if isinstance(exc, Terminated) else
            "interrupted")
    done = (f"it had written {', '.join(str(f) for f in files)}" if files else
            "no output was written")
    if where:
        what, done = f"{what} {where}", "no output was left half-written"
    typer.echo(f"{what}; {done} and no temporary file is left", err=True)


app = typer.Typer(
    cls=DefaultCommandGroup,
    name="fi-design",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    subcommand_metavar="SPEC.yaml | COMMAND [ARGS]...",
    context_settings={"help_option_names": ["-h", "--help"]},
    help="Design friction isolators for precision stages: the paper's four-step "
         "guideline (friction gap, crossover, drive stiffness, PID gains) with a "
         "nonlinear LuGre simulation confirming the verdict.\n\n"
         "fi-design SPEC.yaml runs the default command 'design'. Exit codes: 0 done, "
         "2 bad input, 1 internal error, 3 a design verdict at or below --fail-on.",
)


def _show_version(value: bool) -> None:
    if value:
        from .. import __version__

        typer.echo(f"fi-design {__version__}")
        raise typer.Exit(EXIT_OK)


@app.callback()
def _root(
    version: Annotated[bool, typer.Option(
        "--version", callback=_show_version, is_eager=True,
        help="Print the version and exit.")] = False,
    debug: Annotated[bool, typer.Option(
        "--debug", help=f"Show the traceback of internal errors (also: {DEBUG_ENV}=1).")] = False,
) -> None:
    """Group options; the work happens in the commands."""


def app_commands() -> list[str]:
    """Names of all registered commands, in definition order."""
    return [c.name or c.callback.__name__.replace("_", "-") for c in app.registered_commands]


# --------------------------------------------------------------------------- options

SpecArg = Annotated[Path, typer.Argument(metavar="SPEC.yaml", help="The design spec (YAML).",
                                         show_default=False)]
Force = Annotated[bool, typer.Option("--force", "-f", help="Overwrite existing output files.")]
NoIsolator = Annotated[bool, typer.Option(
    "--no-isolator", help="Simulate the stage without the isolator (one rigid mass on the "
                          "bearing).")]


def output_option(flag: str, metavar: str, text: str) -> Any:
    """An optional output file option (default None)."""
    return typer.Option(None, flag, metavar=metavar, help=text, show_default=False)


JsonOut = Annotated[Optional[Path], typer.Option(
    "--json", metavar="OUT.json", help="Write the full result as JSON.", show_default=False)]
Drive = Annotated[str, typer.Option(
    "--drive", metavar="closed|force",
    help="How the model replays the record: 'closed' (its controller closes the loop on the "
         "measured reference) or 'force' (the plant alone, driven open loop by the measured "
         "force_N and re-anchored to the measurement in windows).")]
#: Most worker processes a study starts (--jobs): more than the machine has cores only adds
#: memory and start-up time.
MAX_JOBS = 64


def at_most(limit: int, why: str) -> Any:
    """An option callback refusing a number above ``limit``, with the number read and why."""

    def check(value: Any) -> Any:
        if value is not None and value > limit:
            raise typer.BadParameter(f"{value} is more than {limit}, the most {why}")
        return value

    return check


Jobs = Annotated[int, typer.Option(
    "--jobs", "-j", min=0, metavar="N",
    callback=at_most(MAX_JOBS, "worker processes a study starts"),
    help="Worker processes (local executor) or local dask workers; 0 = all cores, "
         "1 = serial in this process; at most 64.")]
ExecutorKind = Annotated[str, typer.Option(
    "--executor", metavar="local|dask",
    help="local: a process pool on this machine (default); dask: a dask.distributed "
         "cluster (--scheduler ADDRESS, or a local cluster).")]
Scheduler = Annotated[Optional[str], typer.Option(
    "--scheduler", metavar="ADDRESS",
    help="Address of a running dask scheduler, e.g. tcp://10.0.0.5:8786 (with --executor "
         "dask). Without it, a local cluster is started.", show_default=False)]
Measure = Annotated[str, typer.Option(
    "--measure", metavar="stage|move",
    help="What a point measures: 'stage' (default: does any move of the family end in a "
         "hunting cycle, and how large is it) or 'move' (the paper's metric: hunting cycles "
         "counted on the spec's own move).")]
NoCache = Annotated[bool, typer.Option(
    "--no-cache", help="Neither read nor write the result cache (FI_DESIGN_CACHE_DIR, else the "
                       "user cache directory).")]


# --------------------------------------------------------------------------- steps of a command


def check_measure(measure: str) -> None:
    """Refuse a ``--measure`` other than ``stage`` or ``move`` (exit 2)."""
    if measure not in ("stage", "move"):
        raise typer.BadParameter(f"'{measure}' is not stage or move", param_hint="--measure")


def check_spec_path(spec: Path) -> None:
    """Turn a mistyped command name into a hint instead of 'no such file'.

    Parameters
    ----------
    spec : pathlib.Path
        The SPEC.yaml argument as given.
    """
    close = close_command(spec, [c for c in app_commands() if c != DEFAULT_COMMAND])
    if close:
        from ..errors import SpecFileError

        raise SpecFileError(f"{spec}: no such spec file, and not a command; "
                            f"did you mean 'fi-design {close}'?")


def close_command(spec: Path, commands: list[str]) -> str | None:
    """The command a SPEC.yaml argument is a misspelling of, if it is one.

    Parameters
    ----------
    spec : pathlib.Path
        The argument as given.
    commands : list of str
        The command names it may be a misspelling of.

    Returns
    -------
    str or None
        The closest command name (:func:`difflib.get_close_matches`), when the
        argument is no existing file and has neither an extension nor a folder;
        else None.
    """
    if spec.exists() or spec.suffix or os.sep in str(spec):
        return None
    close = difflib.get_close_matches(str(spec), commands, n=1)
    return close[0] if close else None


def check_outputs(inputs: tuple[Path, ...], force: bool, **paths: Any) -> dict:
    """Every output path of a command checked before any work (:func:`fi_design.output.check_outputs`).

    Parameters
    ----------
    inputs : tuple of pathlib.Path
        The command's input files, never overwritten.
    force : bool
        ``--force``.
    **paths : (path or None, extensions)
        The outputs by name (``json``, ``report``, ``spec`` ...), named in a
        message by their option (:data:`OUTPUT_OPTIONS`).

    Returns
    -------
    dict
        Name to checked path (None where not asked).
    """
    from ..output import check_outputs as check

    flags = {name: OUTPUT_OPTIONS.get(name, name) for name in paths}
    checked = check(inputs, force=force, **{flags[name]: p for name, p in paths.items()})
    return {name: checked[flags[name]] for name in paths}


#: The option of each output a command's :func:`check_outputs` names.
OUTPUT_OPTIONS = {"json": "--json", "report": "--report", "spec": "--write-spec",
                  "fixed": "--write-spec", "csv": "--csv", "figure": "--figure"}


def load(spec: Path) -> Any:
    """The spec of a command, read after its output paths were checked.

    Parameters
    ----------
    spec : pathlib.Path
        SPEC.yaml.

    Returns
    -------
    fi_design.spec.Spec
    """
    from ..spec.file import load_spec

    check_spec_path(spec)
    import_pint()
    return load_spec(spec)


def import_pint() -> None:
    """Import pint with dask hidden, unless either is imported already.

    pint imports ``dask.base`` at its own import when dask is installed (for
    dask arrays of quantities): about 0.15 s of every command's start. A command
    never hands pint a dask array (units are read at the spec's boundary only),
    so the command line imports pint while ``import dask`` fails; dask itself
    imports normally afterwards (``--executor dask``). The library does not do
    this: a program that imports fi_design keeps pint's dask support.
    """
    if "pint" in sys.modules or "dask" in sys.modules:
        return
    sys.modules["dask"] = None  # type: ignore[assignment]  # import dask -> ImportError
    try:
        import pint  # noqa: F401
    finally:
        del sys.modules["dask"]


def json_text(result: Any) -> str:
    """A result's ``to_dict()`` as the JSON text of ``--json``."""
    import json

    return json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n"


def write_outputs(console: "Console", outs: dict, payloads: dict) -> None:
    """Write each payload (text, bytes, or a function that writes text into an open file, for
    outputs of millions of rows) to its checked path, atomically, and say so.

    Parameters
    ----------
    console : rich.console.Console
        Where to say so.
    outs : dict
        Checked paths by name (:func:`check_outputs`).
    payloads : dict
        Content by the same names.
    """
    from ..output import atomic_path, write_atomic

    for name, data in payloads.items():
        if callable(data):
            with atomic_path(outs[name]) as tmp, open(tmp, "w", encoding="utf-8") as fh:
                data(fh)
        else:
            write_atomic(outs[name], data)
        console.print(f"wrote {outs[name]}", markup=False)


def write_report(console: "Console", path: Optional[Path], result: Any, *,
                 figure_worker: bool = False, **options: Any) -> None:
    """The report of a result (:func:`fi_design.report.render_report`), written atomically.

    Parameters
    ----------
    console : rich.console.Console
        Where to say so.
    path : pathlib.Path or None
        The checked report path; None: no report.
    result : object
        The result.
    figure_worker : bool, optional
        The figures drawn by a worker process too (:func:`fi_design.cli.pools.report_pool`):
        a PDF's while this one lays the report out, an HTML's beside this one; for
        reports with figures placed by name (the design report).
    **options
        Passed on (``design_map`` of a design report).
    """
    if path is None:
        return
    from ..console import Status, make_console
    from ..report import render_report
    from .pools import report_pool

    # the worker forks before the spinner's thread starts (fork and threads do not mix)
    with report_pool(path if figure_worker else None) as pool, \
            Status(make_console(stderr=True), "writing the report ...") as status, \
            _report_garbage_kept():
        render_report(result, path, command=command_line(), progress=status, executor=pool,
                      **options)
    console.print(f"wrote {path}", markup=False)


def command_line() -> str:
    """The command as typed, for a report's title block."""
    import shlex

    return "fi-design " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def study_pool(kind: str, jobs: int, scheduler: Optional[str]) -> Any:
    """The executor of a study command (:class:`fi_design.cli.pools.StudyPool`), options checked."""
    from .pools import EXECUTORS, StudyPool

    if kind not in EXECUTORS:
        raise typer.BadParameter(f"'{kind}' is not one of {', '.join(EXECUTORS)}",
                                 param_hint="--executor")
    if scheduler and kind != "dask":
        raise typer.BadParameter("--scheduler needs --executor dask", param_hint="--scheduler")
    return StudyPool(kind, jobs, scheduler)


def run_study(label: str, pool: Any, no_cache: bool, work: Any) -> Any:
    """Run ``work(executor, progress, cache)`` with a progress bar; Ctrl-C exits 130.

    An interruption writes no output; the finished points stay in the cache.
    """
    from ..console import ProgressBar, make_console
    from ..studies import PointCache

    err = make_console(stderr=True)
    try:
        with pool as ex, ProgressBar(err, label) as bar:
            return work(ex, bar, None if no_cache else PointCache())
    except Exception as exc:  # noqa: BLE001 -- only an error on the way out of an interruption
        cause = _interruption(exc)
        if cause is None:
            raise
        _study_interrupted(err, cause, no_cache)
    except KeyboardInterrupt as exc:
        _study_interrupted(err, exc, no_cache)


def _study_interrupted(err: "Console", exc: KeyboardInterrupt, no_cache: bool) -> None:
    """Say that a study was interrupted and where its finished points are; exit 130 (or 128 +
    the signal)."""
    what = "terminated" if isinstance(exc, Terminated) else "interrupted"
    err.print(f"{what}; nothing was kept (--no-cache) and no output was written"
              if no_cache else f"{what}; the finished points are in the result cache: "
              "run the same command again to resume. No output was written",
              markup=False, highlight=False)
    raise typer.Exit(128 + exc.signum if isinstance(exc, Terminated) else
                     EXIT_INTERRUPTED) from None


def write_study(console: "Console", outs: dict, result: Any, figure: Any) -> None:
    """The CSV, JSON, ``figure(result)`` and report of a sweep or robustness study, as asked."""
    payloads: dict = {}
    if outs["csv"] is not None:
        payloads["csv"] = result.to_csv()
    if outs["json"] is not None:
        payloads["json"] = json_text(result)
    if outs["figure"] is not None:
        from ..plots import figure_bytes

        payloads["figure"] = figure_bytes(figure(result), outs["figure"].suffix)
    write_outputs(console, outs, payloads)
    write_report(console, outs["report"], result)


def check_drive(drive: str, record: object = True) -> None:
    """Refuse an unknown ``--drive`` or ``--drive force`` without a record (exit 2)."""
    if drive not in ("closed", "force"):
        raise typer.BadParameter(f"expected 'closed' or 'force', got {drive!r}",
                                 param_hint="--drive")
    if drive == "force" and record is None:
        raise typer.BadParameter("--drive force replays a record: give --record MEASURED.csv",
                                 param_hint="--drive")
