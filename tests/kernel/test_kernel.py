"""The integrator's pieces against exact answers: linear algebra, dense output, order."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fi_design.kernel import integrator
from fi_design.kernel.equations import jacobian, rhs
from fi_design.kernel.layout import MODE_SIGN
from fi_design.trajectory import from_moves
from fi_design.model import resolve

from conftest import ROOT


@pytest.mark.parametrize("isolated", [True, False])
def test_structured_solve_equals_dense_solve(paper_spec, isolated):
    """Eliminating the leaf states gives the same solution as a dense solve."""
    p = resolve(paper_spec).plant(isolated).to_array()
    n = 7 if isolated else 5
    rng = np.random.default_rng(1)
    modes = np.zeros(4, dtype=np.int64)
    modes[MODE_SIGN] = 1
    for _ in range(20):
        y = rng.normal(size=n) * np.array([1e-3, 1e-2, 1e-3, 1e-2, 1e-6, 1.0, 1.0][:n])
        J = np.empty((n, n))
        jacobian(0.0, y, p, modes, 0.0, 0.0, 0.0, True, J)
        sigma = 10 ** rng.uniform(1, 6)
        M = np.empty((n - 3, n - 3))
        piv = np.empty(n - 3, dtype=np.int64)
        w = np.empty((4, max(n - 3, 3)))
        assert integrator.struct_factor(J, sigma, M, piv, w)
        b = rng.normal(size=n)
        x = b.copy()
        integrator.struct_solve(J, M, piv, w, x, np.empty(n))
        exact = np.linalg.solve(sigma * np.eye(n) - J, b)
        assert np.allclose(x, exact, rtol=1e-9, atol=1e-12 * np.max(np.abs(exact)))


FILTERS = [{"type": "notch", "frequency": "150 Hz", "width": "75 Hz", "depth": "20 dB"},
           {"type": "low_pass", "frequency": "600 Hz", "damping": 0.5},
           {"type": "low_pass", "frequency": "900 Hz", "order": 1}]


@pytest.mark.parametrize("isolated", [True, False])
@pytest.mark.parametrize("gains", [None, {"kp": 2000.0, "ki": 8000.0, "kd": 80.0}])
def test_the_jacobian_of_the_filter_chain_is_the_rhs_s_derivative(paper_spec, isolated, gains):
    """With the drive's filters (their states after u), the analytic Jacobian equals central
    differences of the right-hand side, the rule's filtered output and an ideal D's
    algebraic one alike; the dense solve of such a plant equals numpy's."""
    from conftest import variant

    more = {} if gains is None else {"controller.crossover": None, "controller.gains": gains}
    params = resolve(variant(paper_spec, **{"controller.filters": FILTERS}, **more)).plant(
        isolated)
    p = params.to_array()
    n = params.n_states
    assert n == (7 if isolated else 5) + 5
    rng = np.random.default_rng(2)
    modes = np.zeros(4, dtype=np.int64)
    modes[MODE_SIGN] = 1
    scale = np.array(([1e-3, 1e-2, 1e-3, 1e-2] if isolated else [1e-3, 1e-2])
                     + [1e-6, 1.0, 1.0] + [1.0] * 5)
    for _ in range(5):
        y = rng.normal(size=n) * scale
        J = np.empty((n, n))
        jacobian(0.0, y, p, modes, 1e-3, 1e-2, 0.3, True, J)
        fd = np.empty((n, n))
        for j in range(n):
            h = 1e-6 * scale[j]
            fp, fm = np.empty(n), np.empty(n)
            yp, ym = y.copy(), y.copy()
            yp[j] += h
            ym[j] -= h
            rhs(0.0, yp, p, modes, 1e-3, 1e-2, 0.3, True, fp)
            rhs(0.0, ym, p, modes, 1e-3, 1e-2, 0.3, True, fm)
            fd[:, j] = (fp - fm) / (2 * h)
        np.testing.assert_allclose(J, fd, rtol=1e-6, atol=1e-6 * np.max(np.abs(fd)))
        sigma = 10 ** rng.uniform(1, 6)
        M = np.empty((n, n))
        piv = np.empty(n, dtype=np.int64)
        assert integrator.factor_e(J, sigma, M, piv, np.empty((4, n)), True)
        b = rng.normal(size=n)
        x = b.copy()
        integrator.solve_e(J, M, piv, np.empty((4, n)), x, np.empty(n), True)
        exact = np.linalg.solve(sigma * np.eye(n) - J, b)
        assert np.allclose(x, exact, rtol=1e-9, atol=1e-12 * np.max(np.abs(exact)))


@settings(max_examples=60, deadline=None)
@given(t=st.floats(0.0, 25.0))
def test_reference_lookup_matches_the_vectorised_evaluation(paper_spec, t):
    ref = from_moves(paper_spec.motion.moves, 20.0)
    r, rd, rdd, _, _ = integrator.reference_at(t, np.array(ref.breaks), np.array(ref.coeffs), 0)
    assert r == pytest.approx(float(ref(t)), abs=1e-15)
    assert rd == pytest.approx(float(ref(t, 1)), abs=1e-12)
    assert rdd == pytest.approx(float(ref(t, 2)), abs=1e-9)


@settings(max_examples=80, deadline=None)
@given(start=st.floats(-1.0, 3.0).map(lambda s: round(s, 6)), t=st.floats(-2.0, 30.0),
       on_break=st.integers(-1, 40),
       derivative=st.integers(0, 2))
def test_one_time_lookup_is_the_vectorised_evaluation_bit_for_bit(start, t, on_break,
                                                                  derivative):
    """Trajectory.at (the reference solver's per-right-hand-side lookup) against the
    vectorised call, before the first break, on the breaks and after the last, for a
    jerk-limited move pair and a spline through samples."""
    from fi_design.spec import Move
    from fi_design.trajectory import from_samples

    moves = (Move(distance=0.01, velocity=0.05, acceleration=1.0, jerk=50.0, start=max(start, 0)),
             Move(distance=-0.002, velocity=0.05, acceleration=1.0, start=5.0 + start))
    samples = np.linspace(start, start + 3.0, 31)
    for ref in (from_moves(moves, 20.0), from_samples(samples, np.sin(samples) * 1e-3)):
        times = [t] + ([float(ref.breaks[on_break % len(ref.breaks)])] if on_break >= 0 else [])
        for tt in times:
            assert ref.at(tt, derivative) == float(ref(tt, derivative)), (tt, derivative)


def test_trapezoid_reference_reaches_the_target(paper_spec):
    mv = paper_spec.motion.moves[0]
    ref = from_moves(paper_spec.motion.moves, 20.0)
    t = np.linspace(0, 20, 200001)
    assert ref.final == pytest.approx(mv.distance, abs=1e-15)
    assert np.max(ref(t, 1)) == pytest.approx(mv.velocity)
    assert np.max(np.abs(ref(t, 2))) == pytest.approx(mv.acceleration)


def test_jerk_limited_reference_respects_all_limits(paper_spec):
    from fi_design.spec import Move

    moves = (Move(distance=0.01, velocity=0.05, acceleration=1.0, jerk=50.0),
             Move(distance=-0.002, velocity=0.05, acceleration=1.0, jerk=50.0, start=5.0))
    ref = from_moves(moves, 10.0)
    t = np.linspace(0, 10, 400001)
    assert ref.final == pytest.approx(0.008, abs=1e-12)
    assert np.max(np.abs(ref(t, 1))) <= 0.05 * (1 + 1e-9)
    assert np.max(np.abs(ref(t, 2))) <= 1.0 * (1 + 1e-9)
    acc = ref(t, 2)
    assert np.max(np.abs(np.diff(acc) / np.diff(t))) <= 50.0 * (1 + 1e-6)
    assert ref(4.9) == pytest.approx(0.01)


def test_dense_output_is_as_accurate_as_the_steps(paper_spec):
    """The 1 kHz outputs lie between steps (a few thousand steps for 20 001 samples);
    the continuous extension keeps them at the tolerance's accuracy, and tighter
    tolerance makes them better. The reference at rtol 1e-9 lies within 4e-13 of rtol 1e-10, a
    thousandth of the smallest difference measured here, at three quarters of its cost."""
    from fi_design.simulation.run import simulate

    exact = simulate(paper_spec, isolated=True, method="reference", rtol=1e-9)
    errs = []
    for rtol in (1e-4, 1e-6):
        r = simulate(paper_spec, isolated=True, rtol=rtol)
        assert r.n_steps < len(r.time) / 20
        errs.append(np.max(np.abs(r.position - exact.position)))
    assert errs[0] > 10 * errs[1]
    assert errs[1] < 1e-8  # 10 nm over a 10 mm move at rtol 1e-6


@pytest.mark.slow
def test_cache_falls_back_to_a_user_directory(tmp_path):
    """With no writable __pycache__ beside the source, numba caches in the user cache dir."""
    src = tmp_path / "pkg"
    shutil.copytree(os.path.dirname(os.path.dirname(integrator.__file__)), src / "fi_design",
                    ignore=shutil.ignore_patterns("__pycache__"))
    (src / "fi_design" / "kernel" / "__pycache__").write_text("a file, so no cache directory")
    cache = tmp_path / "xdg"
    env = dict(os.environ, PYTHONPATH=str(src), XDG_CACHE_HOME=str(cache))
    env.pop("NUMBA_CACHE_DIR", None)
    subprocess.run([sys.executable, "-c", "import fi_design.kernel.integrator"], check=True,
                   env=env, cwd=tmp_path)
    assert list(cache.rglob("integrator.integrate-*.nbi"))


def test_the_installed_kernel_is_the_ahead_of_time_build_of_these_sources():
    """An install compiles the kernel ahead of time (hatch_build.py); CI must get that build."""
    from fi_design.kernel import build

    k = build.compiled()
    if k.backend != "aot":
        if os.environ.get("CI"):
            pytest.fail(f"the kernel runs on numba's JIT in CI: {k.reason}")
        pytest.skip(f"the ahead-of-time kernel is not in use here: {k.reason}")
    from fi_design.kernel import _aot

    assert _aot.source_digest() == build.source_digest()
    # the simulation path runs without loading numba at all
    out = subprocess.run([sys.executable, "-c",
                          "import sys; from fi_design.spec.file import load_spec; "
                          "from fi_design.simulation.run import simulate; "
                          "r = simulate(load_spec(sys.argv[1]), isolated=False); "
                          "print(r.metrics.hunting_cycles, 'numba' in sys.modules)",
                          str(ROOT / "examples" / "paper_setup.yaml")],
                         check=True, capture_output=True, text=True)
    assert out.stdout.split() == ["5", "False"]


def test_the_jit_build_of_the_same_source_agrees(paper_spec, tmp_path):
    """FI_DESIGN_KERNEL=jit compiles the source with numba: the same trajectories as the
    build in use (to rounding; the hunting plant amplifies it by its stick-slip events)."""
    from fi_design.simulation.run import simulate

    code = ("import sys, numpy as np; from fi_design.spec.file import load_spec; "
            "from fi_design.simulation.run import simulate; from fi_design.kernel import build; "
            "s = load_spec(sys.argv[1]); "
            "np.save(sys.argv[2], np.array([simulate(s, isolated=i).position for i in (True, "
            "False)])); print(build.backend())")
    env = dict(os.environ, FI_DESIGN_KERNEL="jit")
    out = subprocess.run([sys.executable, "-c", code, str(
        ROOT / "examples" / "paper_setup.yaml"),
        str(tmp_path / "jit.npy")], env=env, check=True, capture_output=True, text=True)
    assert out.stdout.strip() == "jit"
    jit = np.load(tmp_path / "jit.npy")
    here = [simulate(paper_spec, isolated=i).position for i in (True, False)]
    assert np.max(np.abs(jit[0] - here[0])) < 1e-9
    assert np.max(np.abs(jit[1] - here[1])) < 1e-6


@pytest.mark.parametrize("argv, code", [(["--help"], 0), (["-h"], 0), (["--force"], 2),
                                        (["a", "b"], 2)])
def test_the_build_command_reads_its_options_without_building(argv, code, monkeypatch, capsys,
                                                              tmp_path):
    """``python -m fi_design.kernel.build --help`` built the kernel into a folder named
    '--help'; an option is now read as one (usage, or refused with exit code 2)."""
    from fi_design.kernel import build as kb

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(kb, "build", lambda *a, **k: pytest.fail("built the kernel"))
    monkeypatch.setattr("sys.argv", ["build", *argv])
    if code:
        with pytest.raises(SystemExit) as exc:
            kb.main()
        assert exc.value.code == code and "unexpected argument" in capsys.readouterr().err
    else:
        kb.main()
        assert "usage: python -m fi_design.kernel.build [DIR]" in capsys.readouterr().out
    assert not any(tmp_path.iterdir())
