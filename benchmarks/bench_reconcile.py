"""Benchmark of the reconciliation: a 20 s trace at 1 kHz against the whole catalogue.

Usage::

    python benchmarks/bench_reconcile.py [--effect NAME] [--no-isolator]

Generates a 20 s "measured" trace (1 kHz, 20001 samples) of the paper-like
stage of examples/measured_stage.yaml with a hidden effect (default
``position_dependent_friction``) and sensor noise, reconciles it against the
spec without the effect over all ten catalogue effects, and prints a Markdown
section for BENCHMARKS.md: the total time, the time, simulations and score of
every candidate, and the answer. The kernel is compiled (and cached) before the
clock starts. Target: under 2 minutes on the project's 2-core machine.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

HIDDEN = {
    "position_dependent_friction": {"amplitude": 0.25, "wavelength": 0.005, "phase": "0.8 rad"},
    "force_ripple": {"amplitude": 0.3, "pitch": 0.004, "phase": "1.0 rad"},
    "cable_force": {"stiffness": 60.0, "preload": -0.4},
    "time_delay": {"delay": 0.002},
    "quantization": {"resolution": 1e-6},
    "mass_error": {"stage_mass": 1.9, "cart_mass": 0.5},
    "viscous_friction": {"viscous": 35.0},
    "stribeck_velocity": {"stribeck_velocity": 0.008},
    "force_saturation": {"limit": 2.2},
    "joint_damping": {"damping": 15.0},
}


def trace(effect: str, isolated: bool):
    import yaml

    from fi_design.measured import measurement_from_arrays
    from fi_design.simulation.run import simulate
    from fi_design.spec import EFFECT_MODELS
    from fi_design.spec.file import load_spec

    raw = yaml.safe_load((ROOT / "examples" / "measured_stage.yaml").read_text())
    raw["motion"] = {"moves": [
        {"distance": "15 mm", "velocity": "20 mm/s", "acceleration": "0.5 m/s^2"},
        {"distance": "-15 mm", "velocity": "20 mm/s", "acceleration": "0.5 m/s^2",
         "start": "6 s"},
        {"distance": "10 mm", "velocity": "50 mm/s", "acceleration": "1 m/s^2",
         "start": "12 s"}], "duration": "20 s"}
    raw["requirements"] = {"hunting": {"window_start": "15 s", "window_length": "5 s"}}
    if not isolated:
        raw.pop("isolator")
    spec = load_spec(raw)
    entry = EFFECT_MODELS[effect].model_validate({"type": effect, **HIDDEN[effect]})
    res = simulate(spec, isolated, effects=[entry])
    rng = np.random.default_rng(3)
    n = len(res.time)
    x = np.asarray(res.position)
    if effect == "quantization":
        x = np.round(x / entry.resolution) * entry.resolution
    data = measurement_from_arrays(
        res.time, res.reference, x + 0.2e-6 * rng.standard_normal(n),
        np.asarray(res.force) + 2e-3 * rng.standard_normal(n),
        (np.asarray(res.deflection) + 0.02e-6 * rng.standard_normal(n)) if isolated else None)
    return spec, data


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--effect", default="position_dependent_friction", choices=sorted(HIDDEN))
    ap.add_argument("--no-isolator", action="store_true")
    args = ap.parse_args(argv)
    from fi_design.reconciliation import reconcile
    from fi_design.simulation.run import simulate

    isolated = not args.no_isolator
    spec, data = trace(args.effect, isolated)
    simulate(spec, isolated)  # compiled and cached before the clock starts
    t0 = time.perf_counter()
    result = reconcile(spec, data)
    total = time.perf_counter() - t0
    plant = "with isolator" if isolated else "without isolator"
    print(f"### Reconciliation: 20 s at 1 kHz, whole catalogue ({plant}, hidden "
          f"{args.effect})\n")
    print(f"Machine: {platform.machine()}, Python {platform.python_version()}; "
          f"`python benchmarks/bench_reconcile.py --effect {args.effect}"
          f"{' --no-isolator' if args.no_isolator else ''}`.\n")
    print(f"Answer: **{result.effect}** {result.parameters}; misfit "
          f"{result.gap_before['misfit']:.4g} -> {result.gap_after['misfit']:.4g} noise units; "
          f"{data.n} samples, {result.n_points} residual entries.\n")
    print(f"Total: **{total:.1f} s** ({result.n_simulations} simulations, "
          f"{1e3 * total / result.n_simulations:.1f} ms each on average; target < 120 s).\n")
    print("| Candidate | Time [s] | Simulations | ms / simulation | Score |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for c in sorted(result.candidates, key=lambda c: -c.wall_time):
        per = 1e3 * c.wall_time / max(c.n_simulations, 1)
        print(f"| `{c.name}` | {c.wall_time:.2f} | {c.n_simulations} | {per:.1f} | "
              f"{c.score:.4g} |")
    rest = total - sum(c.wall_time for c in result.candidates)
    print(f"| (nominal run, noise, segments, signatures, gap metrics) | {rest:.2f} | | | |")
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
