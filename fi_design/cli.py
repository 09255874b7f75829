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
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite existing output files.")] = False,
) -> None:
    """Run the four-step guideline on a spec and confirm it by simulation (the default command).

    Prints the checks (PASS / FAIL / WARN / INFO), the PID gains, the crossover
    of the four linear limit cases, the simulated verdicts with and without the
    isolator, the lowest hunting-free crossovers and the conclusion; writes
    JSON on request.
    """
    from .output import check_output, write_atomic

    json_path = check_output(json_out, force=force, protect=(spec,),
                             extensions=(".json",)) if json_out else None
    _check_spec_path(spec)
    warmup = None if no_simulation else start_kernel_warmup()

    from .specfile import load_spec

    spec_obj = load_spec(spec)

    from .guideline import design

    console = _console()
    err = _console(stderr=True)
    with _status(err, "running the design guideline ...") as status:
        result = design(spec_obj, confirm=False)
        if not no_simulation:
            from .confirm import confirm

            status("compiling the simulation kernel (first run only) ...")
            wait_kernel_warmup(warmup)
            advice = result.isolator_advice
            result = result.with_simulation(confirm(
                spec_obj, (advice.stroke, advice.stiffness) if advice else None,
                progress=status))

    text = None
    if json_path is not None:
        import json

        text = json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n"
    print_design(console, result, spec_path=spec)
    if json_path is not None:
        write_atomic(json_path, text)
        console.print(f"wrote {json_path}", markup=False)


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


def start_kernel_warmup():
    """Compile (or load) the numba kernel in a background process.

    The kernel compiles once per installation (about 10 s, then it loads from
    numba's on-disk cache in a fraction of a second). Starting it in a second
    process lets the compilation overlap the linear analysis (python-control
    takes seconds to import). Returns the process, or None when the cache is
    already warm or a process cannot be started.
    """
    import subprocess

    if kernel_cache_is_warm():
        return None
    try:
        return subprocess.Popen([sys.executable, "-c", "import fi_design.kernel"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        return None


def wait_kernel_warmup(process) -> None:
    """Wait for :func:`start_kernel_warmup`'s process (the kernel then loads from cache)."""
    if process is not None:
        process.wait()


def kernel_cache_is_warm() -> bool:
    """Whether numba's cache holds the integrator for the installed kernel source."""
    import importlib.util

    spec = importlib.util.find_spec("fi_design.kernel")
    if spec is None or spec.origin is None:
        return False
    src = Path(spec.origin)
    cache_dirs = [src.parent / "__pycache__"]
    if os.environ.get("NUMBA_CACHE_DIR"):
        cache_dirs.append(Path(os.environ["NUMBA_CACHE_DIR"]))
    try:
        from platformdirs import user_cache_dir

        cache_dirs.append(Path(user_cache_dir("fi_design")) / "numba")
    except ImportError:  # pragma: no cover - platformdirs is a dependency
        pass
    stamp = src.stat().st_mtime
    for d in cache_dirs:
        for index in d.rglob("kernel.integrate-*.nbi") if d.is_dir() else ():
            if index.stat().st_mtime >= stamp:
                return True
    return False


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
        t = Table(title="PID gains (step 4)", title_justify="left", box=box.SIMPLE_HEAD,
                  pad_edge=False)
        for col in ("kp [N/m]", "ki [N/(m s)]", "kd [N s/m]", "wt [rad/s]", "tuning mass [kg]"):
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
    force: Annotated[bool, typer.Option(
        "--force", "-f", help="Overwrite existing output files.")] = False,
) -> None:
    """Simulate the stage once and print the hunting metric.

    The CSV has the columns of measured data (DESIGN.md section 4): time_s,
    reference_m, position_m, force_N (the commanded force) and, with the
    isolator, deflection_m; overlay it on your measurements.
    """
    from .output import check_output, write_atomic

    csv_path = check_output(csv_out, force=force, protect=(spec,),
                            extensions=(".csv",)) if csv_out else None
    json_path = check_output(json_out, force=force, protect=(spec,),
                             extensions=(".json",)) if json_out else None
    if csv_path is not None and json_path is not None and csv_path == json_path:
        raise typer.BadParameter("--csv and --json name the same file")
    _check_spec_path(spec)

    from .specfile import load_spec

    spec_obj = load_spec(spec)
    isolated = False if no_isolator else None
    if not no_isolator and spec_obj.isolator is None:
        isolated = False

    from .simulate import simulate

    err = _console(stderr=True)
    with _status(err, "simulating ..."):
        result = simulate(spec_obj, isolated=isolated,
                          method="reference" if reference else "fast")
    console = _console()
    _print_simulation(console, result)
    if csv_path is not None:
        write_atomic(csv_path, traces_csv(result.traces()))
        console.print(f"wrote {csv_path}", markup=False)
    if json_path is not None:
        import json

        write_atomic(json_path, json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n")
        console.print(f"wrote {json_path}", markup=False)


def traces_csv(columns: dict) -> str:
    """CSV text of equal-length columns, header first, full float precision."""
    import io

    import numpy as np

    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    np.savetxt(buf, data, delimiter=",", fmt="%.10g")
    return buf.getvalue()


def _print_simulation(console: "Console", result) -> None:
    from rich import box
    from rich.table import Table
    from rich.text import Text

    m = result.metrics
    plant = "with isolator" if result.isolated else "without isolator"
    t = Table(title=f"Simulation {plant} at {result.crossover:g} Hz ({result.friction_model}, "
                    f"{result.method} solver)", title_justify="left", box=box.SIMPLE_HEAD,
              pad_edge=False)
    t.add_column("Quantity")
    t.add_column("Value", justify="right")
    rows = [
        ("verdict", m.verdict),
        ("hunting cycles in the window [-]", str(m.hunting_cycles)),
        ("amplitude (peak to peak) [um]", _fmt(1e6 * m.amplitude, 4)),
        ("period [s]", _fmt(m.period, 4)),
        ("settling time [s]", _fmt(m.settling_time, 4)),
        ("final error [um]", _fmt(1e6 * m.final_error, 4)),
        ("integration", "ok" if result.success else result.message),
        ("steps / rejected / events [-]", f"{result.n_steps} / {result.n_rejected} / "
                                          f"{result.n_events}"),
        ("wall time [ms]", _fmt(1e3 * result.wall_time, 3)),
    ]
    for k, v in rows:
        t.add_row(Text(k), Text(str(v)))
    console.print(t)
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


def main() -> None:
    """Console-script entry point (``fi-design``, ``python -m fi_design``)."""
    app(prog_name="fi-design")
