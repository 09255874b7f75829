"""Benchmark of the sign-off report, measured in one run.

Usage::

    python benchmarks/bench_report.py [--repeat 3]

Prints a Markdown section for BENCHMARKS.md:

- the whole command, ``fi-design examples/paper_setup.yaml`` without a report,
  with ``--report out.html`` and with ``--report out.pdf`` (fresh processes,
  the numba kernel cached: one untimed run first), best of ``--repeat``, wall
  time and the CPU time of the process and its children;
- the report's phases in one process on a design computed beforehand: the
  context with its figures (matplotlib), the HTML (jinja), the PDF
  (WeasyPrint), each wall and CPU time, best of ``--repeat``.

The machine's load average is printed with the figures: on a shared machine
the wall times grow with it, the CPU times much less.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "paper_setup.yaml"
CLI = Path(sys.executable).parent / "fi-design"


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_cli(args: list[str], repeat: int) -> tuple[float, float]:
    """Best wall and CPU time [s] of the command in fresh processes."""
    best = (float("inf"), float("inf"))
    for _ in range(repeat):
        c0, t0 = _children_cpu(), time.perf_counter()
        subprocess.run([str(CLI), *args], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, cwd=ROOT)
        wall, cpu = time.perf_counter() - t0, _children_cpu() - c0
        if wall < best[0]:
            best = (wall, cpu)
    return best


def phase(fn, repeat: int) -> tuple[float, float, object]:
    """Best wall and CPU time [s] of an in-process call, and its value."""
    best, value = (float("inf"), float("inf")), None
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        value = fn()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        if wall < best[0]:
            best = (wall, cpu)
    return best[0], best[1], value


def _pages(pdf: Path) -> str:
    """Page count from poppler's pdfinfo, if installed."""
    import shutil

    if shutil.which("pdfinfo") is None:
        return "?"
    out = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True).stdout
    return next((ln.split()[-1] for ln in out.splitlines() if ln.startswith("Pages:")), "?")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)

    with tempfile.TemporaryDirectory() as tmp:
        html, pdf = Path(tmp) / "out.html", Path(tmp) / "out.pdf"
        subprocess.run([str(CLI), str(SPEC)], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)  # warm the kernel cache
        load0 = os.getloadavg()[0]
        plain = run_cli([str(SPEC)], args.repeat)
        with_html = run_cli([str(SPEC), "--report", str(html), "--force"], args.repeat)
        with_pdf = run_cli([str(SPEC), "--report", str(pdf), "--force"], args.repeat)
        load1 = os.getloadavg()[0]

        from fi_design import design, report
        from fi_design.spec.file import load_spec

        result = design(load_spec(SPEC))
        ctx_t = phase(lambda: report.build_context(result, date="2026-01-01"), args.repeat)
        ctx = ctx_t[2]
        html_t = phase(lambda: report.render_html(ctx), args.repeat)
        text = html_t[2]
        pdf_t = phase(lambda: report.write_document(text, pdf), args.repeat)
        pages = _pages(pdf)
        html_size = len(text.encode("utf-8")) / 1024
        pdf_size = pdf.stat().st_size / 1024

    print("## Sign-off report (`fi-design SPEC --report`)\n")
    print(f"`python benchmarks/bench_report.py --repeat {args.repeat}` on "
          f"{platform.machine()} with {os.cpu_count()} CPUs, Python "
          f"{platform.python_version()}; load average {load0:.1f} to {load1:.1f} during "
          "the command runs (other work on the machine). Kernel cached; best of "
          f"{args.repeat}.\n")
    print("| `fi-design examples/paper_setup.yaml` | wall [s] | CPU, with children [s] |")
    print("| --- | ---: | ---: |")
    for label, (w, c) in (("no report", plain), ("`--report out.html`", with_html),
                          ("`--report out.pdf`", with_pdf)):
        print(f"| {label} | {w:.2f} | {c:.2f} |")
    print()
    print("| Report phase (one process, design done) | wall [s] | CPU [s] |")
    print("| --- | ---: | ---: |")
    for label, t in (("context and 6 figures (matplotlib, SVG)", ctx_t),
                     ("HTML (jinja)", html_t), ("PDF from the HTML (WeasyPrint)", pdf_t)):
        print(f"| {label} | {t[0]:.2f} | {t[1]:.2f} |")
    print()
    print(f"HTML {html_size:.0f} kB (self-contained), PDF {pdf_size:.0f} kB, {pages} pages.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
