"""Benchmark of the open-loop replay (``simulate --record ... --drive force``): its cost over the kernel's.

Usage::

    python benchmarks/bench_open_loop.py [--rounds 7]

Replays examples/measured_trace.csv (8 s at 1 kHz) on the plant of
examples/measured_stage.yaml driven by the record's force, re-anchored every
0.1 s (80 windows, the default), as a reconciliation does in each of its
simulations. The yardstick, measured in the same call: the kernel's own
integration time (``SimulationResult.wall_time``, the sum over the windows).
Prints the best of ``--rounds`` of the whole call and its kernel time [ms],
their ratio (the Python around the kernel, per window: anchoring at the data,
the reference's pieces, the parameters), and the time per window [ms].
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    args = ap.parse_args(argv)

    from fi_design import load_spec, simulate
    from fi_design.measured import load_measurement

    spec = load_spec(ROOT / "examples" / "measured_stage.yaml")
    record = load_measurement(ROOT / "examples" / "measured_trace.csv")
    simulate(spec, record=record, drive="force")  # the kernel loaded, the record's fits kept
    best = (float("inf"), 0.0, 0)
    for _ in range(args.rounds):
        t0 = time.perf_counter()
        r = simulate(spec, record=record, drive="force")
        wall = time.perf_counter() - t0
        if wall < best[0]:
            best = (wall, r.wall_time, int(r.window.max()) + 1)
    wall, kernel, windows = best
    print("## Open-loop replay (`benchmarks/bench_open_loop.py`)\n")
    print(f"`python benchmarks/bench_open_loop.py --rounds {args.rounds}` on "
          f"{platform.machine()} with {os.cpu_count()} CPUs, Python "
          f"{platform.python_version()}; best of {args.rounds}.\n")
    print("| replay of examples/measured_trace.csv, `--drive force` | whole call [ms] | "
          "kernel [ms] | ratio | per window [ms] |")
    print("| --- | ---: | ---: | ---: | ---: |")
    print(f"| {windows} windows of 0.1 s | {wall * 1e3:.1f} | {kernel * 1e3:.1f} | "
          f"{wall / kernel:.2f} | {wall / windows * 1e3:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
