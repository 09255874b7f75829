"""How to build the simulation kernel: what each way costs at install, on the first run and on a
warm run.

Usage::

    python benchmarks/bench_kernel_build.py [--rounds 3] [--repeat 10]

The ways measured (every figure in fresh processes, the median of
``--rounds``, the ways alternating round by round so a drifting machine load
falls on all of them):

- ``pycc``: numba's ahead-of-time compiler builds an extension module at
  install (``python -m fi_design.kernel.build``, the package's default); a
  run loads it and never imports numba.
- ``jit, cache filled at install``: numba's JIT of the same source, its
  on-disk cache filled by an install step that imports the source
  (``NUMBA_CACHE_DIR`` a fresh folder, ``FI_DESIGN_KERNEL=jit``).
- ``jit, cache not usable``: the same, where the install's cache does not
  apply at the first run (numba keys its cache on the source file's path and
  time stamp: a wheel unpacked elsewhere, files with new times, a read-only
  site-packages): the first run compiles.

"first run": a fresh process loading the spec, the kernel and simulating both
paper plants once (20 s each, outputs at 1 kHz), timed from its first
statement, and of that the kernel's load alone (``compiled()``: load the
extension, or import numba and compile or load its cache); "warm run": the
same process started again. "simulation": the
kernel's own time per plant in that process (best of ``--repeat``), which
tells whether a build runs slower code; ``--speed`` compares the two builds' run
time in one process instead, alternating between them (``compiled()`` chosen
anew each time), which a shared machine's drifting load disturbs less.

Prints a Markdown section for BENCHMARKS.md.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "paper_setup.yaml"

RUN = r"""
import time
t0 = time.perf_counter()
import json, sys
from fi_design.spec.file import load_spec
from fi_design.simulation.run import simulate
from fi_design.kernel.build import compiled
spec = load_spec(sys.argv[1])
t1 = time.perf_counter()
compiled()
kernel = time.perf_counter() - t1
simulate(spec, isolated=True)
simulate(spec, isolated=False)
first = time.perf_counter() - t0
best = {iso: min(simulate(spec, isolated=iso).wall_time for _ in range(int(sys.argv[2])))
        for iso in (True, False)}
print(json.dumps({"backend": compiled().backend, "numba": "numba" in sys.modules,
                  "first": first, "kernel": kernel, "isolated": best[True], "non_isolated": best[False]}))
"""


def process(args: list[str], env: dict) -> tuple[float, str]:
    """Wall time of a fresh Python process [s] and its standard output."""
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, *args], check=True, env=env, cwd=ROOT,
                          capture_output=True, text=True)
    return time.perf_counter() - t0, done.stdout


def run(env: dict, repeat: int) -> dict:
    _, out = process(["-c", RUN, str(SPEC), str(repeat)], env)
    return json.loads(out.strip().splitlines()[-1])


def one_round(repeat: int) -> dict:
    base = {k: v for k, v in os.environ.items() if k not in ("FI_DESIGN_KERNEL",
                                                              "NUMBA_CACHE_DIR")}
    rows: dict = {}
    with tempfile.TemporaryDirectory() as out:
        install, _ = process(["-m", "fi_design.kernel.build", out], base)
    first, warm = run(base, repeat), run(base, repeat)
    rows["pycc"] = dict(install=install, first=first, warm=warm)
    with tempfile.TemporaryDirectory() as cache:
        env = dict(base, NUMBA_CACHE_DIR=cache, FI_DESIGN_KERNEL="jit")
        install, _ = process(["-c", "import fi_design.kernel.integrator"], env)
        first, warm = run(env, repeat), run(env, repeat)
        rows["jit, cache filled at install"] = dict(install=install, first=first, warm=warm)
    with tempfile.TemporaryDirectory() as cache:
        env = dict(base, NUMBA_CACHE_DIR=cache, FI_DESIGN_KERNEL="jit")
        first, warm = run(env, repeat), run(env, repeat)
        rows["jit, cache not usable"] = dict(install=0.0, first=first, warm=warm)
    return rows


def speed(rounds: int, repeat: int) -> None:
    """Both builds' kernel time per plant in this process, alternating (needs the extension)."""
    from fi_design.kernel.build import BACKEND_ENV, compiled
    from fi_design.simulation.run import simulate
    from fi_design.spec.file import load_spec

    spec = load_spec(SPEC)
    times: dict = {}
    for _ in range(rounds):
        for way in ("aot", "jit"):
            os.environ[BACKEND_ENV] = way
            compiled.cache_clear()
            assert compiled().backend == way
            for iso in (True, False):
                best = min(simulate(spec, isolated=iso).wall_time for _ in range(repeat))
                times.setdefault((way, iso), []).append(best)
    print("| build | isolated [ms] | non-isolated [ms] |")
    print("| --- | ---: | ---: |")
    for way, label in (("aot", "pycc"), ("jit", "numba's JIT")):
        print(f"| {label} | {1e3 * statistics.median(times[(way, True)]):.2f} | "
              f"{1e3 * statistics.median(times[(way, False)]):.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--speed", action="store_true")
    args = ap.parse_args()
    if args.speed:
        speed(args.rounds, args.repeat)
        return
    rounds = [one_round(args.repeat) for _ in range(args.rounds)]
    for r in rounds:  # each way ran the build it names
        assert r["pycc"]["first"]["backend"] == "aot" and not r["pycc"]["first"]["numba"]
        assert all(r[k]["first"]["backend"] == "jit" for k in r if k != "pycc")

    def med(way, *keys):
        vals = []
        for r in rounds:
            v = r[way]
            for k in keys:
                v = v[k]
            vals.append(v)
        return statistics.median(vals)

    print(f"Measured {time.strftime('%Y-%m-%d')} on this machine, median of {args.rounds} rounds; "
          "paper setup, both plants, 20 s each.\n")
    print("| build | at install [s] | first run [s] (kernel load) | warm run [s] (kernel load) "
          "| simulation, isolated / non-isolated [ms] |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for way in rounds[0]:
        install = med(way, "install")
        print(f"| {way} | {install:.1f} | {med(way, 'first', 'first'):.2f} "
              f"({med(way, 'first', 'kernel'):.2f}) | {med(way, 'warm', 'first'):.2f} "
              f"({med(way, 'warm', 'kernel'):.2f}) | {1e3 * med(way, 'warm', 'isolated'):.2f} / "
              f"{1e3 * med(way, 'warm', 'non_isolated'):.2f} |")


if __name__ == "__main__":
    main()
