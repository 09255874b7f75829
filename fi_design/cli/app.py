"""The ``fi-design`` command line: a thin layer over the library.

Each command parses its arguments, checks its output paths, calls one public
function, prints a summary (:mod:`fi_design.console`) and writes its outputs
atomically. Executors and progress displays are made on this side
(:mod:`fi_design.cli.pools`, :mod:`fi_design.console`) and passed into the
library; the steps the commands share are in :mod:`fi_design.cli.parts`. The
library raises; :class:`~fi_design.cli.parts.DefaultCommandGroup` translates:

- exit 0: done (whatever the design verdict);
- exit 2: bad input -- any :class:`~fi_design.errors.FiDesignError` (the
  message names the field and YAML line) or a usage error; no traceback,
  nothing written;
- exit 1: internal error -- a bug; ``--debug`` or ``FI_DESIGN_DEBUG=1`` shows
  the traceback;
- exit 3: the design verdict is at or below the level of ``--fail-on``
  (``fail``: the design does not pass, FAIL or NOT_CONFIRMED; ``warn``: also
  PASS_WITH_WARNINGS), for scripts and CI;
  the outputs are written first;
- exit 130: interrupted with Ctrl-C (128 + the signal's number for SIGTERM and
  SIGHUP), at any instant: the message says which outputs were written.

``fi-design SPEC.yaml`` runs the default command ``design`` through
:class:`~fi_design.cli.parts.DefaultCommandGroup`: when the first word after the group's own options
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
from pathlib import Path
from typing import Annotated, Optional

import typer

from .parts import (DEFAULT_COMMAND, EXIT_VERDICT, Drive, ExecutorKind, Force, Jobs, JsonOut,
                    Measure, NoCache, NoIsolator, Scheduler, SpecArg, app, at_most, check_drive,
                    check_measure, check_outputs, check_spec_path, json_text, load, output_option,
                    run_study, study_pool, write_outputs, write_report, write_study)

__all__ = ["app", "main", "DEFAULT_COMMAND"]

#: Studies for `fi-design study NAME`.
STUDIES = ("paper",)


# --------------------------------------------------------------------------- design


@app.command("design")
def design_command(
    spec: Annotated[Path, typer.Argument(
        metavar="SPEC.yaml", help="The design spec (YAML); fi-design init writes an example.",
        show_default=False)],
    json_out: JsonOut = None,
    no_simulation: Annotated[bool, typer.Option(
        "--no-simulation", help="Only the four linear steps: skip the nonlinear "
                                "confirmation.")] = False,
    report_out: Optional[Path] = output_option("--report", "OUT.html|OUT.pdf",
        "Write the sign-off report: one self-contained HTML file, or a PDF (A4), chosen by the "
        "extension."),
    with_map: Annotated[bool, typer.Option(
        "--map", help="Add a crossover x stroke hunting map around the design point to the "
                      "report (about 50 more simulations; also report: {map: true} in the "
                      "spec).")] = False,
    write_spec: Optional[Path] = output_option("--write-spec", "OUT.yaml",
        "Write the spec with step 4's gains as controller.gains and controller.roll_off (the "
        "form the spec and a drive take; comments kept; never the input)."),
    fail_on: Annotated[Optional[str], typer.Option(
        "--fail-on", metavar="fail|warn",
        help="Exit with code 3 (after writing the outputs) when the verdict is at or below "
             "this level: 'fail' when it does not pass (FAIL, or NOT_CONFIRMED without "
             "simulation), 'warn' on PASS_WITH_WARNINGS too; for scripts "
             "and CI.")] = None,
    no_recommend: Annotated[bool, typer.Option(
        "--no-recommend", help="On a FAIL verdict, skip the search for a design that passes "
                               "(it takes seconds to a minute; the command fi-design recommend "
                               "runs it alone).")] = False,
    no_cache: NoCache = False,
    force: Force = False,
) -> None:
    """Run the four-step guideline on a spec and confirm it by simulation (the default command).

    Prints the checks (PASS / FAIL / WARN / INFO), the PID gains, the crossover
    of the four linear limit cases, the simulated verdicts with and without the
    isolator, the lowest hunting-free crossovers, the conclusion and the
    verdict on the hardware as specified (PASS, PASS_WITH_WARNINGS or FAIL,
    with its reasons, the hunting probability under friction scatter, the
    margins and, when it fails, a design that passes, found by search);
    writes JSON and the sign-off report (HTML or PDF) on request. With
    --fail-on, exits 3 when the verdict is at or below that level. The design
    search is kept in the result cache: run again on the same spec, or as
    fi-design recommend, it is read back.
    """
    from ..results.verdict import FAIL_ON_LEVELS as levels

    if fail_on is not None and fail_on not in levels:
        raise typer.BadParameter(f"expected 'fail' or 'warn', got {fail_on!r}",
                                 param_hint="--fail-on")
    if with_map and report_out is None:
        raise typer.BadParameter("the map is part of the report; add --report OUT.html or "
                                 "--report OUT.pdf", param_hint="--map")
    if with_map and no_simulation:
        raise typer.BadParameter("the map simulates; it cannot go with --no-simulation",
                                 param_hint="--map")
    outs = check_outputs((spec,), force, json=(json_out, (".json",)),
                         report=(report_out, (".html", ".pdf")),
                         spec=(write_spec, (".yaml", ".yml")))
    spec_obj = load(spec)

    from ..console import Status, make_console, print_design
    from .pools import confirmation_pool
    from ..signoff import design

    console, err = make_console(), make_console(stderr=True)
    # the pool's workers fork before the spinner's thread starts (fork and threads do not mix)
    with confirmation_pool(not no_simulation) as pool, \
            Status(err, "running the design guideline ...") as status:
        result = design(spec_obj, confirm=not no_simulation, executor=pool, progress=status,
                        recommend=not no_recommend, fe_check=outs["report"] is not None,
                        sensitivity=outs["report"] is not None, cache=not no_cache)
    payloads = {} if outs["json"] is None else {"json": json_text(result)}
    if outs["spec"] is not None:
        from ..controller.handoff import gains_spec_text

        payloads["spec"] = gains_spec_text(result)
    print_design(console, result, spec_path=spec)
    write_outputs(console, outs, payloads)
    design_map = None
    if outs["report"] is not None and (with_map or (not no_simulation
                                                    and result.spec.report.map)):
        from ..studies import design_map as make_map

        with Status(err, "computing the hunting map ...") as status:
            design_map = make_map(result, progress=lambda done, total: status(
                f"hunting map: {done}/{total} simulations"))
    write_report(console, outs["report"], result, design_map=design_map, figure_worker=True)
    if fail_on is not None and result.verdict.at_or_below(levels[fail_on]):
        raise typer.Exit(EXIT_VERDICT)


# --------------------------------------------------------------------------- simulate, schema, init


@app.command("simulate")
def simulate_command(
    ctx: typer.Context,
    spec: SpecArg,
    no_isolator: NoIsolator = False,
    csv_out: Optional[Path] = output_option("--csv", "TRACE.csv",
        "Write the traces at the output rate (1 kHz by default) in the measured-data layout."),
    json_out: Optional[Path] = output_option("--json", "OUT.json",
        "Write the metrics and solver statistics as JSON."),
    reference: Annotated[bool, typer.Option(
        "--reference", help="Integrate with scipy's solve_ivp (Radau, tight tolerance) instead "
                            "of the fast kernel: slow, for checks.")] = False,
    record: Optional[Path] = output_option("--record", "MEASURED.csv",
        "Replay this measured record instead of the spec's motion: the model starts from the "
        "state in the data and is driven by its reference_m (and disturbance_N)."),
    drive: Drive = "closed",
    window: Annotated[float, typer.Option(
        "--window", metavar="SECONDS", help="With --drive force: length of the windows after "
                                            "which the model is re-anchored to the "
                                            "measurement [s].")] = 0.1,
    force: Force = False,
) -> None:
    """Simulate the stage once, or replay a measured record, and print the result.

    The CSV has the columns of measured data (docs/interfaces.md): time_s,
    reference_m, position_m, force_N (the commanded force) and, with the
    isolator, deflection_m; overlay it on your measurements. An open-loop
    replay (--drive force) adds a column 'window' numbering the re-anchored
    windows.
    """
    check_drive(drive, record)
    if drive != "force" and ctx.get_parameter_source("window").name != "DEFAULT":
        raise typer.BadParameter("only an open-loop replay has windows: give --record "
                                 "MEASURED.csv --drive force, or leave --window out",
                                 param_hint="--window")
    if not 0 < window < math.inf:
        raise typer.BadParameter(f"must be a positive, finite time in seconds, got {window!r}",
                                 param_hint="--window")
    inputs = (spec,) if record is None else (spec, record)
    outs = check_outputs(inputs, force, csv=(csv_out, (".csv",)), json=(json_out, (".json",)))
    spec_obj = load(spec)

    from ..console import Status, make_console, print_simulation
    from ..measured import load_measurement
    from ..simulation.run import simulate

    measured = None if record is None else load_measurement(record)
    with Status(make_console(stderr=True),
                "replaying the record ..." if measured is not None else "simulating ..."):
        result = simulate(spec_obj, isolated=False if no_isolator else None,
                          method="reference" if reference else "fast", record=measured,
                          drive=drive, window=window)
    console = make_console()
    print_simulation(console, result)
    payloads = {}
    if outs["csv"] is not None:
        from ..measured import write_columns_csv

        payloads["csv"] = lambda fh: write_columns_csv(fh, result.traces())
    if outs["json"] is not None:
        payloads["json"] = json_text(result)
    write_outputs(console, outs, payloads)


@app.command("schema")
def schema_command(
    markdown: Annotated[bool, typer.Option(
        "--markdown", help="Print the spec reference as Markdown tables instead "
                           "(the tables of docs/spec.md).")] = False,
) -> None:
    """Print the JSON Schema of the spec file."""
    if markdown:
        from ..docs import reference_markdown

        typer.echo(reference_markdown(), nl=False)
        return
    import json

    from ..spec import Spec

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

    from ..output import check_output, write_atomic

    out = check_output(path, force=force, extensions=(".yaml", ".yml"))
    text = files("fi_design").joinpath("example_spec.yaml").read_text(encoding="utf-8")
    write_atomic(out, text.replace("{path}", str(path)))
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
    csv_out: Optional[Path] = output_option("--csv", "OUT.csv",
        "Write one row per point (SI values; each column named with its unit, "
        "controller.crossover_Hz, amplitude_m, period_s)."),
    json_out: JsonOut = None,
    figure_out: Optional[Path] = output_option("--figure", "OUT.svg|OUT.png",
        "Write the heatmap (or line plot)."),
    report_out: Optional[Path] = output_option("--report", "OUT.html",
        "Write the report of the sweep (HTML, or PDF for a .pdf name)."),
    measure: Measure = "stage",
    jobs: Jobs = 0,
    executor: ExecutorKind = "local",
    scheduler: Scheduler = None,
    no_cache: NoCache = False,
    force: Force = False,
) -> None:
    """Map hunting over one or two spec values (the paper's Figure 4).

    Every point is the spec with the swept values replaced and validated; an
    invalid point (say Fs < Fc), one whose drawn guide the stage's weight
    buckles (not simulated) or a failed simulation is recorded, and the
    sweep goes on. Finished points are cached, so a repeated or interrupted
    sweep only simulates what is missing.
    """
    outs = check_outputs((spec,), force, csv=(csv_out, (".csv",)), json=(json_out, (".json",)),
                    figure=(figure_out, (".svg", ".png")),
                    report=(report_out, (".html", ".pdf")))
    check_spec_path(spec)
    logs = {v.strip().lower() for v in (log or [])}
    if logs - {"x", "y"}:
        raise typer.BadParameter(f"expected x or y, got {', '.join(sorted(logs - {'x', 'y'}))}",
                                 param_hint="--log")
    if "y" in logs and y is None:
        raise typer.BadParameter("--log y needs --y", param_hint="--log")
    pool = study_pool(executor, jobs, scheduler)
    spec_obj = load(spec)

    from ..console import make_console, print_sweep
    from ..plots import sweep_figure
    from ..studies import parse_axis, sweep

    ax = parse_axis(x, log="x" in logs, spec=spec_obj)
    ay = parse_axis(y, log="y" in logs, spec=spec_obj) if y is not None else None
    if ay is not None and ay.path == ax.path:
        raise typer.BadParameter("--x and --y sweep the same value", param_hint="--y")
    isolated = False if no_isolator else spec_obj.has_isolator
    check_measure(measure)
    result = run_study("sweep", pool, no_cache, lambda ex, bar, cache: sweep(
        spec_obj, ax, ay, isolated=isolated, executor=ex, progress=bar, cache=cache,
        measure=measure))
    console = make_console()
    write_study(console, outs, result, sweep_figure)
    print_sweep(console, result, spec_path=spec, executor=pool.describe(),
                files=tuple(p for p in (outs["figure"], outs["csv"]) if p is not None))


@app.command("study")
def study_command(
    study: Annotated[str, typer.Argument(metavar="STUDY", help="The study: 'paper' (the four "
                                                               "maps of the paper's Figure 4).",
                                         show_default=False)],
    spec: SpecArg,
    out: Annotated[Path, typer.Option(
        "--out", "-o", metavar="DIR",
        help="Directory for figure4.svg, figure4.png, map_A.csv ... map_D.csv and study.json "
             "(created if missing). A map file there of a map this run leaves out (--maps) is "
             "refused; --force removes it (and no other file).")] = Path("paper_study"),
    resolution: Annotated[int, typer.Option(
        "--resolution", "-n", min=2, metavar="N",
        callback=at_most(150, "points per axis (four maps of 150 x 150 are 90 000 simulations)"),
        help="Points per axis of every map (at most 150: four maps of 150 x 150 are 90 000 "
             "simulations).")] = 12,
    report_out: Optional[Path] = output_option("--report", "OUT.html",
        "Also write the report of the four maps (HTML, or PDF for a .pdf name)."),
    maps: Annotated[str, typer.Option(
        "--maps", metavar="ABCD", help="Which maps: A static vs Coulomb friction, B crossover "
                                       "vs mass (both without isolator), C stroke vs stiffness, "
                                       "D crossover vs stroke (with isolator).")] = "ABCD",
    measure: Measure = "stage",
    jobs: Jobs = 0,
    executor: ExecutorKind = "local",
    scheduler: Scheduler = None,
    no_cache: NoCache = False,
    force: Force = False,
) -> None:
    """Run a named parameter study around the spec's design point.

    fi-design study paper SPEC.yaml evaluates the paper's four maps (Figure
    4) with the spec as the design point and writes the figure, one CSV per
    map and the JSON of the whole study into --out. With --force, the files
    of an earlier study there are replaced, and its map CSVs of maps this run
    leaves out (--maps) removed, so that the directory holds this study only.
    """
    if study not in STUDIES:
        close = difflib.get_close_matches(study, STUDIES, n=1)
        raise typer.BadParameter(f"unknown study '{study}'"
                                 + (f"; did you mean '{close[0]}'?" if close else "")
                                 + f"; available: {', '.join(STUDIES)}", param_hint="STUDY")
    letters = [k for k in maps.upper() if not k.isspace()]
    names = ["figure4.svg", "figure4.png", "study.json"] + [f"map_{k}.csv" for k in letters]
    from ..output import check_output_dir
    from ..studies import PAPER_MAPS

    stale = [f"map_{d.key}.csv" for d in PAPER_MAPS if d.key not in letters]
    targets = check_output_dir(out, names, force=force, protect=(spec,), stale=stale)
    report_path = check_outputs((spec,), force, report=(report_out, (".html", ".pdf")))["report"]
    if report_path is not None and report_path.resolve() in {p.resolve() for p in
                                                             targets.values()}:
        raise typer.BadParameter("the report would overwrite a file of the study",
                                 param_hint="--report")
    check_spec_path(spec)
    check_measure(measure)
    pool = study_pool(executor, jobs, scheduler)
    spec_obj = load(spec)

    from ..console import make_console, print_study
    from ..plots import figure_bytes, study_figure
    from ..studies import paper_study

    result = run_study("paper study", pool, no_cache, lambda ex, bar, cache: paper_study(
        spec_obj, resolution, maps="".join(letters), executor=ex, progress=bar, cache=cache,
        measure=measure))
    console = make_console()
    fig = study_figure(result)
    payloads = {"figure4.svg": figure_bytes(fig, "svg"), "figure4.png": figure_bytes(fig, "png"),
                "study.json": json_text(result)}
    payloads.update({f"map_{m.definition.key}.csv": m.result.to_csv() for m in result.maps})
    out.mkdir(exist_ok=True)
    from ..output import remove_output, write_atomic

    for name, data in payloads.items():
        write_atomic(targets[name], data)
    removed = [name for name in stale if remove_output(out / name)]
    console.print(f"wrote {', '.join(payloads)} to {out}"
                  + (f"; removed {', '.join(removed)} (maps of an earlier study that this one "
                     "leaves out)" if removed else ""), markup=False)
    write_report(console, report_path, result)
    print_study(console, result, spec_path=spec, executor=pool.describe(), out=out)


@app.command("robustness")
def robustness_command(
    spec: SpecArg,
    samples: Annotated[int, typer.Option(
        "--samples", "-n", min=1, metavar="N",
        callback=at_most(100_000, "samples of a study (each simulated with and without the "
                                  "isolator)"),
        help="Number of random samples (at most 100 000, each simulated with and without the "
             "isolator).")] = 100,
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
    seed: Annotated[int, typer.Option("--seed", metavar="S", min=0,
                                      help="Seed of the random generator.")] = 0,
    confidence: Annotated[float, typer.Option(
        "--confidence", min=0.5, max=0.999, metavar="LEVEL",
        help="Level of the Wilson confidence interval.")] = 0.95,
    csv_out: Optional[Path] = output_option("--csv", "OUT.csv",
        "Write one row per sample: the drawn values and, per plant, the outcome (each "
        "column named with its unit, friction.static_N, isolated_amplitude_m)."),
    json_out: JsonOut = None,
    figure_out: Optional[Path] = output_option("--figure", "OUT.svg|OUT.png",
        "Write a bar chart of the probabilities."),
    report_out: Optional[Path] = output_option("--report", "OUT.html",
        "Write the report (HTML, or PDF for a .pdf name)."),
    measure: Measure = "stage",
    jobs: Jobs = 0,
    executor: ExecutorKind = "local",
    scheduler: Scheduler = None,
    no_cache: NoCache = False,
    force: Force = False,
) -> None:
    """Probability of hunting when friction (or any spec value) scatters.

    Draws the scattered values around the spec's, judges every sample with
    and without the isolator (by default over every move of its family), and
    prints the probability of hunting, and of not settling for any reason,
    with their Wilson confidence intervals. The same seed gives the same
    result.
    """
    outs = check_outputs((spec,), force, csv=(csv_out, (".csv",)), json=(json_out, (".json",)),
                    figure=(figure_out, (".svg", ".png")),
                    report=(report_out, (".html", ".pdf")))
    check_spec_path(spec)
    if distribution not in ("normal", "uniform"):
        raise typer.BadParameter(f"'{distribution}' is not normal or uniform",
                                 param_hint="--distribution")
    if not scatter and position_friction is None:
        raise typer.BadParameter("give at least one --scatter PATH=SPREAD (e.g. "
                                 "--scatter friction.static=10%) or --position-friction",
                                 param_hint="--scatter")
    check_measure(measure)
    pool = study_pool(executor, jobs, scheduler)
    spec_obj = load(spec)

    from ..console import make_console, print_robustness
    from ..plots import robustness_figure
    from ..studies import parse_position_friction, parse_scatter, robustness

    items = [parse_scatter(s, spec_obj) for s in scatter or []]
    pf = parse_position_friction(position_friction) if position_friction else None
    result = run_study("robustness", pool, no_cache, lambda ex, bar, cache: robustness(
        spec_obj, items, samples, seed=seed, distribution=distribution, position_friction=pf,
        confidence=confidence, executor=ex, progress=bar, cache=cache, measure=measure))
    console = make_console()
    write_study(console, outs, result, robustness_figure)
    print_robustness(console, result, spec_path=spec, executor=pool.describe())


# --------------------------------------------------------------------------- recommend


@app.command("recommend")
def recommend_command(
    spec: SpecArg,
    json_out: JsonOut = None,
    report_out: Optional[Path] = output_option("--report", "OUT.html|OUT.pdf",
        "Write the report of the search (HTML, or PDF for a .pdf name)."),
    write_spec: Optional[Path] = output_option("--write-spec", "OUT.yaml",
        "Write the spec with the recommended guide, stroke (and crossover) in it, in its own "
        "units, comments kept, a revision added; the design command on it passes."),
    jobs: Jobs = 0,
    executor: ExecutorKind = "local",
    scheduler: Scheduler = None,
    no_cache: NoCache = False,
    force: Force = False,
) -> None:
    """Search a buildable isolator (and the rule's crossover) for the stiffest design that passes.

    Sizes leaf-spring guides from stock over strokes and stiffnesses, judges
    every one after every move of its family at the loop's crossover with the
    fold of its cycle, and signs off the stiffest joint that keeps
    requirements.hunting_margin with the reserves of requirements.reserve.
    Prints the design beside the spec's, its guide, what binds it and the
    least change of the spec that passes; with none feasible, the nearest
    design and what it violates. A search of the same spec by the same code
    (this command's, or the design command's on a failing spec) is read from
    the result cache.
    """
    outs = check_outputs((spec,), force, json=(json_out, (".json",)),
                         report=(report_out, (".html", ".pdf")),
                         spec=(write_spec, (".yaml", ".yml")))
    check_spec_path(spec)
    pool = study_pool(executor, jobs, scheduler)
    spec_obj = load(spec)

    from ..console import Status, make_console, print_recommendation
    from ..recommend import recommend, recommended_spec_text

    console, err = make_console(), make_console(stderr=True)
    # the pool's workers fork before the spinner's thread starts (fork and threads do not mix)
    with pool as ex, Status(err, "searching the design space ...") as status:
        result = recommend(spec_obj, executor=ex, progress=status, cache=not no_cache)
    payloads = {} if outs["json"] is None else {"json": json_text(result)}
    if outs["spec"] is not None and result.feasible:
        payloads["spec"] = recommended_spec_text(result)
    print_recommendation(console, result, spec_path=spec)
    write_outputs(console, outs, payloads)
    write_report(console, outs["report"], result)
    if outs["spec"] is not None and not result.feasible:
        err.print(f"[bold red]{outs['spec']} not written:[/] no design of the searched space "
                  "passes the sign-off (the nearest one is shown above)")
        raise typer.Exit(EXIT_VERDICT)


# --------------------------------------------------------------------------- reconcile


@app.command("reconcile")
def reconcile_command(
    spec: Annotated[Path, typer.Argument(
        metavar="SPEC.yaml", help="The spec of the stage (YAML).", show_default=False)],
    measured: Annotated[Path, typer.Argument(
        metavar="MEASURED.csv", help="The measured trace: columns time_s, reference_m, "
                                     "position_m, optional force_N and deflection_m.",
        show_default=False)],
    report_out: Optional[Path] = output_option("--report", "GAP.html",
        "Write the report: overlays, gap table, ranked candidates (HTML, or PDF for a .pdf "
        "name)."),
    json_out: JsonOut = None,
    write_spec: Optional[Path] = output_option("--write-spec", "FIXED.yaml",
        "Write the spec with the named effect added to its effects list (never the input)."),
    max_effects: Annotated[int, typer.Option(
        "--max-effects", min=1, max=10, metavar="N",
        help="Name up to N effects, each searched on the gap the earlier ones leave.")] = 1,
    drive: Drive = "closed",
    force: Force = False,
) -> None:
    """Find the physical effect the model misses in a measured trace.

    Replays the measured reference through the model, compares it with the
    measurement segment by segment and by hunting features against the sensor
    noise, fits every effect of the catalogue, and names the one that explains
    the gap best (or 'none'), with its fitted size and the gap before and after.
    With --drive force the plant alone is driven by the measured force in
    re-anchored windows, so the controller's description drops out of the
    comparison.
    """
    check_drive(drive)
    outs = check_outputs((spec, measured), force, report=(report_out, (".html", ".pdf")),
                    json=(json_out, (".json",)), fixed=(write_spec, (".yaml", ".yml")))
    spec_obj = load(spec)

    from ..console import FractionBar, make_console, print_reconcile
    from ..measured import load_measurement
    from ..reconciliation import fixed_spec_text, reconcile

    data = load_measurement(measured)
    with FractionBar(make_console(stderr=True), "reconciling") as bar:
        result = reconcile(spec_obj, data, max_effects=max_effects, drive=drive,
                           progress=bar)
    console = make_console()
    print_reconcile(console, result)
    if outs["json"] is not None:
        write_outputs(console, outs, {"json": json_text(result)})
    if outs["fixed"] is not None:
        from ..output import write_atomic

        write_atomic(outs["fixed"], fixed_spec_text(result))
        console.print(f"wrote {outs['fixed']}"
                      + ("" if result.entries else " (no effect found: the spec is unchanged)"),
                      markup=False)
    write_report(console, outs["report"], result)


# --------------------------------------------------------------------------- identify


@app.command("identify", context_settings={"allow_extra_args": True})
def identify_command(
    ctx: typer.Context,
    measured: Annotated[Path, typer.Argument(
        metavar="MEASURED.csv", help="The measured record: time_s, reference_m, position_m, "
                                     "force_N (optional deflection_m, disturbance_N).",
        show_default=False)],
    spec: Optional[Path] = output_option("--spec", "SPEC.yaml",
        "The stage's spec: its loop sets the filter, its isolator gives the flexure force, its "
        "masses the split; needed for --write-spec and --report. It may also come first, "
        "as reconcile takes it: fi-design identify SPEC.yaml MEASURED.csv."),
    json_out: Optional[Path] = output_option("--json", "OUT.json", "Write the identification as JSON."),
    write_spec: Optional[Path] = output_option("--write-spec", "OUT.yaml",
        "Write the spec with the identified friction and masses filled in (never the input)."),
    report_out: Optional[Path] = output_option("--report", "IDENT.html",
        "Write the report: force-velocity map, force residual, fit statistics (HTML, or PDF "
        "for a .pdf name)."),
    form: Annotated[str, typer.Option(
        "--form", metavar="symmetric|per-direction",
        help="symmetric: one Coulomb friction and an offset; per-direction: Coulomb "
             "friction per direction, no offset.")] = "symmetric",
    force: Force = False,
) -> None:
    """Identify mass, friction and force offset from a measured record (guideline step 1).

    Inverse-dynamics least squares on the filtered record gives the moving
    mass, Coulomb and viscous friction per direction and the offset, with
    standard errors; static friction, Stribeck velocity and bristle
    stiffness only where the record holds their excitation (breakaways after
    a stop, a slow velocity sweep through zero, presliding).
    """
    if ctx.args:  # the order reconcile and simulate take: SPEC.yaml MEASURED.csv
        if (len(ctx.args) > 1 or spec is not None
                or measured.suffix.lower() not in (".yaml", ".yml")):
            raise typer.BadParameter(
                f"one record only, got {measured}, {', '.join(ctx.args)}; the spec goes first "
                "(a .yaml file) or with --spec", param_hint="MEASURED.csv")
        spec, measured = measured, Path(ctx.args[0])
    forms = {"symmetric": "symmetric", "per-direction": "per_direction",
             "per_direction": "per_direction"}
    if form not in forms:
        raise typer.BadParameter("must be 'symmetric' or 'per-direction'", param_hint="--form")
    if spec is None and (write_spec is not None or report_out is not None):
        raise typer.BadParameter("--write-spec and --report need the stage's spec",
                                 param_hint="--spec")
    outs = check_outputs(tuple(p for p in (spec, measured) if p is not None), force,
                    json=(json_out, (".json",)), spec=(write_spec, (".yaml", ".yml")),
                    report=(report_out, (".html", ".pdf")))
    spec_obj = load(spec) if spec is not None else None

    from ..console import FractionBar, make_console, print_identification
    from ..identification import identified_spec_text, identify, kept_mass_message
    from ..measured import load_measurement

    data = load_measurement(measured)
    with FractionBar(make_console(stderr=True), "identifying") as bar:
        result = identify(data, spec_obj, form=forms[form], progress=bar)
    console = make_console()
    print_identification(console, result)
    payloads = {} if outs["json"] is None else {"json": json_text(result)}
    if outs["spec"] is not None:
        payloads["spec"] = identified_spec_text(result)
        kept = kept_mass_message(result)
        if kept:
            console.print(f"--write-spec: {kept}", style="yellow", markup=False)
    write_outputs(console, outs, payloads)
    write_report(console, outs["report"], result)


def main() -> None:
    """Console-script entry point (``fi-design``, ``python -m fi_design``)."""
    from .parts import run_app

    run_app(app)

