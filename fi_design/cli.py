"""The ``fi-design`` command line: a thin layer over the library.

Each command parses its arguments, checks its output paths, calls one public
function, prints a summary and writes its outputs atomically. The library
raises; this module translates:

- exit 0: done (whatever the design verdict);
- exit 2: bad input -- any :class:`~fi_design.errors.FiDesignError` (the
  message names the field and YAML line) or a usage error; no traceback,
  nothing written;
- exit 1: internal error -- a bug; ``--debug`` or ``FI_DESIGN_DEBUG=1`` shows
  the traceback.

``fi-design SPEC.yaml`` runs the default command ``design`` through
:class:`DefaultCommandGroup`: when the first word after the group's own options
is not a command name, ``design`` is put in front of it. Every other command is
one function decorated with ``@app.command()``; error handling lives in the
group, so a new command needs nothing else.

Imports of the library (pydantic, numpy, python-control, scipy, numba,
matplotlib) and of rich happen inside the command functions, so
``fi-design --help`` stays fast.
"""

from __future__ import annotations

import difflib
import math
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer
from typer.core import TyperGroup

from .errors import FiDesignError

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console

#: Environment variable that makes internal errors show their traceback.
DEBUG_ENV = "FI_DESIGN_DEBUG"
#: Command run when the first argument is not a command name.
DEFAULT_COMMAND = "design"

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2

_STYLES = {"PASS": "bold green", "FAIL": "bold red", "WARN": "bold yellow", "INFO": "cyan"}


def _debug_requested(ctx: typer.Context | None = None) -> bool:
    if os.environ.get(DEBUG_ENV, "").strip().lower() not in ("", "0", "false", "no"):
        return True
    return bool(ctx is not None and ctx.params.get("debug"))


class DefaultCommandGroup(TyperGroup):
    """A command group that runs :data:`DEFAULT_COMMAND` when no command is named.

    ``fi-design SPEC.yaml --json out.json`` is read as ``fi-design design
    SPEC.yaml --json out.json``; ``fi-design schema`` still runs ``schema``.
    The group's own flags (``--version``, ``--debug``, ``--help``) may come
    first; ``--debug`` is also accepted anywhere before ``--``. A spec file
    whose name equals a command name can be given as ``./NAME``.

    The group also translates errors for every command: a
    :class:`~fi_design.errors.FiDesignError` exits 2 with its message, any
    other exception exits 1 with a short "internal error" note (the traceback
    with ``--debug`` or ``FI_DESIGN_DEBUG=1``).
    """

    default_command = DEFAULT_COMMAND

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        args = list(args)
        end = args.index("--") if "--" in args else len(args)
        if "--debug" in args[1:end]:
            head = [a for a in args[:end] if a != "--debug"]
            args = ["--debug"] + head + args[end:]
        i = self._skip_group_options(ctx, args)
        if i < len(args) and args[i] != "--" and args[i] not in self.commands:
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

    def invoke(self, ctx: Any) -> Any:
        try:
            return super().invoke(ctx)
        except (typer.Exit, typer.Abort, typer.TyperException, BrokenPipeError):
            raise  # usage errors, explicit exits, `fi-design ... | head`
        except FiDesignError as exc:
            if _debug_requested(ctx):
                import traceback

                traceback.print_exc(file=sys.stderr)
            typer.echo(f"error: {exc}", err=True)
            raise typer.Exit(EXIT_BAD_INPUT) from None
        except Exception as exc:  # noqa: BLE001 -- the one place that turns bugs into exit 1
            if _debug_requested(ctx):
                import traceback

                traceback.print_exc(file=sys.stderr)
                typer.echo(f"internal error: {type(exc).__name__}: {exc}", err=True)
            else:
                typer.echo(f"internal error: {type(exc).__name__}: {exc}\n"
                           f"This is a bug in fi-design, not in your input. Run again with "
                           f"--debug (or set {DEBUG_ENV}=1) to see the traceback, and please "
                           f"report it with the spec file.", err=True)
            raise typer.Exit(EXIT_INTERNAL) from None


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
         "2 bad input, 1 internal error.",
)


def _show_version(value: bool) -> None:
    if value:
        from . import __version__

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


# --------------------------------------------------------------------------- helpers


def _console(stderr: bool = False) -> "Console":
    """A rich console; wide enough for the tables when output is not a terminal."""
    from rich.console import Console

    console = Console(stderr=stderr, highlight=False)
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = Console(stderr=stderr, highlight=False, width=120)
    return console


def _fmt(value: Any, digits: int = 4) -> str:
    """A number for a table cell: ``digits`` significant digits, '-' for none."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, float)):
        return f"{value:.{digits}g}"
    return str(value)


def _status_text(status: Any):
    from rich.text import Text

    name = getattr(status, "value", status)
    name = str(name) if name is not None else "INFO"
    return Text(name, style=_STYLES.get(name, ""))


def checks_table(checks, title: str = "Checks"):
    """A rich table of :class:`~fi_design.results.Check` values, status coloured.

    Checks are grouped by their ``step``: a bold heading row starts each group.

    Parameters
    ----------
    checks : sequence of fi_design.results.Check
        The checks, in report order.
    title : str, optional
        Table title.

    Returns
    -------
    rich.table.Table
        Columns check, status, value, limit, unit, message.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    table = Table(title=title, title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    table.add_column("Check", no_wrap=True)
    table.add_column("Status", no_wrap=True)
    table.add_column("Value", justify="right", no_wrap=True)
    table.add_column("Limit", justify="right", no_wrap=True)
    table.add_column("Unit", no_wrap=True)
    table.add_column("Message", ratio=1, min_width=30)
    step = None
    for c in checks:
        if (c.step or "") != step:
            step = c.step or ""
            if step:
                table.add_row(Text(step, style="bold"))
        table.add_row(Text(c.name), _status_text(c.status), _fmt(c.value), _fmt(c.limit),
                      Text(c.unit or ""), Text(c.message or ""))
    return table


def _check_spec_path(spec: Path) -> None:
    """Turn a mistyped command name into a hint instead of 'no such file'."""
    if spec.exists() or spec.suffix or os.sep in str(spec):
        return
    close = difflib.get_close_matches(str(spec), [c for c in app_commands()
                                                  if c != DEFAULT_COMMAND], n=1)
    if close:
        from .errors import SpecFileError

        raise SpecFileError(f"{spec}: no such spec file, and not a command; "
                            f"did you mean 'fi-design {close[0]}'?")


def app_commands() -> list[str]:
    """Names of all registered commands, in definition order."""
    return [c.name or c.callback.__name__.replace("_", "-") for c in app.registered_commands]


# --------------------------------------------------------------------------- commands


@app.command("design")
def design_command(
    spec: Annotated[Path, typer.Argument(
        metavar="SPEC.yaml", help="The design spec (YAML); `fi-design init` writes an example.",
        show_default=False)],
    json_out: Annotated[Optional[Path], typer.Option(
        "--json", metavar="OUT.json", help="Write the full result as JSON.",
        show_default=False)] = None,
    no_simulation: Annotated[bool, typer.Option(
        "--no-simulation", help="Only the four linear steps: skip the nonlinear "
                                "confirmation.")] = False,
    report_out: Annotated[Optional[Path], typer.Option(
        "--report", metavar="OUT.html|OUT.pdf",
        help="Write the sign-off report: one self-contained HTML file, or a PDF (A4), "
             "chosen by the extension.", show_default=False)] = None,
    with_map: Annotated[bool, typer.Option(
        "--map", help="Add a crossover x stroke hunting map around the design point to the "
                      "report (about 50 more simulations; also `report: {map: true}` in the "
                      "spec).")] = False,
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite existing output files.")] = False,
) -> None:
    """Run the four-step guideline on a spec and confirm it by simulation (the default command).

    Prints the checks (PASS / FAIL / WARN / INFO), the PID gains, the crossover
    of the four linear limit cases, the simulated verdicts with and without the
    isolator, the lowest hunting-free crossovers and the conclusion; writes
    JSON and the sign-off report (HTML or PDF) on request.
    """
    from .output import write_atomic

    if with_map and report_out is None:
        raise typer.BadParameter("the map is part of the report; add --report OUT.html or "
                                 "--report OUT.pdf", param_hint="--map")
    if with_map and no_simulation:
        raise typer.BadParameter("the map simulates; it cannot go with --no-simulation",
                                 param_hint="--map")
    outs = _outputs(spec, force, json=(json_out, (".json",)),
                    report=(report_out, (".html", ".pdf")))
    json_path, report_path = outs["json"], outs["report"]
    _check_spec_path(spec)

    from .specfile import load_spec

    spec_obj = load_spec(spec)
    # The simulations run in a second process while this one imports
    # python-control and does the linear analysis: on a multi-core machine the
    # two overlap (and a first run compiles the numba kernel there).
    job = None if no_simulation else _Job(spec_obj)

    from .guideline import design

    console = _console()
    err = _console(stderr=True)
    with _status(err, "running the design guideline ...") as status:
        try:
            result = design(spec_obj, confirm=False)
        except BaseException:
            if job is not None:
                job.cancel()
            raise
        if job is not None:
            status("simulating with and without the isolator (the first run on a machine "
                   "compiles the kernel, about 10 s) ...")
            if report_path is not None:  # use the wait: import the report's libraries
                from .report import preload

                preload(report_path)
            result = result.with_simulation(job.result())

    text = None
    if json_path is not None:
        import json

        text = json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n"
    print_design(console, result, spec_path=spec)
    if json_path is not None:
        write_atomic(json_path, text)
        console.print(f"wrote {json_path}", markup=False)
    if report_path is not None:
        from .report import render_report

        with _status(err, "writing the report ...") as status:
            render_report(result, report_path, command=_command_line(),
                          map=True if with_map else (False if no_simulation else None),
                          progress=status)
        console.print(f"wrote {report_path}", markup=False)


class _status:
    """A spinner with a changing message on a terminal; silent otherwise.

    Used as ``with _status(console, text) as update: update("next step")``.
    """

    def __init__(self, console: "Console", text: str) -> None:
        self._console = console
        self._text = text
        self._live = None

    def __enter__(self):
        if self._console.is_terminal:
            self._live = self._console.status(self._text, spinner="dots")
            self._live.__enter__()
        return self.update

    def update(self, text: str) -> None:
        if self._live is not None:
            self._live.update(text)

    def __exit__(self, *exc) -> None:
        if self._live is not None:
            self._live.__exit__(*exc)


class _Job:
    """A confirmation computed in a forked process (inline where fork is unavailable).

    ``result()`` returns the :class:`~fi_design.confirm.Confirmation` or
    re-raises the worker's exception; ``cancel()`` stops the worker (used
    when the linear analysis fails first).
    """

    def __init__(self, spec) -> None:
        from .guideline import suggested_isolator

        suggestion = suggested_isolator(spec) if spec.isolator is None else None
        self._args = (spec, suggestion)
        self._proc = None
        self._conn = None
        try:
            import multiprocessing

            ctx = multiprocessing.get_context("fork")
            self._conn, child = ctx.Pipe(duplex=False)
            self._proc = ctx.Process(target=_confirm_worker, args=(child, *self._args),
                                     daemon=True)
            self._proc.start()
            child.close()
        except (ValueError, OSError):  # no fork on this platform: run inline later
            self._proc = None

    def result(self):
        if self._proc is None:
            from .confirm import confirm

            return confirm(*self._args)
        try:
            ok, value = self._conn.recv()
        except EOFError:
            raise RuntimeError("the simulation process ended without a result") from None
        finally:
            self._proc.join()
        if not ok:
            raise value
        return value

    def cancel(self) -> None:
        if self._proc is not None and self._proc.is_alive():
            self._proc.terminate()
            self._proc.join()


def _confirm_worker(conn, spec, suggestion) -> None:
    """Body of the :class:`_Job` process: send ``(True, result)`` or ``(False, error)``."""
    from .confirm import confirm

    try:
        conn.send((True, confirm(spec, suggestion)))
    except BaseException as exc:  # noqa: BLE001 - handed back to the parent
        conn.send((False, exc))
    finally:
        conn.close()


def print_design(console: "Console", result, spec_path: Path | None = None) -> None:
    """Print the readable summary of a :class:`~fi_design.guideline.DesignResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.guideline.DesignResult
        The design result.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    data = result.to_dict()
    name = _spec_name(result)
    head = Text(name or "fi-design", style="bold")
    if spec_path is not None:
        head.append(f"  ({spec_path})", style="dim")
    console.print(head)

    gap = data.get("friction_gap") or {}
    if gap:
        risk = gap.get("hunting_risk")
        console.print(Text(
            f"Friction gap Fs - Fc = {_fmt(gap.get('gap'))} N (threshold "
            f"{_fmt(gap.get('threshold'))} N): "
            + ("hunting is a risk" if risk else "hunting unlikely" if risk is not None else "")))

    console.print(checks_table(result.checks))

    pid = data.get("pid") or {}
    if pid:
        if pid.get("source") == "gains":
            # the hardware's loop beside the rule's gains in the same form
            hw, rule = pid["controller"], pid["rule_in_hardware_form"]
            t = Table(title="PID gains (step 4): the hardware's, and the rule's at the same "
                            "crossover", title_justify="left", box=box.SIMPLE_HEAD,
                      pad_edge=False)
            t.add_column("")
            for col in ("kp [N/m]", "ki [N/(m s)]", "kd [N s/m]", "D roll-off [Hz]"):
                t.add_column(Text(col), justify="right", no_wrap=True)
            for label, g in (("hardware", hw), ("rule", rule)):
                wf = g.get("roll_off")
                t.add_row(label, _fmt(g.get("kp")), _fmt(g.get("ki")), _fmt(g.get("kd")),
                          "none" if wf is None else _fmt(wf / (2 * 3.141592653589793)))
            console.print(t)
        else:
            t = Table(title="PID gains (step 4)", title_justify="left", box=box.SIMPLE_HEAD,
                      pad_edge=False)
            for col in ("kp [N/m]", "ki [N/(m s)]", "kd [N s/m]", "wt [rad/s]",
                        "tuning mass [kg]"):
                t.add_column(Text(col), justify="right", no_wrap=True)
            t.add_row(_fmt(pid.get("kp")), _fmt(pid.get("ki")), _fmt(pid.get("kd")),
                      _fmt(pid.get("wt")), _fmt(pid.get("tuning_mass")))
            console.print(t)

    xo = data.get("crossover") or {}
    if xo:
        line = (f"Crossover: desired {_fmt(xo.get('desired'))} Hz, achievable "
                f"{_fmt(xo.get('achievable'))} Hz")
        if xo.get("limited_by"):
            line += f", limited by {xo['limited_by']}"
        console.print(Text(line))
        cases = xo.get("cases") or []
        if cases:
            console.print(_cases_table(cases))

    stiff = data.get("stiffness") or {}
    if stiff.get("maximum") is not None:
        if stiff.get("suggested"):
            text = (f"Drive stiffness (suggestion for an isolator with a "
                    f"{_fmt(1e3 * stiff['stroke'], 3)} mm stroke): k_max = "
                    f"{_fmt(stiff['maximum'])} N/m, start from k = {_fmt(stiff.get('chosen'))} N/m")
        else:
            text = (f"Drive stiffness: k_max = {_fmt(stiff['maximum'])} N/m, chosen k = "
                    f"{_fmt(stiff.get('chosen'))} N/m")
            if stiff.get("source"):
                text += f" ({stiff['source']})"
            if stiff.get("force_at_stroke") is not None:
                text += f", flexure force at full stroke {_fmt(stiff['force_at_stroke'], 3)} N"
        console.print(Text(text))

    sim = data.get("simulation")
    if isinstance(sim, dict) and "isolated" in sim:
        console.print(_simulation_table(sim))

    conclusion = getattr(result, "conclusion", "") or data.get("conclusion", "")
    if conclusion:
        console.print(Text("Conclusion: ", style="bold").append(Text(str(conclusion),
                                                                        style="")))
    for w in getattr(result, "warnings", ()) or ():
        console.print(Text("warning: ", style="bold yellow").append(Text(_warning_text(w))))


def _simulation_table(sim: dict) -> Any:
    """Table of the simulated verdicts from the confirmation's JSON form."""
    from rich import box
    from rich.table import Table
    from rich.text import Text

    label = "suggested isolator" if sim.get("suggested_isolator") else "with isolator"
    t = Table(title="Nonlinear confirmation (LuGre simulation, paper section 2.3)"
              if sim["isolated"].get("friction_model") == "lugre"
              else "Nonlinear confirmation (switch friction model)",
              title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    for col, just in (("Plant", "left"), ("Verdict", "left"), ("Cycles", "right"),
                      ("Amplitude [um]", "right"), ("Period [s]", "right"),
                      ("Final error [um]", "right"), ("Hunting-free from [Hz]", "right"),
                      ("Other model", "left")):
        t.add_column(Text(col), justify=just, no_wrap=True)
    mins = sim.get("min_hunting_free_crossover") or {}
    other = sim.get("cross_check") or {}
    for key, name in (("isolated", label), ("non_isolated", "without isolator")):
        v = sim[key]
        verdict = v.get("verdict", "")
        style = {"settled": "bold green", "hunting": "bold red"}.get(verdict, "bold yellow")
        m = mins.get(key)
        t.add_row(name, Text(verdict, style=style), str(v.get("hunting_cycles")),
                  _fmt(None if v.get("amplitude") is None else 1e6 * v["amplitude"], 3),
                  _fmt(v.get("period"), 3),
                  _fmt(None if v.get("final_error") is None else 1e6 * v["final_error"], 3),
                  "not found" if m is None else f"{m:g} (+-{mins.get('resolution', 0):g})",
                  (other.get(key) or {}).get("verdict", ""))
    return t


def _spec_name(result) -> str:
    spec = getattr(result, "spec", None)
    return getattr(spec, "name", "") if spec is not None else ""


def _warning_text(w: Any) -> str:
    if isinstance(w, (tuple, list)) and len(w) == 2:
        return f"{w[0]}: {w[1]}"
    return str(w)


#: Columns of the limit-case table: JSON key -> header with unit (others are appended).
CASE_COLUMNS = {
    "crossover": "Crossover [Hz]",
    "phase_margin_deg": "Phase margin [deg]",
    "gain_margin_db": "Gain margin [dB]",
    "modulus_margin": "Modulus margin [-]",
    "delay_margin": "Delay margin [s]",
    "stable": "Stable",
}
_CASE_SKIP = {"name", "description", "passed", "failed", "crossovers"}


def _cases_table(cases: list) -> Any:
    """Table of the linear limit cases (paper Figure 2) from their JSON form."""
    from rich import box
    from rich.table import Table
    from rich.text import Text

    try:
        from .linear import CASE_NUMBERS
    except ImportError:  # pragma: no cover
        CASE_NUMBERS = {}
    keys = [k for k in CASE_COLUMNS if any(k in c for c in cases)]
    for case in cases:
        keys += [k for k, v in case.items() if k not in keys and k not in _CASE_SKIP
                 and not isinstance(v, (dict, list))]
    t = Table(title="Linear limit cases at the desired crossover (paper Figure 2)",
              title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    t.add_column("#", justify="right", no_wrap=True)
    t.add_column("Case", no_wrap=True)
    for k in keys:
        t.add_column(Text(CASE_COLUMNS.get(k, _header(k))), justify="right")
    t.add_column("Status", no_wrap=True)
    for i, case in enumerate(cases, 1):
        number = str(CASE_NUMBERS.get(case.get("name"), i))
        label = case.get("description") or case.get("name") or ""
        cells = [Text("inf" if case.get(k) is None and "margin" in k else _fmt(case.get(k)))
                 for k in keys]
        passed = case.get("passed")
        status = _status_text("INFO" if passed is None else "PASS" if passed else "FAIL")
        if case.get("failed"):
            status.append(" " + ", ".join(map(str, case["failed"])))
        t.add_row(number, Text(str(label)), *cells, status)
    return t


def _header(key: str) -> str:
    """``crossover_hz`` -> ``Crossover [Hz]``; other keys capitalised."""
    units = {"_hz": "Hz", "_deg": "deg", "_db": "dB", "_s": "s", "_m": "m", "_n": "N",
             "_rad_s": "rad/s"}
    for suffix, unit in units.items():
        if key.endswith(suffix):
            return f"{key[: -len(suffix)].replace('_', ' ').capitalize()} [{unit}]"
    return key.replace("_", " ").capitalize()


@app.command("simulate")
def simulate_command(
    spec: Annotated[Path, typer.Argument(
        metavar="SPEC.yaml", help="The design spec (YAML).", show_default=False)],
    no_isolator: Annotated[bool, typer.Option(
        "--no-isolator", help="Simulate the stage without the isolator (one rigid mass on the "
                              "bearing).")] = False,
    csv_out: Annotated[Optional[Path], typer.Option(
        "--csv", metavar="TRACE.csv", help="Write the traces at the output rate (1 kHz by "
                                           "default) in the measured-data layout.",
        show_default=False)] = None,
    json_out: Annotated[Optional[Path], typer.Option(
        "--json", metavar="OUT.json", help="Write the metrics and solver statistics as JSON.",
        show_default=False)] = None,
    reference: Annotated[bool, typer.Option(
        "--reference", help="Integrate with scipy's solve_ivp (Radau, tight tolerance) instead "
                            "of the fast kernel: slow, for checks.")] = False,
    record: Annotated[Optional[Path], typer.Option(
        "--record", metavar="MEASURED.csv", help="Replay this measured record instead of the "
                                                 "spec's motion: the model starts from the "
                                                 "state in the data and is driven by its "
                                                 "reference_m (and disturbance_N).",
        show_default=False)] = None,
    drive: Annotated[str, typer.Option(
        "--drive", metavar="closed|force", help="With --record: 'closed' (the model's "
                                                "controller closes the loop) or 'force' (the "
                                                "plant driven open loop by the measured "
                                                "force_N, re-anchored every --window)."
                                                )] = "closed",
    window: Annotated[float, typer.Option(
        "--window", metavar="SECONDS", help="With --drive force: length of the windows after "
                                            "which the model is re-anchored to the "
                                            "measurement [s].")] = 0.1,
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite existing output files.")] = False,
) -> None:
    """Simulate the stage once, or replay a measured record, and print the result.

    The CSV has the columns of measured data (DESIGN.md section 4): time_s,
    reference_m, position_m, force_N (the commanded force) and, with the
    isolator, deflection_m; overlay it on your measurements. An open-loop
    replay (--drive force) adds a column ``window`` numbering the re-anchored
    windows.
    """
    from .output import check_output, write_atomic

    if drive not in ("closed", "force"):
        raise typer.BadParameter(f"expected 'closed' or 'force', got {drive!r}",
                                 param_hint="--drive")
    if drive == "force" and record is None:
        raise typer.BadParameter("--drive force replays a record: give --record MEASURED.csv",
                                 param_hint="--drive")
    if not window > 0:
        raise typer.BadParameter(f"must be a positive time in seconds, got {window!r}",
                                 param_hint="--window")

    csv_path = check_output(csv_out, force=force, protect=(spec,),
                            extensions=(".csv",)) if csv_out else None
    json_path = check_output(json_out, force=force, protect=(spec,),
                             extensions=(".json",)) if json_out else None
    if csv_path is not None and json_path is not None and csv_path == json_path:
        raise typer.BadParameter("--csv and --json name the same file")
    _check_spec_path(spec)

    from .specfile import load_spec

    spec_obj = load_spec(spec)
    measured = None
    if record is not None:
        from .measured import load_measurement

        measured = load_measurement(record)
    isolated = False if no_isolator else None
    if not no_isolator and spec_obj.isolator is None:
        isolated = False

    from .simulation import simulate

    err = _console(stderr=True)
    with _status(err, "replaying the record ..." if measured is not None else "simulating ..."):
        result = simulate(spec_obj, isolated=isolated,
                          method="reference" if reference else "fast", record=measured,
                          drive=drive, window=window)
    console = _console()
    _print_simulation(console, result)
    if csv_path is not None:
        from .measured import columns_csv

        write_atomic(csv_path, columns_csv(result.traces()))
        console.print(f"wrote {csv_path}", markup=False)
    if json_path is not None:
        import json

        write_atomic(json_path, json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n")
        console.print(f"wrote {json_path}", markup=False)


def _print_simulation(console: "Console", result) -> None:
    from rich import box
    from rich.table import Table
    from rich.text import Text

    m = result.metrics
    plant = "with isolator" if result.isolated else "without isolator"
    loop = "closed loop" if result.drive == "closed" else "open loop, measured force"
    what = "Simulation" if result.replay is None else f"Replay of {result.record} ({loop})"
    t = Table(title=f"{what} {plant} at {result.crossover:.4g} Hz ({result.friction_model}, "
                    f"{result.method} solver)", title_justify="left", box=box.SIMPLE_HEAD,
              pad_edge=False)
    t.add_column("Quantity")
    t.add_column("Value", justify="right")
    rows = []
    fit = result.replay
    if fit is not None:
        rows += [
            ("position, model - measured, rms [um]", _fmt(1e6 * fit.position_rms, 4)),
            ("position, model - measured, max [um]", _fmt(1e6 * fit.position_max, 4)),
            ("tracking error r - x1 rms, model [um]", _fmt(1e6 * fit.tracking_rms_model, 4)),
            ("tracking error r - x1 rms, measured [um]",
             _fmt(1e6 * fit.tracking_rms_measured, 4)),
            ("commanded force, model - measured, rms [N]", _fmt(fit.force_rms, 4)),
        ]
        if result.window is not None:
            rows.append(("re-anchored windows [-]", str(int(result.window.max()) + 1)))
    else:  # the hunting metric judges a settling stage, not a record in motion
        rows += [
            ("verdict", m.verdict),
            ("hunting cycles in the window [-]", str(m.hunting_cycles)),
            ("amplitude (peak to peak) [um]", _fmt(1e6 * m.amplitude, 4)),
            ("period [s]", _fmt(m.period, 4)),
            ("settling time [s]", _fmt(m.settling_time, 4)),
            ("final error [um]", _fmt(1e6 * m.final_error, 4)),
        ]
    rows += [
        ("integration", "ok" if result.success else result.message),
        ("steps / rejected / events [-]", f"{result.n_steps} / {result.n_rejected} / "
                                          f"{result.n_events}"),
        ("wall time [ms]", _fmt(1e3 * result.wall_time, 3)),
    ]
    for k, v in rows:
        t.add_row(Text(k), Text(str(v)))
    console.print(t)
    if result.replay is None:
        console.print(Text(m.reason))


@app.command("schema")
def schema_command(
    markdown: Annotated[bool, typer.Option(
        "--markdown", help="Print the spec reference as Markdown tables instead "
                           "(the README's table).")] = False,
) -> None:
    """Print the JSON Schema of the spec file."""
    if markdown:
        from .docs import reference_markdown

        typer.echo(reference_markdown(), nl=False)
        return
    import json

    from .spec import Spec

    typer.echo(json.dumps(Spec.model_json_schema(), indent=2))


@app.command("init")
def init_command(
    path: Annotated[Path, typer.Argument(
        metavar="[PATH]", help="Where to write the example spec.")] = Path("bearing.yaml"),
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite an existing file.")] = False,
) -> None:
    """Write a fully commented example spec (default bearing.yaml)."""
    from importlib.resources import files

    from .output import check_output, write_atomic

    out = check_output(path, force=force, extensions=(".yaml", ".yml"))
    text = files("fi_design").joinpath("example_spec.yaml").read_text(encoding="utf-8")
    write_atomic(out, text)
    typer.echo(f"wrote {out}; edit it, then run: fi-design {out}")


# =========================================================================== parameter studies
# sweep, study, robustness (fi_design.studies). Executors and the progress bar are made here; the
# library only receives them.

#: Executors for --executor.
EXECUTORS = ("local", "dask")
#: Studies for `fi-design study NAME`.
STUDIES = ("paper",)

_JOBS_OPTION = typer.Option(
    "--jobs", "-j", min=0, metavar="N",
    help="Worker processes (local executor) or local dask workers; 0 = all cores, "
         "1 = serial in this process.")
_EXECUTOR_OPTION = typer.Option(
    "--executor", metavar="local|dask",
    help="local: a process pool on this machine (default); dask: a dask.distributed "
         "cluster (--scheduler ADDRESS, or a local cluster).")
_SCHEDULER_OPTION = typer.Option(
    "--scheduler", metavar="ADDRESS",
    help="Address of a running dask scheduler, e.g. tcp://10.0.0.5:8786 (with --executor "
         "dask). Without it, a local cluster is started.", show_default=False)
_NO_CACHE_OPTION = typer.Option(
    "--no-cache", help="Neither read nor write the result cache (FI_DESIGN_CACHE_DIR, else the "
                       "user cache directory).")


class _Executor:
    """The executor of a study command, as a context manager (None: serial).

    Creates a process pool (fork start method where available, after the
    kernel is loaded in this process, so that workers inherit it), or a
    dask.distributed client on a given scheduler or a local cluster.
    """

    def __init__(self, kind: str, jobs: int, scheduler: Optional[str]) -> None:
        if kind not in EXECUTORS:
            raise typer.BadParameter(f"'{kind}' is not one of {', '.join(EXECUTORS)}",
                                     param_hint="--executor")
        if scheduler and kind != "dask":
            raise typer.BadParameter("--scheduler needs --executor dask",
                                     param_hint="--scheduler")
        self.kind = kind
        self.jobs = jobs or (os.cpu_count() or 1)
        self.scheduler = scheduler
        self._closers: list = []

    def describe(self) -> str:
        if self.kind == "dask":
            return f"dask cluster at {self.scheduler}" if self.scheduler else \
                f"local dask cluster, {self.jobs} worker(s)"
        return "serial" if self.jobs == 1 else f"{self.jobs} worker processes"

    def __enter__(self):
        try:
            return self._start()
        except BaseException:
            self.__exit__(None, None, None)
            raise

    def _start(self):
        from .studies import warm_up

        warm_up()  # compile or load the kernel once here, before any worker starts
        if self.kind == "local":
            if self.jobs == 1:
                return None
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            methods = multiprocessing.get_all_start_methods()
            ctx = multiprocessing.get_context("fork") if "fork" in methods and \
                sys.platform.startswith("linux") else None
            pool = ProcessPoolExecutor(max_workers=self.jobs, mp_context=ctx,
                                       initializer=warm_up)
            self._closers.append(lambda: pool.shutdown(wait=True, cancel_futures=True))
            # start the workers now, before the progress bar's thread exists (fork and threads
            # do not mix); with fork all workers start at the first submit
            pool.submit(int).result()
            return pool
        return self._dask()

    def _dask(self):
        import logging

        from .errors import FiDesignError
        from .studies import warm_up

        try:
            from distributed import Client, LocalCluster
        except ImportError:  # pragma: no cover - a dependency
            raise FiDesignError("--executor dask needs the 'distributed' package "
                                "(pip install 'dask[distributed]')") from None
        logging.getLogger("distributed").setLevel(logging.ERROR)
        try:
            if self.scheduler:
                client = Client(self.scheduler, timeout="10s")
            else:
                cluster = LocalCluster(n_workers=self.jobs, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
                self._closers.append(cluster.close)
                client = Client(cluster)
        except (OSError, TimeoutError, ValueError) as exc:
            where = self.scheduler or "a local cluster"
            raise FiDesignError(f"cannot connect to the dask scheduler at {where}: {exc}") \
                from None
        self._closers.insert(0, client.close)
        client.run(warm_up)  # every worker loads the kernel before its first chunk
        return client

    def __exit__(self, *exc) -> None:
        for close in self._closers:
            try:
                close()
            except Exception:  # noqa: BLE001 -- closing must not hide the real outcome
                pass


class _ProgressBar:
    """A rich progress bar with ETA on stderr, fed by the library's ``progress(done, total)``."""

    def __init__(self, console: "Console", text: str) -> None:
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                                   TimeElapsedColumn, TimeRemainingColumn)

        self._progress = Progress(TextColumn("[progress.description]{task.description}"),
                                  BarColumn(), MofNCompleteColumn(), TextColumn("points"),
                                  TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                                  console=console, transient=False,
                                  disable=not console.is_terminal)
        self._task = self._progress.add_task(text, total=None)
        self._first: Optional[int] = None

    def __enter__(self) -> "_ProgressBar":
        self._progress.__enter__()
        return self

    def __call__(self, done: int, total: int) -> None:
        if self._first is None:  # cached points arrive at once; the ETA counts the rest
            self._first = done
            self._progress.reset(self._task, total=total, completed=done)
            return
        self._progress.update(self._task, total=total, completed=done)

    def __exit__(self, *exc) -> None:
        self._progress.__exit__(*exc)


#: Exit code of a study interrupted with Ctrl-C (128 + SIGINT, as shells report it).
EXIT_INTERRUPTED = 130


def _interrupted(err: "Console", no_cache: bool) -> None:
    """Say what an interruption kept, then exit 130; no output file is written."""
    if no_cache:
        text = "interrupted; nothing was kept (--no-cache) and no output was written"
    else:
        text = ("interrupted; the finished points are in the result cache: run the same command "
                "again to resume. No output was written")
    err.print(text, markup=False, highlight=False)
    raise typer.Exit(EXIT_INTERRUPTED)


def _cache_for(no_cache: bool):
    from .studies import PointCache

    return None if no_cache else PointCache()


def _outputs(spec: Path, force: bool, **paths: tuple[Optional[Path], tuple[str, ...]]) -> dict:
    """Check every output path before the work starts; refuse duplicates."""
    from .output import check_output

    out: dict = {}
    seen: list[Path] = []
    for name, (path, exts) in paths.items():
        if path is None:
            out[name] = None
            continue
        checked = check_output(path, force=force, protect=(spec, *seen), extensions=exts)
        seen.append(checked)
        out[name] = checked
    return out


def _axis_values_text(axis) -> str:
    from .plots import display_unit

    unit, f = display_unit(axis.unit)
    v = axis.values
    scale = "log" if axis.log else "linear"
    return (f"{axis.path}: {len(v)} values {_fmt(v[0] * f)} to {_fmt(v[-1] * f)} {unit} "
            f"({scale})")


_CELL = {"settled": ("·", "green"), "stuck": ("s", "yellow"), "undetermined": ("?", "yellow"),
         "invalid": ("-", "dim"), "failed": ("×", "bold red")}


def sweep_grid_table(result, max_columns: int = 25):
    """The map as a rich table: hunting cycles per point, marks for the other verdicts.

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        A two-dimensional sweep (a line is shown as one row).
    max_columns : int, optional
        Wider maps are not tabulated (None is returned).

    Returns
    -------
    rich.table.Table or None
        Rows are y values, columns x values, both in display units; a cell
        holds the cycle count of a hunting point, ``·`` settled, ``s`` stuck,
        ``?`` undetermined, ``-`` invalid, ``×`` failed.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    from .plots import display_unit

    x, y = result.x, result.y
    if len(x.values) > max_columns:
        return None
    xu, xf = display_unit(x.unit)
    if y is not None:
        yu, yf = display_unit(y.unit)
    t = Table(box=box.SIMPLE_HEAD, pad_edge=False)
    t.add_column(Text("" if y is None else f"[{yu}]"), justify="right", no_wrap=True)
    for v in x.values:
        t.add_column(Text(_fmt(v * xf, 3)), justify="right", no_wrap=True)
    rows = result.verdict.reshape(-1, len(x.values))
    cycles = result.hunting_cycles.reshape(-1, len(x.values))
    labels = [""] if y is None else [_fmt(v * yf, 3) for v in y.values]
    for label, vrow, crow in zip(labels, rows, cycles):
        cells = []
        for v, c in zip(vrow, crow):
            if v == "hunting":
                cells.append(Text(str(int(c)), style="bold red"))
            else:
                mark, style = _CELL.get(str(v), ("", ""))
                cells.append(Text(mark, style=style))
        t.add_row(label, *cells)
    return t


def grid_caption(result) -> str:
    """What the cells and axes of :func:`sweep_grid_table` mean, in one line.

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        The sweep.

    Returns
    -------
    str
    """
    from .plots import display_unit

    text = f"hunting cycles in the window; columns {result.x.path} " \
           f"[{display_unit(result.x.unit)[0]}]"
    if result.y is not None:
        text += f", rows {result.y.path} [{display_unit(result.y.unit)[0]}]"
    return text + "; · settled, s stuck, ? undetermined, - invalid, × failed"


def _print_grid(console: "Console", result) -> None:
    from rich.text import Text

    table = sweep_grid_table(result)
    if table is not None:
        console.print(Text(grid_caption(result), style="dim"))
        console.print(table)


def _print_counts(console: "Console", counts: dict) -> None:
    text = ", ".join(f"{n} {v}" for v, n in counts.items() if n)
    console.print(f"points: {text}", markup=False, highlight=False)


def _print_run(console: "Console", run, executor: str) -> None:
    console.print(f"{run.points} points: {run.computed} simulated, {run.cached} from the cache; "
                  f"{executor}; {run.wall_time:.2f} s", markup=False, highlight=False)


@app.command("sweep")
def sweep_command(
    spec: Annotated[Path, typer.Argument(metavar="SPEC.yaml", help="The design spec (YAML).",
                                         show_default=False)],
    x: Annotated[str, typer.Option(
        "--x", metavar="PATH=START:STOP:N",
        help="First swept value: a dotted spec path and a range with units, e.g. "
             "'isolator.stroke=0.05 mm:1 mm:12' (or PATH=V1,V2,...).", show_default=False)],
    y: Annotated[Optional[str], typer.Option(
        "--y", metavar="PATH=START:STOP:N",
        help="Second swept value (rows of the map); omit for a one-dimensional sweep.",
        show_default=False)] = None,
    log: Annotated[Optional[list[str]], typer.Option(
        "--log", metavar="x|y", help="Space an axis logarithmically (repeat for both).",
        show_default=False)] = None,
    no_isolator: Annotated[bool, typer.Option(
        "--no-isolator", help="Simulate the stage without its isolator.")] = False,
    csv_out: Annotated[Optional[Path], typer.Option(
        "--csv", metavar="OUT.csv", help="Write one row per point (SI values).",
        show_default=False)] = None,
    json_out: Annotated[Optional[Path], typer.Option(
        "--json", metavar="OUT.json", help="Write the full result as JSON.",
        show_default=False)] = None,
    figure_out: Annotated[Optional[Path], typer.Option(
        "--figure", metavar="OUT.svg|OUT.png", help="Write the heatmap (or line plot).",
        show_default=False)] = None,
    report_out: Annotated[Optional[Path], typer.Option(
        "--report", metavar="OUT.html", help="Write the report of the sweep (HTML, or PDF for "
                                             "a .pdf name).", show_default=False)] = None,
    jobs: Annotated[int, _JOBS_OPTION] = 0,
    executor: Annotated[str, _EXECUTOR_OPTION] = "local",
    scheduler: Annotated[Optional[str], _SCHEDULER_OPTION] = None,
    no_cache: Annotated[bool, _NO_CACHE_OPTION] = False,
    force: Annotated[bool, typer.Option("--force", "-f",
                                        help="Overwrite existing output files.")] = False,
) -> None:
    """Map hunting cycles over one or two spec values (the paper's Figure 4).

    Every point is the spec with the swept values replaced and validated; an
    invalid point (say Fs < Fc) or a failed simulation is recorded, and the
    sweep goes on. Finished points are cached, so a repeated or interrupted
    sweep only simulates what is missing.
    """
    outs = _outputs(spec, force, csv=(csv_out, (".csv",)), json=(json_out, (".json",)),
                    figure=(figure_out, (".svg", ".png")),
                    report=(report_out, (".html", ".pdf")))
    _check_spec_path(spec)
    logs = {v.strip().lower() for v in (log or [])}
    if logs - {"x", "y"}:
        raise typer.BadParameter(f"expected x or y, got {', '.join(sorted(logs - {'x', 'y'}))}",
                                 param_hint="--log")
    if "y" in logs and y is None:
        raise typer.BadParameter("--log y needs --y", param_hint="--log")
    pool = _Executor(executor, jobs, scheduler)

    from .specfile import load_spec
    from .studies import parse_axis, sweep

    spec_obj = load_spec(spec)
    ax = parse_axis(x, log="x" in logs, spec=spec_obj)
    ay = parse_axis(y, log="y" in logs, spec=spec_obj) if y is not None else None
    isolated = False if no_isolator else spec_obj.has_isolator
    if ay is not None and ay.path == ax.path:
        raise typer.BadParameter("--x and --y sweep the same value", param_hint="--y")
    console = _console()
    err = _console(stderr=True)
    try:
        with pool as ex, _ProgressBar(err, "sweep") as bar:
            result = sweep(spec_obj, ax, ay, isolated=isolated, executor=ex, progress=bar,
                           cache=_cache_for(no_cache))
    except KeyboardInterrupt:
        _interrupted(err, no_cache)
    _write_sweep_outputs(result, outs, console)
    print_sweep(console, result, spec_path=spec, executor=pool.describe())


def _write_sweep_outputs(result, outs: dict, console: "Console") -> None:
    import json

    from .output import write_atomic

    texts: dict = {}
    if outs["csv"] is not None:
        texts["csv"] = result.to_csv()
    if outs["json"] is not None:
        texts["json"] = json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n"
    if outs.get("figure") is not None:
        from .plots import figure_bytes, sweep_figure

        texts["figure"] = figure_bytes(sweep_figure(result), outs["figure"].suffix)
    for name, data in texts.items():
        write_atomic(outs[name], data)
        console.print(f"wrote {outs[name]}", markup=False, highlight=False)
    _write_report(result, outs.get("report"), console)


def _write_report(result, path: Optional[Path], console: "Console") -> None:
    """The HTML report of a study (fi_design.report), written atomically."""
    if path is None:
        return
    from .report import render_report

    render_report(result, path, command=_command_line())
    console.print(f"wrote {path}", markup=False, highlight=False)


def _command_line() -> str:
    """The command as typed, for the report's title block."""
    import shlex

    return "fi-design " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def print_sweep(console: "Console", result, spec_path: Optional[Path] = None,
                executor: str = "") -> None:
    """Print the summary of a :class:`~fi_design.studies.SweepResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.studies.SweepResult
        The sweep.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    executor : str, optional
        How the points ran, for the last line.
    """
    from rich.text import Text

    from .plots import display_unit

    head = Text(f"Sweep of {result.spec.name}", style="bold")
    if spec_path is not None:
        head.append(f"  ({spec_path})", style="dim")
    console.print(head)
    plant = "with isolator" if result.isolated else "without isolator"
    console.print(Text(f"{_axis_values_text(result.x)}; {plant}"))
    if result.y is not None:
        console.print(Text(_axis_values_text(result.y)))
    _print_grid(console, result)
    _print_counts(console, result.counts())
    xu, xf = display_unit(result.x.unit)
    above = result.boundary("above")
    if result.y is None:
        if not math.isnan(above[0]):
            console.print(Text(f"no hunting from {result.x.path} = {_fmt(above[0] * xf)} {xu} "
                               "upwards"))
    failed = [p for p in result.points if p.status == "failed"]
    for p in failed[:3]:
        console.print(Text(f"failed at {dict(zip(result.paths, p.values))}: {p.message}",
                           style="red"))
    if len(failed) > 3:
        console.print(Text(f"... and {len(failed) - 3} more failed point(s); see --csv or --json",
                           style="red"))
    _print_run(console, result.run, executor)


@app.command("study")
def study_command(
    study: Annotated[str, typer.Argument(metavar="STUDY", help="The study: 'paper' (the four "
                                                               "maps of the paper's Figure 4).",
                                         show_default=False)],
    spec: Annotated[Path, typer.Argument(metavar="SPEC.yaml", help="The design spec (YAML).",
                                         show_default=False)],
    out: Annotated[Path, typer.Option(
        "--out", "-o", metavar="DIR", help="Directory for figure4.svg, figure4.png, "
                                            "map_A.csv ... map_D.csv and study.json (created "
                                            "if missing).")] = Path("paper_study"),
    resolution: Annotated[int, typer.Option(
        "--resolution", "-n", min=2, max=200, metavar="N",
        help="Points per axis of every map.")] = 12,
    report_out: Annotated[Optional[Path], typer.Option(
        "--report", metavar="OUT.html", help="Also write the report of the four maps (HTML, or "
                                             "PDF for a .pdf name).", show_default=False)] = None,
    maps: Annotated[str, typer.Option(
        "--maps", metavar="ABCD", help="Which maps: A static vs Coulomb friction, B crossover "
                                       "vs mass (both without isolator), C stroke vs stiffness, "
                                       "D crossover vs stroke (with isolator).")] = "ABCD",
    jobs: Annotated[int, _JOBS_OPTION] = 0,
    executor: Annotated[str, _EXECUTOR_OPTION] = "local",
    scheduler: Annotated[Optional[str], _SCHEDULER_OPTION] = None,
    no_cache: Annotated[bool, _NO_CACHE_OPTION] = False,
    force: Annotated[bool, typer.Option("--force", "-f",
                                        help="Overwrite existing output files.")] = False,
) -> None:
    """Run a named parameter study around the spec's design point.

    `fi-design study paper SPEC.yaml` evaluates the paper's four maps (Figure
    4) with the spec as the design point and writes the figure, one CSV per
    map and the JSON of the whole study into --out.
    """
    if study not in STUDIES:
        close = difflib.get_close_matches(study, STUDIES, n=1)
        raise typer.BadParameter(f"unknown study '{study}'"
                                 + (f"; did you mean '{close[0]}'?" if close else "")
                                 + f"; available: {', '.join(STUDIES)}", param_hint="STUDY")
    letters = [k for k in maps.upper() if not k.isspace()]
    names = ["figure4.svg", "figure4.png", "study.json"] + [f"map_{k}.csv" for k in letters]
    targets = _study_targets(out, names, spec, force)
    report_path = _outputs(spec, force, report=(report_out, (".html", ".pdf")))["report"]
    if report_path is not None and report_path.resolve() in {p.resolve() for p in
                                                             targets.values()}:
        raise typer.BadParameter("the report would overwrite a file of the study",
                                 param_hint="--report")
    _check_spec_path(spec)
    pool = _Executor(executor, jobs, scheduler)

    from .specfile import load_spec
    from .studies import paper_study

    spec_obj = load_spec(spec)
    console = _console()
    err = _console(stderr=True)
    try:
        with pool as ex, _ProgressBar(err, "paper study") as bar:
            result = paper_study(spec_obj, resolution, maps="".join(letters), executor=ex,
                                 progress=bar, cache=_cache_for(no_cache))
    except KeyboardInterrupt:
        _interrupted(err, no_cache)
    _write_study(result, out, targets, console)
    _write_report(result, report_path, console)
    print_study(console, result, spec_path=spec, executor=pool.describe())


def _study_targets(out: Path, names: list[str], spec: Path, force: bool) -> dict:
    from .errors import OutputError
    from .output import check_output

    if out.exists() and not out.is_dir():
        raise OutputError(f"{out}: exists and is not a directory")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise OutputError(f"{out}: directory {parent} does not exist")
    targets = {}
    for name in names:
        path = out / name
        if out.is_dir():
            check_output(path, force=force, protect=(spec,))
        targets[name] = path
    return targets


def _write_study(result, out: Path, targets: dict, console: "Console") -> None:
    import json

    from .output import write_atomic
    from .plots import figure_bytes, study_figure

    fig = study_figure(result)
    data = {"figure4.svg": figure_bytes(fig, "svg"), "figure4.png": figure_bytes(fig, "png"),
            "study.json": json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n"}
    for m in result.maps:
        data[f"map_{m.definition.key}.csv"] = m.result.to_csv()
    out.mkdir(exist_ok=True)
    for name, payload in data.items():
        write_atomic(targets[name], payload)
    console.print(f"wrote {', '.join(data)} to {out}", markup=False, highlight=False)


def print_study(console: "Console", result, spec_path: Optional[Path] = None,
                executor: str = "") -> None:
    """Print the summary of a :class:`~fi_design.studies.StudyResult`: one grid per map.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.studies.StudyResult
        The study.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    executor : str, optional
        How the points ran, for the last line.
    """
    from rich.text import Text

    head = Text(f"Paper study (Figure 4) around {result.spec.name}", style="bold")
    if spec_path is not None:
        head.append(f"  ({spec_path})", style="dim")
    console.print(head)
    for m in result.maps:
        d = m.definition
        console.print(Text(f"\n{d.key}) {d.title}", style="bold"))
        console.print(Text(f"paper: {d.paper}", style="dim"))
        _print_grid(console, m.result)
        _print_counts(console, m.result.counts())
    _print_run(console, result.run, executor)


@app.command("robustness")
def robustness_command(
    spec: Annotated[Path, typer.Argument(metavar="SPEC.yaml", help="The design spec (YAML).",
                                         show_default=False)],
    samples: Annotated[int, typer.Option(
        "--samples", "-n", min=1, metavar="N", help="Number of random samples.")] = 100,
    scatter: Annotated[Optional[list[str]], typer.Option(
        "--scatter", metavar="PATH=SPREAD",
        help="A scattered spec value and its spread: '10%' of the nominal value (standard "
             "deviation, or half-width with --distribution uniform), or absolute with units "
             "('0.3 N'). Repeat for several values.", show_default=False)] = None,
    position_friction: Annotated[Optional[str], typer.Option(
        "--position-friction", metavar="AMPLITUDE:WAVELENGTH",
        help="Add friction varying along the rail (effect position_dependent_friction), e.g. "
             "'10%:20 mm'; every sample draws its phase.", show_default=False)] = None,
    distribution: Annotated[str, typer.Option(
        "--distribution", metavar="normal|uniform", help="Distribution of the scatter.")] =
        "normal",
    seed: Annotated[int, typer.Option("--seed", metavar="S",
                                      help="Seed of the random generator.")] = 0,
    confidence: Annotated[float, typer.Option(
        "--confidence", min=0.5, max=0.999, metavar="LEVEL",
        help="Level of the Wilson confidence interval.")] = 0.95,
    csv_out: Annotated[Optional[Path], typer.Option(
        "--csv", metavar="OUT.csv", help="Write one row per sample.", show_default=False)] = None,
    json_out: Annotated[Optional[Path], typer.Option(
        "--json", metavar="OUT.json", help="Write the full result as JSON.",
        show_default=False)] = None,
    figure_out: Annotated[Optional[Path], typer.Option(
        "--figure", metavar="OUT.svg|OUT.png", help="Write a bar chart of the probabilities.",
        show_default=False)] = None,
    report_out: Annotated[Optional[Path], typer.Option(
        "--report", metavar="OUT.html", help="Write the report (HTML, or PDF for a .pdf name).",
        show_default=False)] = None,
    jobs: Annotated[int, _JOBS_OPTION] = 0,
    executor: Annotated[str, _EXECUTOR_OPTION] = "local",
    scheduler: Annotated[Optional[str], _SCHEDULER_OPTION] = None,
    no_cache: Annotated[bool, _NO_CACHE_OPTION] = False,
    force: Annotated[bool, typer.Option("--force", "-f",
                                        help="Overwrite existing output files.")] = False,
) -> None:
    """Probability of hunting when friction (or any spec value) scatters.

    Draws the scattered values around the spec's, simulates every sample with
    and without the isolator, and prints the probability of hunting with its
    Wilson confidence interval. The same seed gives the same result.
    """
    outs = _outputs(spec, force, csv=(csv_out, (".csv",)), json=(json_out, (".json",)),
                    figure=(figure_out, (".svg", ".png")),
                    report=(report_out, (".html", ".pdf")))
    _check_spec_path(spec)
    if distribution not in ("normal", "uniform"):
        raise typer.BadParameter(f"'{distribution}' is not normal or uniform",
                                 param_hint="--distribution")
    if not scatter and position_friction is None:
        raise typer.BadParameter("give at least one --scatter PATH=SPREAD (e.g. "
                                 "--scatter friction.static=10%) or --position-friction",
                                 param_hint="--scatter")
    pool = _Executor(executor, jobs, scheduler)

    from .specfile import load_spec
    from .studies import parse_position_friction, parse_scatter, robustness

    spec_obj = load_spec(spec)
    items = [parse_scatter(s, spec_obj) for s in scatter or []]
    pf = parse_position_friction(position_friction) if position_friction else None
    console = _console()
    err = _console(stderr=True)
    try:
        with pool as ex, _ProgressBar(err, "robustness") as bar:
            result = robustness(spec_obj, items, samples, seed=seed, distribution=distribution,
                                position_friction=pf, confidence=confidence, executor=ex,
                                progress=bar, cache=_cache_for(no_cache))
    except KeyboardInterrupt:
        _interrupted(err, no_cache)
    import json

    from .output import write_atomic

    texts: dict = {}
    if outs["csv"] is not None:
        texts["csv"] = result.to_csv()
    if outs["json"] is not None:
        texts["json"] = json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n"
    if outs["figure"] is not None:
        from .plots import figure_bytes, robustness_figure

        texts["figure"] = figure_bytes(robustness_figure(result), outs["figure"].suffix)
    for name, data in texts.items():
        write_atomic(outs[name], data)
        console.print(f"wrote {outs[name]}", markup=False, highlight=False)
    _write_report(result, outs["report"], console)
    print_robustness(console, result, spec_path=spec, executor=pool.describe())


def print_robustness(console: "Console", result, spec_path: Optional[Path] = None,
                     executor: str = "") -> None:
    """Print the summary of a :class:`~fi_design.studies.RobustnessResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.studies.RobustnessResult
        The robustness study.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    executor : str, optional
        How the points ran, for the last line.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    from .plots import display_unit

    head = Text(f"Robustness of {result.spec.name}", style="bold")
    if spec_path is not None:
        head.append(f"  ({spec_path})", style="dim")
    console.print(head)
    for sc in result.scatter:
        unit, f = display_unit("") if sc.relative else display_unit(
            _path_unit(sc.path, result.spec))
        spread = f"{sc.spread:.3g} of nominal ({100 * sc.spread:.3g} %)" if sc.relative else \
            f"{_fmt(sc.spread * f)} {unit}"
        console.print(Text(f"scatter {sc.path}: {result.distribution}, spread {spread}"))
    if result.position_friction is not None:
        pf = result.position_friction
        console.print(Text(f"position-dependent friction: amplitude {100 * pf.amplitude:.3g} %, "
                           f"wavelength {pf.wavelength * 1e3:.4g} mm, random phase"))
    conf = result.not_isolated.confidence
    t = Table(title=f"Probability of hunting, {result.samples} samples, seed {result.seed}",
              title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    t.caption = Text(f"P: probability of hunting among the valid samples; CI: {conf:.0%} Wilson "
                     "interval", style="dim")
    t.caption_justify = "left"
    for col in ("Plant", "Hunting", "Valid", "P [%]", "CI [%]", "Settled", "Stuck",
                "Undetermined", "Invalid", "Failed"):
        t.add_column(Text(col), justify="left" if col == "Plant" else "right", no_wrap=True)
    for label, p in (("with isolator", result.isolated),
                     ("without isolator", result.not_isolated)):
        if p is None:
            continue
        prob = "-" if p.probability is None else f"{100 * p.probability:.1f}"
        c = p.counts
        t.add_row(label, str(p.hunting), str(p.valid), prob,
                  f"{100 * p.low:.1f} to {100 * p.high:.1f}", str(c["settled"]), str(c["stuck"]),
                  str(c["undetermined"]), str(c["invalid"]), str(c["failed"]))
    console.print(t)
    _print_run(console, result.run, executor)


def _path_unit(path: str, spec) -> str:
    from .specfile import path_unit

    try:
        return path_unit(path, spec)
    except Exception:  # noqa: BLE001 -- a label only
        return ""


# --------------------------------------------------------------------------- reconcile
# (model against measurement: fi_design.reconciliation, fi_design.measured, fi_design.gapreport)


@app.command("reconcile")
def reconcile_command(
    spec: Annotated[Path, typer.Argument(
        metavar="SPEC.yaml", help="The spec of the stage (YAML).", show_default=False)],
    measured: Annotated[Path, typer.Argument(
        metavar="MEASURED.csv", help="The measured trace: columns time_s, reference_m, "
                                     "position_m, optional force_N and deflection_m.",
        show_default=False)],
    report_out: Annotated[Optional[Path], typer.Option(
        "--report", metavar="GAP.html", help="Write the report: overlays, gap table, ranked "
                                             "candidates (HTML, or PDF for a .pdf name).",
        show_default=False)] = None,
    json_out: Annotated[Optional[Path], typer.Option(
        "--json", metavar="OUT.json", help="Write the full result as JSON.",
        show_default=False)] = None,
    write_spec: Annotated[Optional[Path], typer.Option(
        "--write-spec", metavar="FIXED.yaml", help="Write the spec with the named effect added "
                                                   "to its effects list (never the input).",
        show_default=False)] = None,
    max_effects: Annotated[int, typer.Option(
        "--max-effects", min=1, max=10, metavar="N",
        help="Name up to N effects, each searched on the gap the earlier ones leave.")] = 1,
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite existing output files.")] = False,
) -> None:
    """Find the physical effect the model misses in a measured trace.

    Replays the measured reference through the model, compares it with the
    measurement segment by segment and by hunting features against the sensor
    noise, fits every effect of the catalogue, and names the one that explains
    the gap best (or 'none'), with its fitted size and the gap before and after.
    """
    outs = _outputs(spec, force, report=(report_out, (".html", ".pdf")),
                    json=(json_out, (".json",)), fixed=(write_spec, (".yaml", ".yml")))
    from .output import check_output

    for key in ("report", "json", "fixed"):
        if outs[key] is not None:
            check_output(outs[key], force=force, protect=(spec, measured))
    _check_spec_path(spec)

    from .measured import load_measurement
    from .reconciliation import fixed_spec_text, reconcile
    from .specfile import load_spec

    spec_obj = load_spec(spec)
    data = load_measurement(measured)
    err = _console(stderr=True)
    with _FractionBar(err, "reconciling") as bar:
        result = reconcile(spec_obj, data, max_effects=max_effects, progress=bar)
    console = _console()
    print_reconcile(console, result)
    import json

    from .output import write_atomic

    fixed_text = fixed_spec_text(result) if outs["fixed"] is not None else None
    if outs["json"] is not None:
        write_atomic(outs["json"], json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n")
        console.print(f"wrote {outs['json']}", markup=False, highlight=False)
    if outs["fixed"] is not None:
        write_atomic(outs["fixed"], fixed_text)
        console.print(f"wrote {outs['fixed']}"
                      + ("" if result.entries else " (no effect found: the spec is unchanged)"),
                      markup=False, highlight=False)
    if outs["report"] is not None:
        from .gapreport import render_gap_report

        render_gap_report(result, outs["report"], command=_command_line())
        console.print(f"wrote {outs['report']}", markup=False, highlight=False)


class _FractionBar:
    """A rich progress bar on stderr fed by ``progress(message, fraction)``."""

    def __init__(self, console: "Console", text: str) -> None:
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        self._progress = Progress(TextColumn("{task.description}"), BarColumn(),
                                  TimeElapsedColumn(), console=console, transient=True,
                                  disable=not console.is_terminal)
        self._text = text
        self._task = self._progress.add_task(text, total=1.0)

    def __enter__(self) -> "_FractionBar":
        self._progress.__enter__()
        return self

    def __call__(self, message: str, fraction: float) -> None:
        self._progress.update(self._task, completed=fraction,
                              description=f"{self._text}: {message}")

    def __exit__(self, *exc) -> None:
        self._progress.__exit__(*exc)


def print_reconcile(console: "Console", result) -> None:
    """Print the readable summary of a :class:`~fi_design.reconciliation.ReconcileResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.reconciliation.ReconcileResult
        The reconciliation.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    head = Text("Effect: ", style="bold")
    head.append(Text(result.effect, style="bold green" if result.effect != "none" else "bold"))
    console.print(head)
    console.print(Text(result.conclusion))
    if result.diagnosis.mismatch and result.diagnosis.causes:
        d = Table(title="Likely causes of the structural gap", title_justify="left",
                  box=box.SIMPLE_HEAD, pad_edge=False)
        for col, just in (("Cause", "left"), ("Share", "right"), ("What was measured", "left")):
            d.add_column(col, justify=just)
        for c in result.diagnosis.causes:
            d.add_row(Text(c.name.replace("_", " ")), f"{100 * c.share:.0f} %", Text(c.detail))
        console.print(d)
    if len(result.steps) > 1:
        s = Table(title="Effects in order", title_justify="left", box=box.SIMPLE_HEAD,
                  pad_edge=False)
        for col in ("Effect", "Misfit before", "Misfit after"):
            s.add_column(col, justify="left" if col == "Effect" else "right")
        for st in result.steps:
            s.add_row(Text(st.name), _fmt(st.misfit_before), _fmt(st.misfit_after))
        console.print(s)
    t = Table(title="Candidates (best first)", title_justify="left", box=box.SIMPLE_HEAD,
              pad_edge=False)
    for col, just in (("Effect", "left"), ("Score", "right"), ("Explained", "right"),
                      ("Fitted parameters (SI)", "left"), ("Not named because", "left")):
        t.add_column(col, justify=just)
    for c in result.candidates:
        params = ", ".join(f"{k} = {_fmt(v)}" + (f" +- {_fmt(c.uncertainty.get(k), 2)}"
                                                 if c.uncertainty.get(k) else "")
                           for k, v in c.parameters.items() if v is not None)
        why = "" if c.name in result.effects else (c.reasons[0] if c.reasons else "")
        t.add_row(Text(c.name), _fmt(c.score), f"{100 * c.explained:.1f} %", Text(params),
                  Text(why, style="dim"))
    console.print(t)
    g = Table(title="Gap before and after", title_justify="left", box=box.SIMPLE_HEAD,
              pad_edge=False)
    for col in ("Metric", "Unit", "Before", "After", "Noise"):
        g.add_column(col, justify="left" if col in ("Metric", "Unit") else "right")
    for m in result.gaps:
        g.add_row(Text(m.name), Text(m.unit), _fmt(m.before), _fmt(m.after), _fmt(m.noise))
    console.print(g)
    nz = result.noise
    parts = [f"position {_fmt(nz.position, 3)} m ({nz.source.get('position')})"]
    if nz.force is not None:
        parts.append(f"force {_fmt(nz.force, 3)} N ({nz.source.get('force')})")
    if nz.deflection is not None:
        parts.append(f"deflection {_fmt(nz.deflection, 3)} m ({nz.source.get('deflection')})")
    console.print(Text("Noise: " + ", ".join(parts)))
    console.print(Text("Position lattice: " + result.lattice.detail))
    for name, why in result.skipped.items():
        console.print(Text(f"skipped {name}: {why}", style="dim"))


# --------------------------------------------------------------------------- identify
# (friction and mass from a measured record: fi_design.identification, fi_design.identreport)


@app.command("identify")
def identify_command(
    measured: Annotated[Path, typer.Argument(
        metavar="MEASURED.csv", help="The measured record: time_s, reference_m, position_m, "
                                     "force_N (optional deflection_m, disturbance_N).",
        show_default=False)],
    spec: Annotated[Optional[Path], typer.Option(
        "--spec", metavar="SPEC.yaml", help="The stage's spec: its loop sets the filter, its "
                                            "isolator gives the flexure force, its masses the "
                                            "split; needed for --write-spec and --report.",
        show_default=False)] = None,
    json_out: Annotated[Optional[Path], typer.Option(
        "--json", metavar="OUT.json", help="Write the identification as JSON.",
        show_default=False)] = None,
    write_spec: Annotated[Optional[Path], typer.Option(
        "--write-spec", metavar="OUT.yaml", help="Write the spec with the identified friction "
                                                 "and masses filled in (never the input).",
        show_default=False)] = None,
    report_out: Annotated[Optional[Path], typer.Option(
        "--report", metavar="IDENT.html", help="Write the report: force-velocity map, force "
                                               "residual, fit statistics (HTML, or PDF for a "
                                               ".pdf name).", show_default=False)] = None,
    form: Annotated[str, typer.Option(
        "--form", help="symmetric: one Coulomb friction and an offset; per-direction: Coulomb "
                       "friction per direction, no offset.")] = "symmetric",
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite existing output files.")] = False,
) -> None:
    """Identify mass, friction and force offset from a measured record (guideline step 1).

    Inverse-dynamics least squares on the filtered record gives the moving
    mass, Coulomb and viscous friction per direction and the offset, with
    standard errors; static friction, Stribeck velocity and bristle
    stiffness only where the record holds a breakaway or presliding.
    """
    forms = {"symmetric": "symmetric", "per-direction": "per_direction",
             "per_direction": "per_direction"}
    if form not in forms:
        raise typer.BadParameter("must be 'symmetric' or 'per-direction'", param_hint="--form")
    if spec is None and (write_spec is not None or report_out is not None):
        raise typer.BadParameter("--write-spec and --report need the stage's spec",
                                 param_hint="--spec")
    from .output import check_output

    outs, seen = {}, []
    for key, path, exts in (("json", json_out, (".json",)), ("spec", write_spec, (".yaml", ".yml")),
                            ("report", report_out, (".html", ".pdf"))):
        outs[key] = None if path is None else check_output(
            path, force=force, protect=(spec, measured, *seen), extensions=exts)
        if outs[key] is not None:
            seen.append(outs[key])
    from .identification import identified_spec_text, identify
    from .measured import load_measurement
    from .specfile import load_spec

    spec_obj = load_spec(spec) if spec is not None else None
    data = load_measurement(measured)
    with _FractionBar(_console(stderr=True), "identifying") as bar:
        result = identify(data, spec_obj, form=forms[form], progress=bar)
    console = _console()
    print_identification(console, result)
    text = identified_spec_text(result) if outs["spec"] is not None else None
    import json

    from .output import write_atomic

    if outs["json"] is not None:
        write_atomic(outs["json"], json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n")
        console.print(f"wrote {outs['json']}", markup=False, highlight=False)
    if outs["spec"] is not None:
        write_atomic(outs["spec"], text)
        console.print(f"wrote {outs['spec']}", markup=False, highlight=False)
    if outs["report"] is not None:
        from .identreport import render_identification_report

        render_identification_report(result, outs["report"], command=_command_line())
        console.print(f"wrote {outs['report']}", markup=False, highlight=False)


def print_identification(console: "Console", result) -> None:
    """Print an :class:`~fi_design.identification.IdentificationResult`: table, fit, notes.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.identification.IdentificationResult
        The identification.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    m = result.measurement
    console.print(Text(f"Identification from {m.source or 'the record'}: {m.n} samples, "
                       f"{result.form.replace('_', '-')} form, {result.model.replace('_', ' ')} "
                       "model", style="bold"))
    t = Table(title="Parameters (SI; standard error one sigma)", title_justify="left",
              box=box.SIMPLE_HEAD, pad_edge=False)
    for col, just in (("Parameter", "left"), ("Value", "right"), ("Std. error", "right"),
                      ("Unit", "left"), ("Identifiable", "left")):
        t.add_column(col, justify=just, no_wrap=True)
    for name, p in result.parameters.items():
        t.add_row(Text(name), _fmt(p.value, 6), _fmt(p.std_error, 3), Text(p.unit),
                  Text("yes" if p.identifiable else "no",
                       style="green" if p.identifiable else "yellow"))
    console.print(t)
    f = result.fit
    console.print(Text(f"Fit: RMS force residual {_fmt(f.force_rms_residual, 3)} N, relative "
                       f"error {_fmt(f.relative_error, 3)}, condition number "
                       f"{_fmt(f.condition_number, 3)}, {f.samples_used} samples used "
                       f"({_fmt(f.effective_samples, 3)} effective)"))
    ms = result.masses
    console.print(Text(f"Masses: stage {_fmt(ms.stage, 5)} kg, cart {_fmt(ms.cart, 5)} kg "
                       f"({ms.source})"))
    for name in ("static", "stribeck_velocity", "bristle_stiffness"):
        p = result.parameters[name]
        if not p.identifiable:
            console.print(Text(f"{name}: {p.note}", style="dim"))
    for note in result.notes:
        console.print(Text(f"note: {note}", style="dim"))


def main() -> None:
    """Console-script entry point (``fi-design``, ``python -m fi_design``)."""
    app(prog_name="fi-design")
