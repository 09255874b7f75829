"""Benchmark of the sign-off report, measured in one run.

Usage::

    python benchmarks/bench_report.py [--rounds 3]

Prints a Markdown section for BENCHMARKS.md:

- the whole command, ``fi-design examples/paper_setup.yaml --no-recommend`` with
  ``--json out.json``, ``--report out.html`` and ``--report out.pdf`` (fresh
  processes, the numba kernel cached: one untimed run first), each run paired with
  ``python -c "import control"`` in the same round; medians of ``--rounds`` of wall
  time, CPU time of the process and its children, and the paired ratio;
- the PDF's phases in one process on a design computed beforehand, as the design
  command runs them: the context and HTML with the figures placed by name, the
  figures drawn (matplotlib, PNG), WeasyPrint's import, layout and output, and the
  whole report written in one process and with its figures drawn by a worker
  (:func:`fi_design.cli.pools.report_pool`), best of ``--rounds``.

The machine's load average is printed with the figures: on a shared machine
the wall times grow with it, the CPU times much less.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "paper_setup.yaml"
YARDSTICK = [sys.executable, "-c", "import control"]


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(cmd: list[str]) -> tuple[float, float]:
    """Wall and CPU time [s] of a command in a fresh process (its children included)."""
    c0, t0 = _children_cpu(), time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   cwd=ROOT)
    return time.perf_counter() - t0, _children_cpu() - c0


def phase(fn, rounds: int) -> tuple[float, float, object, float]:
    """Best wall and CPU time [s] of an in-process call, its value, and the CPU time of
    its child processes [s] in that round."""
    best, value = (float("inf"), float("inf"), 0.0), None
    for _ in range(rounds):
        c0, t0, k0 = time.process_time(), time.perf_counter(), _children_cpu()
        value = fn()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        if wall < best[0]:
            best = (wall, cpu, _children_cpu() - k0)
    return best[0], best[1], value, best[2]


def _pages(pdf: Path) -> str:
    """Page count from poppler's pdfinfo, if installed."""
    import shutil

    if shutil.which("pdfinfo") is None:
        return "?"
    out = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True).stdout
    return next((ln.split()[-1] for ln in out.splitlines() if ln.startswith("Pages:")), "?")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        cli = [sys.executable, "-m", "fi_design", str(SPEC), "--no-recommend", "--force"]
        commands = {"`--json out.json`": cli + ["--json", str(tmp / "out.json")],
                    "`--report out.html`": cli + ["--report", str(tmp / "out.html")],
                    "`--report out.pdf`": cli + ["--report", str(tmp / "out.pdf")]}
        run(commands["`--json out.json`"])  # warm the kernel and the caches
        load0 = os.getloadavg()[0]
        rows: dict[str, list] = {k: [] for k in commands}
        for _ in range(args.rounds):
            for label, cmd in commands.items():
                yard = run(YARDSTICK)
                rows[label].append((*run(cmd), yard[0]))
        load1 = os.getloadavg()[0]

        from fi_design import design, report
        from fi_design.cli.pools import confirmation_pool, report_pool
        from fi_design.plots import deferred_figures
        from fi_design.spec.file import load_spec

        with confirmation_pool() as pool:
            result = design(load_spec(SPEC), executor=pool, recommend=False, fe_check=True,
                            sensitivity=True)

        def placed():
            with deferred_figures() as figures:
                html = report.render_html(report.build_context(result, date="2026-01-01"))
            return html, figures

        ctx_t = phase(placed, args.rounds)
        html, figures = ctx_t[2]
        fig_t = phase(figures.all_png, args.rounds)
        drawn = fig_t[2]

        class Drawn:  # the figures drawn beforehand: the layout below is WeasyPrint's alone
            @staticmethod
            def png(name: str) -> bytes:
                return drawn[name]

        from fi_design.report.render import (_collector_paused, _import_weasyprint,
                                             _png_as_is, _self_contained)

        c0, t0, k0 = time.process_time(), time.perf_counter(), _children_cpu()
        _import_weasyprint()  # as write_document imports it
        import_t = (time.perf_counter() - t0, time.process_time() - c0 + _children_cpu() - k0)
        import weasyprint

        def layout():  # as write_document runs it: the garbage collector paused
            with _collector_paused():
                return weasyprint.HTML(string=html, url_fetcher=_self_contained(Drawn)).render()

        def write():  # as write_document runs it: the PNG figures' rows taken as they are
            with _collector_paused(), _png_as_is():
                layout_t[2].write_pdf(str(pdf))

        layout_t = phase(layout, args.rounds)
        pdf = tmp / "phases.pdf"
        write_t = phase(write, args.rounds)
        here_t = phase(lambda: report.render_report(result, pdf, date="2026-01-01", force=True),
                       args.rounds)

        def apart():
            with report_pool(pdf) as workers:
                report.render_report(result, pdf, date="2026-01-01", executor=workers,
                                     force=True)

        apart_t = phase(apart, args.rounds)
        pages = _pages(pdf)
        pdf_size = pdf.stat().st_size / 1024

    print("## Sign-off report (`benchmarks/bench_report.py`)\n")
    print(f"`python benchmarks/bench_report.py --rounds {args.rounds}` on "
          f"{platform.machine()} with {os.cpu_count()} CPUs, Python "
          f"{platform.python_version()}; load average {load0:.1f} to {load1:.1f} during "
          "the command runs (other work on the machine). Kernel cached; each command "
          "paired with `python -c \"import control\"` in the same round, medians of "
          f"{args.rounds} rounds.\n")
    print("| `fi-design examples/paper_setup.yaml --no-recommend` | wall [s] | CPU, with "
          "children [s] | `import control` [s] | ratio (paired) |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for label, runs in rows.items():
        wall = statistics.median(r[0] for r in runs)
        cpu = statistics.median(r[1] for r in runs)
        yard = statistics.median(r[2] for r in runs)
        ratio = statistics.median(r[0] / r[2] for r in runs)
        print(f"| {label} | {wall:.2f} | {cpu:.2f} | {yard:.2f} | {ratio:.2f} |")
    print()
    print("| The PDF's phases (one process, design done; best of the rounds) | wall [s] | "
          "CPU [s] |")
    print("| --- | ---: | ---: |")
    for label, t in (("context and HTML, the figures placed by name", ctx_t),
                     ("the figures drawn (matplotlib, 200 dpi PNG)", fig_t),
                     ("WeasyPrint's import (CPU with child processes)", import_t),
                     ("WeasyPrint's layout (`render`), the garbage collector paused", layout_t),
                     ("WeasyPrint's output (`write_pdf`), the same", write_t)):
        print(f"| {label} | {t[0]:.2f} | {t[1]:.2f} |")
    print(f"| the report written in one process (`render_report`) | {here_t[0]:.2f} | "
          f"{here_t[1]:.2f} + {here_t[3]:.2f} in child processes (git, run once per "
          "process) |")
    print(f"| the report written, its figures drawn by a worker (`report_pool`) | "
          f"{apart_t[0]:.2f} | {apart_t[1]:.2f} + {apart_t[3]:.2f} in child processes "
          "(the worker, git) |")
    print()
    print(f"PDF {pdf_size:.0f} kB, {pages} pages.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
