"""The ``fi-design`` command line: a thin layer over the library.

Each command parses its arguments, checks its output paths, calls one public
function, prints a summary (:mod:`fi_design.console`) and writes its outputs
atomically. Executors and progress displays are made here
(:mod:`fi_design.pools`, :mod:`fi_design.console`) and passed into the
library. The library raises; this module translates:

- exit 0: done (whatever the design verdict);
- exit 2: bad input -- any :class:`~fi_design.errors.FiDesignError` (the
  message names the field and YAML line) or a usage error; no traceback,
  nothing written;
- exit 1: internal error -- a bug; ``--debug`` or ``FI_DESIGN_DEBUG=1`` shows
  the traceback;
- exit 130: a parameter study interrupted with Ctrl-C.

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
#: Exit code of a study interrupted with Ctrl-C (128 + SIGINT, as shells report it).
EXIT_INTERRUPTED = 130


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
        except Exception as exc:  # noqa: BLE001 -- the one place that turns errors into codes
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


def _out(flag: str, metavar: str, text: str) -> Any:
    """An optional output file option (default None)."""
    return typer.Option(None, flag, metavar=metavar, help=text, show_default=False)


JsonOut = Annotated[Optional[Path], typer.Option(
    "--json", metavar="OUT.json", help="Write the full result as JSON.", show_default=False)]
Jobs = Annotated[int, typer.Option(
    "--jobs", "-j", min=0, metavar="N",
    help="Worker processes (local executor) or local dask workers; 0 = all cores, "
         "1 = serial in this process.")]
ExecutorKind = Annotated[str, typer.Option(
    "--executor", metavar="local|dask",
    help="local: a process pool on this machine (default); dask: a dask.distributed "
         "cluster (--scheduler ADDRESS, or a local cluster).")]
Scheduler = Annotated[Optional[str], typer.Option(
    "--scheduler", metavar="ADDRESS",
    help="Address of a running dask scheduler, e.g. tcp://10.0.0.5:8786 (with --executor "
         "dask). Without it, a local cluster is started.", show_default=False)]
NoCache = Annotated[bool, typer.Option(
    "--no-cache", help="Neither read nor write the result cache (FI_DESIGN_CACHE_DIR, else the "
                       "user cache directory).")]

#: Studies for `fi-design study NAME`.
STUDIES = ("paper",)


# --------------------------------------------------------------------------- helpers


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


def _outputs(inputs: tuple[Path, ...], force: bool, **paths: Any) -> dict:
    from .output import check_outputs

    return check_outputs(inputs, force=force, **paths)


def _load(spec: Path):
    """The spec of a command, after the output paths were checked."""
    from .specfile import load_spec

    _check_spec_path(spec)
    return load_spec(spec)


def _json(result: Any) -> str:
    import json

    return json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n"


def _write(console: "Console", outs: dict, payloads: dict) -> None:
    """Write each payload (text or bytes) to its checked path, atomically, and say so."""
    from .output import write_atomic

    for name, data in payloads.items():
        write_atomic(outs[name], data)
        console.print(f"wrote {outs[name]}", markup=False)


def _write_report(console: "Console", path: Optional[Path], result: Any, **options: Any) -> None:
    """The report of a result (fi_design.report), written atomically."""
    if path is None:
        return
    from .console import Status, make_console
    from .report import render_report

    with Status(make_console(stderr=True), "writing the report ...") as status:
        render_report(result, path, command=_command_line(), progress=status, **options)
    console.print(f"wrote {path}", markup=False)


def _command_line() -> str:
    """The command as typed, for the report's title block."""
    import shlex

    return "fi-design " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def _study_pool(kind: str, jobs: int, scheduler: Optional[str]):
    from .pools import EXECUTORS, StudyPool

    if kind not in EXECUTORS:
        raise typer.BadParameter(f"'{kind}' is not one of {', '.join(EXECUTORS)}",
                                 param_hint="--executor")
    if scheduler and kind != "dask":
        raise typer.BadParameter("--scheduler needs --executor dask", param_hint="--scheduler")
    return StudyPool(kind, jobs, scheduler)


def _run_study(label: str, pool: Any, no_cache: bool, work: Any) -> Any:
    """Run ``work(executor, progress, cache)`` with a progress bar; Ctrl-C exits 130."""
    from .console import ProgressBar, make_console
    from .studies import PointCache

    err = make_console(stderr=True)
    try:
        with pool as ex, ProgressBar(err, label) as bar:
            return work(ex, bar, None if no_cache else PointCache())
    except KeyboardInterrupt:
        err.print("interrupted; nothing was kept (--no-cache) and no output was written"
                  if no_cache else "interrupted; the finished points are in the result cache: "
                  "run the same command again to resume. No output was written",
                  markup=False, highlight=False)
        raise typer.Exit(EXIT_INTERRUPTED) from None


# --------------------------------------------------------------------------- design


@app.command("design")
def design_command(
    spec: Annotated[Path, typer.Argument(
        metavar="SPEC.yaml", help="The design spec (YAML); `fi-design init` writes an example.",
        show_default=False)],
    json_out: JsonOut = None,
    no_simulation: Annotated[bool, typer.Option(
        "--no-simulation", help="Only the four linear steps: skip the nonlinear "
                                "confirmation.")] = False,
    report_out: Optional[Path] = _out("--report", "OUT.html|OUT.pdf",
        "Write the sign-off report: one self-contained HTML file, or a PDF (A4), chosen by the "
        "extension."),
    with_map: Annotated[bool, typer.Option(
        "--map", help="Add a crossover x stroke hunting map around the design point to the "
                      "report (about 50 more simulations; also `report: {map: true}` in the "
                      "spec).")] = False,
    force: Force = False,
) -> None:
    """Run the four-step guideline on a spec and confirm it by simulation (the default command).

    Prints the checks (PASS / FAIL / WARN / INFO), the PID gains, the crossover
    of the four linear limit cases, the simulated verdicts with and without the
    isolator, the lowest hunting-free crossovers and the conclusion; writes
    JSON and the sign-off report (HTML or PDF) on request.
    """
    if with_map and report_out is None:
        raise typer.BadParameter("the map is part of the report; add --report OUT.html or "
                                 "--report OUT.pdf", param_hint="--map")
    if with_map and no_simulation:
        raise typer.BadParameter("the map simulates; it cannot go with --no-simulation",
                                 param_hint="--map")
    outs = _outputs((spec,), force, json=(json_out, (".json",)),
                    report=(report_out, (".html", ".pdf")))
    spec_obj = _load(spec)

    from .console import Status, make_console, print_design
    from .guideline import design
    from .pools import confirmation_pool

    console, err = make_console(), make_console(stderr=True)
    with Status(err, "running the design guideline ...") as status, \
            confirmation_pool(not no_simulation) as pool:
        result = design(spec_obj, confirm=not no_simulation, executor=pool, progress=status)
    payloads = {} if outs["json"] is None else {"json": _json(result)}
    print_design(console, result, spec_path=spec)
    _write(console, outs, payloads)
    design_map = None
    if outs["report"] is not None and (with_map or (not no_simulation
                                                    and result.spec.report.map)):
        from .studies import design_map as make_map

        with Status(err, "computing the hunting map ...") as status:
            design_map = make_map(result, progress=lambda done, total: status(
                f"hunting map: {done}/{total} simulations"))
    _write_report(console, outs["report"], result, design_map=design_map)


# --------------------------------------------------------------------------- simulate, schema, init


@app.command("simulate")
def simulate_command(
    spec: SpecArg,
    no_isolator: NoIsolator = False,
    csv_out: Optional[Path] = _out("--csv", "TRACE.csv",
        "Write the traces at the output rate (1 kHz by default) in the measured-data layout."),
    json_out: Optional[Path] = _out("--json", "OUT.json",
        "Write the metrics and solver statistics as JSON."),
    reference: Annotated[bool, typer.Option(
        "--reference", help="Integrate with scipy's solve_ivp (Radau, tight tolerance) instead "
                            "of the fast kernel: slow, for checks.")] = False,
    force: Force = False,
) -> None:
    """Simulate the stage once and print the hunting metric.

    The CSV has the columns of measured data (DESIGN.md section 4): time_s,
    reference_m, position_m, force_N (the commanded force) and, with the
    isolator, deflection_m; overlay it on your measurements.
    """
    outs = _outputs((spec,), force, csv=(csv_out, (".csv",)), json=(json_out, (".json",)))
    spec_obj = _load(spec)

    from .console import Status, make_console, print_simulation
    from .simulation import simulate

    with Status(make_console(stderr=True), "simulating ..."):
        result = simulate(spec_obj, isolated=False if no_isolator else None,
                          method="reference" if reference else "fast")
    console = make_console()
    print_simulation(console, result)
    payloads = {}
    if outs["csv"] is not None:
        from .measured import columns_csv

        payloads["csv"] = columns_csv(result.traces())
    if outs["json"] is not None:
        payloads["json"] = _json(result)
    _write(console, outs, payloads)


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


@app.command("sweep")
def sweep_command(
    spec: SpecArg,
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
    csv_out: Optional[Path] = _out("--csv", "OUT.csv",
        "Write one row per point (SI values)."),
    json_out: JsonOut = None,
    figure_out: Optional[Path] = _out("--figure", "OUT.svg|OUT.png",
        "Write the heatmap (or line plot)."),
    report_out: Optional[Path] = _out("--report", "OUT.html",
        "Write the report of the sweep (HTML, or PDF for a .pdf name)."),
    jobs: Jobs = 0,
    executor: ExecutorKind = "local",
    scheduler: Scheduler = None,
    no_cache: NoCache = False,
    force: Force = False,
) -> None:
    """Map hunting cycles over one or two spec values (the paper's Figure 4).

    Every point is the spec with the swept values replaced and validated; an
    invalid point (say Fs < Fc) or a failed simulation is recorded, and the
    sweep goes on. Finished points are cached, so a repeated or interrupted
    sweep only simulates what is missing.
    """
    outs = _outputs((spec,), force, csv=(csv_out, (".csv",)), json=(json_out, (".json",)),
                    figure=(figure_out, (".svg", ".png")),
                    report=(report_out, (".html", ".pdf")))
    _check_spec_path(spec)
    logs = {v.strip().lower() for v in (log or [])}
    if logs - {"x", "y"}:
        raise typer.BadParameter(f"expected x or y, got {', '.join(sorted(logs - {'x', 'y'}))}",
                                 param_hint="--log")
    if "y" in logs and y is None:
        raise typer.BadParameter("--log y needs --y", param_hint="--log")
    pool = _study_pool(executor, jobs, scheduler)
    spec_obj = _load(spec)

    from .console import make_console, print_sweep
    from .plots import sweep_figure
    from .studies import parse_axis, sweep

    ax = parse_axis(x, log="x" in logs, spec=spec_obj)
    ay = parse_axis(y, log="y" in logs, spec=spec_obj) if y is not None else None
    if ay is not None and ay.path == ax.path:
        raise typer.BadParameter("--x and --y sweep the same value", param_hint="--y")
    isolated = False if no_isolator else spec_obj.has_isolator
    result = _run_study("sweep", pool, no_cache, lambda ex, bar, cache: sweep(
        spec_obj, ax, ay, isolated=isolated, executor=ex, progress=bar, cache=cache))
    console = make_console()
    _write_study(console, outs, result, sweep_figure)
    print_sweep(console, result, spec_path=spec, executor=pool.describe())


def _write_study(console: "Console", outs: dict, result: Any, figure: Any) -> None:
    """The CSV, JSON, ``figure(result)`` and report of a sweep or robustness study, as asked."""
    payloads: dict = {}
    if outs["csv"] is not None:
        payloads["csv"] = result.to_csv()
    if outs["json"] is not None:
        payloads["json"] = _json(result)
    if outs["figure"] is not None:
        from .plots import figure_bytes

        payloads["figure"] = figure_bytes(figure(result), outs["figure"].suffix)
    _write(console, outs, payloads)
    _write_report(console, outs["report"], result)


@app.command("study")
def study_command(
    study: Annotated[str, typer.Argument(metavar="STUDY", help="The study: 'paper' (the four "
                                                               "maps of the paper's Figure 4).",
                                         show_default=False)],
    spec: SpecArg,
    out: Annotated[Path, typer.Option(
        "--out", "-o", metavar="DIR", help="Directory for figure4.svg, figure4.png, "
                                            "map_A.csv ... map_D.csv and study.json (created "
                                            "if missing).")] = Path("paper_study"),
    resolution: Annotated[int, typer.Option(
        "--resolution", "-n", min=2, max=200, metavar="N",
        help="Points per axis of every map.")] = 12,
    report_out: Optional[Path] = _out("--report", "OUT.html",
        "Also write the report of the four maps (HTML, or PDF for a .pdf name)."),
    maps: Annotated[str, typer.Option(
        "--maps", metavar="ABCD", help="Which maps: A static vs Coulomb friction, B crossover "
                                       "vs mass (both without isolator), C stroke vs stiffness, "
                                       "D crossover vs stroke (with isolator).")] = "ABCD",
    jobs: Jobs = 0,
    executor: ExecutorKind = "local",
    scheduler: Scheduler = None,
    no_cache: NoCache = False,
    force: Force = False,
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
    from .output import check_output_dir

    targets = check_output_dir(out, names, force=force, protect=(spec,))
    report_path = _outputs((spec,), force, report=(report_out, (".html", ".pdf")))["report"]
    if report_path is not None and report_path.resolve() in {p.resolve() for p in
                                                             targets.values()}:
        raise typer.BadParameter("the report would overwrite a file of the study",
                                 param_hint="--report")
    _check_spec_path(spec)
    pool = _study_pool(executor, jobs, scheduler)
    spec_obj = _load(spec)

    from .console import make_console, print_study
    from .plots import figure_bytes, study_figure
    from .studies import paper_study

    result = _run_study("paper study", pool, no_cache, lambda ex, bar, cache: paper_study(
        spec_obj, resolution, maps="".join(letters), executor=ex, progress=bar, cache=cache))
    console = make_console()
    fig = study_figure(result)
    payloads = {"figure4.svg": figure_bytes(fig, "svg"), "figure4.png": figure_bytes(fig, "png"),
                "study.json": _json(result)}
    payloads.update({f"map_{m.definition.key}.csv": m.result.to_csv() for m in result.maps})
    out.mkdir(exist_ok=True)
    from .output import write_atomic

    for name, data in payloads.items():
        write_atomic(targets[name], data)
    console.print(f"wrote {', '.join(payloads)} to {out}", markup=False)
    _write_report(console, report_path, result)
    print_study(console, result, spec_path=spec, executor=pool.describe())


@app.command("robustness")
def robustness_command(
    spec: SpecArg,
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
    csv_out: Optional[Path] = _out("--csv", "OUT.csv",
        "Write one row per sample."),
    json_out: JsonOut = None,
    figure_out: Optional[Path] = _out("--figure", "OUT.svg|OUT.png",
        "Write a bar chart of the probabilities."),
    report_out: Optional[Path] = _out("--report", "OUT.html",
        "Write the report (HTML, or PDF for a .pdf name)."),
    jobs: Jobs = 0,
    executor: ExecutorKind = "local",
    scheduler: Scheduler = None,
    no_cache: NoCache = False,
    force: Force = False,
) -> None:
    """Probability of hunting when friction (or any spec value) scatters.

    Draws the scattered values around the spec's, simulates every sample with
    and without the isolator, and prints the probability of hunting with its
    Wilson confidence interval. The same seed gives the same result.
    """
    outs = _outputs((spec,), force, csv=(csv_out, (".csv",)), json=(json_out, (".json",)),
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
    pool = _study_pool(executor, jobs, scheduler)
    spec_obj = _load(spec)

    from .console import make_console, print_robustness
    from .plots import robustness_figure
    from .studies import parse_position_friction, parse_scatter, robustness

    items = [parse_scatter(s, spec_obj) for s in scatter or []]
    pf = parse_position_friction(position_friction) if position_friction else None
    result = _run_study("robustness", pool, no_cache, lambda ex, bar, cache: robustness(
        spec_obj, items, samples, seed=seed, distribution=distribution, position_friction=pf,
        confidence=confidence, executor=ex, progress=bar, cache=cache))
    console = make_console()
    _write_study(console, outs, result, robustness_figure)
    print_robustness(console, result, spec_path=spec, executor=pool.describe())


# --------------------------------------------------------------------------- reconcile


@app.command("reconcile")
def reconcile_command(
    spec: Annotated[Path, typer.Argument(
        metavar="SPEC.yaml", help="The spec of the stage (YAML).", show_default=False)],
    measured: Annotated[Path, typer.Argument(
        metavar="MEASURED.csv", help="The measured trace: columns time_s, reference_m, "
                                     "position_m, optional force_N and deflection_m.",
        show_default=False)],
    report_out: Optional[Path] = _out("--report", "GAP.html",
        "Write the report: overlays, gap table, ranked candidates (HTML, or PDF for a .pdf "
        "name)."),
    json_out: JsonOut = None,
    write_spec: Optional[Path] = _out("--write-spec", "FIXED.yaml",
        "Write the spec with the named effect added to its effects list (never the input)."),
    max_effects: Annotated[int, typer.Option(
        "--max-effects", min=1, max=10, metavar="N",
        help="Name up to N effects, each searched on the gap the earlier ones leave.")] = 1,
    force: Force = False,
) -> None:
    """Find the physical effect the model misses in a measured trace.

    Replays the measured reference through the model, compares it with the
    measurement segment by segment and by hunting features against the sensor
    noise, fits every effect of the catalogue, and names the one that explains
    the gap best (or 'none'), with its fitted size and the gap before and after.
    """
    outs = _outputs((spec, measured), force, report=(report_out, (".html", ".pdf")),
                    json=(json_out, (".json",)), fixed=(write_spec, (".yaml", ".yml")))
    spec_obj = _load(spec)

    from .console import FractionBar, make_console, print_reconcile
    from .measured import load_measurement
    from .reconciliation import fixed_spec_text, reconcile

    data = load_measurement(measured)
    with FractionBar(make_console(stderr=True), "reconciling") as bar:
        result = reconcile(spec_obj, data, max_effects=max_effects, progress=bar)
    console = make_console()
    print_reconcile(console, result)
    if outs["json"] is not None:
        _write(console, outs, {"json": _json(result)})
    if outs["fixed"] is not None:
        from .output import write_atomic

        write_atomic(outs["fixed"], fixed_spec_text(result))
        console.print(f"wrote {outs['fixed']}"
                      + ("" if result.entries else " (no effect found: the spec is unchanged)"),
                      markup=False)
    if outs["report"] is not None:
        from .report import render_gap_report

        render_gap_report(result, outs["report"], command=_command_line())
        console.print(f"wrote {outs['report']}", markup=False)


def main() -> None:
    """Console-script entry point (``fi-design``, ``python -m fi_design``)."""
    app(prog_name="fi-design")
