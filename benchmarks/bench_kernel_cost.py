"""What a change costs the simulation kernel: compile time and run time against a baseline commit.

Usage::

    python benchmarks/bench_kernel_cost.py --baseline REV [--rounds 3] [--repeat 20]

Checks the baseline revision out into a temporary git worktree and measures
both source trees in fresh processes, alternating baseline and current
(A B A B ...) so that a drifting machine load falls on both:

- the kernel's compile time with an empty numba cache (``NUMBA_CACHE_DIR``
  pointing at a new empty folder; the time of importing the kernel's source
  (``fi_design.kernel.integrator``, ``fi_design.kernel`` before it was a package)
  plus the first simulation, which compiles every function);
- the run time of one 20 s simulation of each plant of
  ``examples/paper_setup.yaml`` (the kernel alone, ``SimulationResult.wall_time``,
  best of ``--repeat``), with the numba cache warm.

Prints a Markdown section for BENCHMARKS.md with medians over the rounds and
the ratio current / baseline.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SNIPPET = r"""
import json, sys, time
t0 = time.perf_counter()
try:  # compiles, or loads the cache
    import fi_design.kernel.integrator  # noqa: F401
except ModuleNotFoundError:  # a baseline from before the kernel package
    import fi_design.kernel  # noqa: F401
from fi_design.simulation.run import simulate
from fi_design.spec.file import load_spec
spec = load_spec(sys.argv[1])
simulate(spec, isolated=True)
simulate(spec, isolated=False)
first = time.perf_counter() - t0
runs = {}
for iso in (True, False):
    runs[iso] = min(simulate(spec, isolated=iso).wall_time for _ in range(int(sys.argv[2])))
print(json.dumps({"first": first, "isolated": runs[True], "non_isolated": runs[False]}))
"""


def measure(src: Path, spec: Path, repeat: int, cold: bool) -> dict:
    """One fresh process on source tree ``src``; a new empty numba cache when ``cold``."""
    env = dict(os.environ, PYTHONPATH=str(src))
    with tempfile.TemporaryDirectory() as cache:
        if cold:
            env["NUMBA_CACHE_DIR"] = cache
        else:
            env["NUMBA_CACHE_DIR"] = str(src / ".bench_numba_cache")
        out = subprocess.run([sys.executable, "-c", SNIPPET, str(spec), str(repeat)], env=env,
                             check=True, capture_output=True, text=True, cwd=src)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--baseline", required=True, help="git revision to compare with")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=20)
    args = ap.parse_args()
    spec = ROOT / "examples" / "paper_setup.yaml"
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp) / "baseline"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(base),
                        args.baseline], check=True)
        try:
            rev = subprocess.run(["git", "-C", str(base), "rev-parse", "--short", "HEAD"],
                                 check=True, capture_output=True, text=True).stdout.strip()
            trees = {"baseline": base, "current": ROOT}
            for tree in trees.values():  # warm each tree's own cache for the run times
                measure(tree, spec, 1, cold=False)
            got = {k: {"compile": [], "isolated": [], "non_isolated": []} for k in trees}
            for _ in range(args.rounds):
                for name, tree in trees.items():
                    got[name]["compile"].append(measure(tree, spec, 1, cold=True)["first"])
                    warm = measure(tree, spec, args.repeat, cold=False)
                    got[name]["isolated"].append(warm["isolated"])
                    got[name]["non_isolated"].append(warm["non_isolated"])
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base)],
                           check=False)
    med = {k: {q: statistics.median(v) for q, v in d.items()} for k, d in got.items()}
    rows = [("kernel compile, empty cache, plus the first two simulations [s]", "compile", 1.0),
            ("isolated plant, 20 s, kernel alone [ms]", "isolated", 1e3),
            ("non-isolated (hunting) plant, 20 s, kernel alone [ms]", "non_isolated", 1e3)]
    print(f"Baseline {rev}, {args.rounds} rounds alternating baseline and current, medians; "
          f"run times best of {args.repeat}.\n")
    print("| figure | baseline | current | current / baseline |")
    print("| --- | ---: | ---: | ---: |")
    for label, key, scale in rows:
        b, c = med["baseline"][key] * scale, med["current"][key] * scale
        print(f"| {label} | {b:.3g} | {c:.3g} | {c / b:.2f} |")


if __name__ == "__main__":
    main()
