"""Benchmark of the simulation kernel, all figures measured in one run.

Usage::

    python benchmarks/bench_simulate.py [--repeat 20] [--skip-cold]

Prints a Markdown section for BENCHMARKS.md:

- one 20 s simulation of each paper-setup plant with the fast RODAS4 kernel
  (best of ``--repeat``), with the project's yardstick (LSODA, rtol 1e-6,
  atol 1e-10, outputs at 1 kHz, a plain Python right-hand side and no
  Jacobian, as a typical engineer writes it: the speed target is 100 times
  it for both plants), with a plain scipy solve_ivp call (LSODA and Radau,
  the same right-hand side and analytic Jacobian, modes taken from the
  state, no events) at the same nominal tolerance, and with python-control's
  ``input_output_response`` on the same right-hand side;
- the accuracy of each against a tight reference (Radau, rtol 1e-10);
- the ahead-of-time build (done once at install), the load of the built
  kernel, and numba's JIT instead (compile with an empty cache, load from
  it), each in a fresh process.

Ratios are against the fast kernel measured in the same run, so the machine's
load cancels out as far as it can.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "paper_setup.yaml"


def best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def kernel_only(spec, isolated: bool):
    """Time only the compiled integrator (the same call simulate() makes)."""
    from fi_design.kernel import run
    from fi_design.trajectory import from_moves
    from fi_design.model import resolve
    from fi_design.simulation.run import tolerances

    key = (id(spec), isolated)
    if key not in _PREPARED:
        par = resolve(spec).plant(isolated)
        ref = from_moves(spec.motion.moves, spec.motion.duration)
        _PREPARED[key] = (par.to_array(), np.zeros(par.n_states), ref, tolerances(par, 1e-6),
                          np.arange(20001) / 1000.0)
    p, y0, ref, atol, t_out = _PREPARED[key]
    return run(p, y0, ref.breaks, ref.coeffs, True, spec.motion.duration, t_out, 1e-6, atol,
               0.05)


_PREPARED: dict = {}


def plain_solve_ivp(spec, isolated: bool, t_end: float, method: str):
    """The same equations in a plain solve_ivp call: modes from the state, no events."""
    from scipy.integrate import solve_ivp

    from fi_design.kernel import equations as plant
    from fi_design.trajectory import from_moves
    from fi_design.model import resolve
    from fi_design.simulation.run import tolerances

    par = resolve(spec).plant(isolated)
    p = par.to_array()
    ref = from_moves(spec.motion.moves, t_end)
    n = par.n_states
    modes = np.zeros(4, dtype=np.int64)
    modes[0] = 1

    def f(t, x):
        x = np.ascontiguousarray(x, dtype=float)
        plant.natural_modes(x, p, modes)
        out = np.empty(n)
        plant.rhs(t, x, p, modes, float(ref(t)), float(ref(t, 1)), 0.0, True, out)
        return out

    def jac(t, x):
        x = np.ascontiguousarray(x, dtype=float)
        plant.natural_modes(x, p, modes)
        J = np.empty((n, n))
        plant.jacobian(t, x, p, modes, float(ref(t)), float(ref(t, 1)), 0.0, True, J)
        return J

    t = np.arange(int(t_end * 1000) + 1) / 1000.0
    sol = solve_ivp(f, (0.0, t_end), np.zeros(n), method=method, t_eval=t, rtol=1e-6,
                    atol=tolerances(par, 1e-6), jac=jac)
    return sol.y[0]


def engineer_lsoda(spec, isolated: bool, t_end: float):
    """The yardstick of the project's speed target, as a typical engineer writes it.

    ``solve_ivp(method="LSODA", rtol=1e-6, atol=1e-10, t_eval=1 kHz)`` on a
    plain Python right-hand side (floats and ``math``, no numba, no Jacobian):
    the paper plant's LuGre friction on the cart, the joint with its limiter
    (isolated), the PID with its output filter, the spec's move as its
    piecewise-cubic reference. Returns the stage position at the output times.
    """
    import bisect
    import math

    from scipy.integrate import solve_ivp

    from fi_design.model import resolve
    from fi_design.trajectory import from_moves

    p = resolve(spec).plant(isolated)
    if p.sample_period or p.delay or p.quantization or p.switch_model or p.pdf_amplitude \
            or p.ripple_amplitude or p.cable_stiffness or p.offset or p.kdm or p.ff_mass:
        raise SystemExit("the yardstick's right-hand side covers the paper plants only")
    ref = from_moves(spec.motion.moves, t_end)
    br = [float(b) for b in ref.breaks]
    co = [tuple(float(c) for c in row) for row in ref.coeffs]
    m1, m2, k, c, s, ks, cs = p.m1, p.m2, p.k, p.c, p.s, p.k_stop, p.c_stop
    Fs, Fc, vs, s0, s1, s2 = p.Fs, p.Fc, p.vs, p.sigma0, p.sigma1, p.sigma2
    kp, ki, kd, wt = p.kp, p.ki, p.kd, p.wt

    def reference(t):
        if t >= br[-1]:
            c0, c1, c2, c3 = co[-1]
            tau = br[-1] - br[-2]
            return c0 + tau * (c1 + tau * (c2 + tau * c3)), 0.0
        i = max(0, bisect.bisect_right(br, t) - 1)
        c0, c1, c2, c3 = co[i]
        tau = t - br[i]
        return c0 + tau * (c1 + tau * (c2 + tau * c3)), c1 + tau * (2.0 * c2 + 3.0 * tau * c3)

    def friction(v, z):
        g = Fc + (Fs - Fc) * math.exp(-(v / vs) ** 2)
        zd = v - s0 * abs(v) * z / g
        return zd, s0 * z + s1 * zd + s2 * v

    def f_isolated(t, y):
        x1, v1, x2, v2, z, i, u = y
        r, rd = reference(t)
        e = r - x1
        d, w = x1 - x2, v1 - v2
        fj = k * d + c * w
        if d > s:
            fj += ks * (d - s) + cs * w
        elif d < -s:
            fj += ks * (d + s) + cs * w
        zd, ff = friction(v2, z)
        return [v1, (u - fj) / m1, v2, (fj - ff) / m2, zd, ki * e,
                wt * (kp * e + i + kd * (rd - v1) - u)]

    def f_rigid(t, y):
        x, v, z, i, u = y
        r, rd = reference(t)
        e = r - x
        zd, ff = friction(v, z)
        return [v, (u - ff) / (m1 + m2), zd, ki * e, wt * (kp * e + i + kd * (rd - v) - u)]

    n = p.n_states
    t = np.arange(int(round(t_end * 1000)) + 1) / 1000.0
    sol = solve_ivp(f_isolated if isolated else f_rigid, (0.0, t_end), np.zeros(n),
                    method="LSODA", rtol=1e-6, atol=1e-10, t_eval=t)
    if not sol.success:
        raise SystemExit(f"the yardstick failed: {sol.message}")
    return sol.y[0]


def python_control_run(spec, isolated: bool, t_end: float):
    """The same equations through control.input_output_response (LSODA, modes from the state)."""
    import control

    from fi_design.kernel import equations as plant
    from fi_design.trajectory import from_moves
    from fi_design.model import resolve
    from fi_design.simulation.run import tolerances

    par = resolve(spec).plant(isolated)
    p = par.to_array()
    ref = from_moves(spec.motion.moves, t_end)
    n = par.n_states
    modes = np.zeros(4, dtype=np.int64)
    modes[0] = 1

    def upd(t, x, u, params):
        x = np.ascontiguousarray(x, dtype=float)
        plant.natural_modes(x, p, modes)
        out = np.empty(n)
        plant.rhs(t, x, p, modes, float(ref(t)), float(ref(t, 1)), 0.0, True, out)
        return out

    sys_ = control.nlsys(upd, None, inputs=0, outputs=n, states=n)
    t = np.arange(int(t_end * 1000) + 1) / 1000.0
    atol = tolerances(par, 1e-6)
    res = control.input_output_response(sys_, t, 0, np.zeros(n), solve_ivp_method="LSODA",
                                        solve_ivp_kwargs={"rtol": 1e-6, "atol": atol})
    return res.outputs[0]


def interleaved_ratios(spec, rounds: int) -> list[float]:
    """The yardstick over the fast path, round by round, each timed right after the other.

    The machine's speed drifts over minutes (the yardstick's best of three moved by
    40 % between runs of this script), and the two are timed a minute apart in the table
    above: here each round times both plants' ``simulate()`` (best of 10) and then one
    yardstick run of each, so that a drift reaches both alike; the median of the rounds'
    ratios is the figure.
    """
    from fi_design.simulation.run import simulate

    out = []
    for _ in range(rounds):
        fast = sum(best(lambda: simulate(spec, isolated=iso), 10) for iso in (True, False))
        yard = 0.0
        for iso in (True, False):
            t0 = time.perf_counter()
            engineer_lsoda(spec, iso, spec.motion.duration)
            yard += time.perf_counter() - t0
        out.append(yard / fast)
    return out


def fresh(code: str, env: dict) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True, env=env, cwd=ROOT)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--skip-cold", action="store_true")
    ap.add_argument("--rounds", type=int, default=9,
                    help="rounds of the interleaved ratio")
    args = ap.parse_args()

    from fi_design.simulation.run import simulate
    from fi_design.spec.file import load_spec

    spec = load_spec(SPEC)
    simulate(spec, isolated=True)  # compile or load the kernel
    rows = []
    total_fast = 0.0
    total_lsoda = 0.0
    total_yard = 0.0
    for iso, name in ((True, "isolated"), (False, "non-isolated")):
        fast = simulate(spec, isolated=iso)
        t_fast = best(lambda: simulate(spec, isolated=iso), args.repeat)
        t_kernel = best(lambda: kernel_only(spec, iso), args.repeat)
        tight = simulate(spec, isolated=iso, method="reference", rtol=1e-10)
        out = {}
        for method in ("LSODA", "Radau"):
            t0 = time.perf_counter()
            x = plain_solve_ivp(spec, iso, spec.motion.duration, method)
            out[method] = (time.perf_counter() - t0, x)
        t0 = time.perf_counter()
        pc = python_control_run(spec, iso, spec.motion.duration)
        out["control"] = (time.perf_counter() - t0, pc)
        yard = []
        for _ in range(3):  # best of 3, as the fast kernel is timed best of --repeat
            t0 = time.perf_counter()
            x = engineer_lsoda(spec, iso, spec.motion.duration)
            yard.append(time.perf_counter() - t0)
        out["yardstick"] = (min(yard), x)

        errors = {k: 1e6 * float(np.max(np.abs(x - tight.position))) for k, (_, x) in out.items()}
        total_fast += t_fast
        total_lsoda += out["LSODA"][0]
        total_yard += out["yardstick"][0]
        rows.append((name, fast.n_steps, t_fast, t_kernel,
                     1e6 * float(np.max(np.abs(fast.position - tight.position))), out, errors))
    print("## Simulation kernel (`benchmarks/bench_simulate.py`)\n")
    print(f"Measured {time.strftime('%Y-%m-%d')} on this machine in one run; paper setup, 20 s, "
          "outputs at 1 kHz. Accuracy: largest position difference from Radau at rtol 1e-10.\n")
    print("| plant | method | time [ms] | ratio to fast | max error [um] |")
    print("| --- | --- | ---: | ---: | ---: |")
    for name, steps, t_fast, t_kernel, e_fast, out, errors in rows:
        print(f"| {name} | `simulate()`: fast RODAS4 kernel ({steps} steps) with set-up, "
              f"traces and metrics | {1e3 * t_fast:.2f} | 1 | {e_fast:.3f} |")
        print(f"| {name} | the kernel call alone (`kernel.run`) | {1e3 * t_kernel:.2f} | "
              f"{t_kernel / t_fast:.2f} | |")
        for label, key in (("the yardstick (best of 3): LSODA, rtol 1e-6, atol 1e-10, plain "
                            "Python right-hand side, no Jacobian", "yardstick"),
                           ("plain solve_ivp LSODA, rtol 1e-6, analytic Jacobian", "LSODA"),
                           ("plain solve_ivp Radau, rtol 1e-6, analytic Jacobian", "Radau"),
                           ("python-control input_output_response (LSODA, no events)",
                            "control")):
            t, _ = out[key]
            print(f"| {name} | {label} | {1e3 * t:.0f} | {t / t_fast:.0f} | {errors[key]:.3f} |")
    print(f"\nBoth plants together: fast {1e3 * total_fast:.2f} ms; the yardstick (LSODA on a "
          f"plain Python right-hand side) {1e3 * total_yard:.0f} ms, ratio "
          f"{total_yard / total_fast:.0f} (target 100); LSODA on the compiled equations with "
          f"their Jacobian {1e3 * total_lsoda:.0f} ms, ratio {total_lsoda / total_fast:.0f}.\n")

    ratios = interleaved_ratios(spec, args.rounds)
    print(f"Interleaved, {args.rounds} rounds (both plants' `simulate()` best of 10, then one "
          f"yardstick run of each, in turn): ratio median {np.median(ratios):.0f}, range "
          f"{min(ratios):.0f}-{max(ratios):.0f} (target 100).\n")

    if not args.skip_cold:
        with tempfile.TemporaryDirectory() as out:
            build = fresh(f"from fi_design.kernel.build import build; build({out!r})",
                          dict(os.environ))
        load = fresh("from fi_design.kernel.build import compiled; "
                     "assert compiled().backend == 'aot'", dict(os.environ))
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, NUMBA_CACHE_DIR=cache, FI_DESIGN_KERNEL="jit")
            cold = fresh("from fi_design.kernel.build import compiled; compiled().integrate", env)
            warm = fresh("from fi_design.kernel.build import compiled; compiled().integrate", env)
            base = fresh("import numpy", env)
        print("| start-up (fresh processes) | time [s] |")
        print("| --- | ---: |")
        print(f"| `python -c 'import numpy'` (the yardstick) | {base:.2f} |")
        print(f"| ahead-of-time build of the kernel (once, at install) | {build:.1f} |")
        print(f"| load the built kernel (the default) | {load:.2f} |")
        print(f"| numba's JIT instead (FI_DESIGN_KERNEL=jit), empty cache: compile | {cold:.1f} |")
        print(f"| numba's JIT, cache warm: load | {warm:.2f} |")
        print("\nThe whole commands' start-up is measured by `benchmarks/bench_startup.py`.")

if __name__ == "__main__":
    main()
