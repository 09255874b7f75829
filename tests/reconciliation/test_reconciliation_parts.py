"""The reconciliation's parts on signals with a known answer: lattice, noise, effective samples.

- the lattice test reads the step and the share of samples on it from the
  positions alone (whole counts, counts under noise), finds none in an
  unquantized signal, and is not fooled by the regular pitch v dt of a
  constant-velocity move sampled at a fixed rate;
- the integrated autocorrelation time is 1 for white residuals and
  (1 + phi) / (1 - phi) for an AR(1) series;
- a failed run scores far above the nominal misfit (it can never win a fit);
- a parameter with a reference value but no standard error fails the distance
  test (nothing tells it from the model's value); one without a reference (a
  phase) does not.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fi_design.reconciliation.lattice import find_lattice
from fi_design.reconciliation.noise import autocorrelation_time, estimate_noise

RATE = 1000.0


def _motion(seconds: float = 4.0) -> np.ndarray:
    """A smooth back-and-forth motion [m] sampled at 1 kHz (10 mm strokes, slow and fast parts)."""
    t = np.arange(int(seconds * RATE)) / RATE
    return 5e-3 * (1.0 - np.cos(2 * np.pi * 0.5 * t)) + 2e-4 * np.sin(2 * np.pi * 3.1 * t)


def test_whole_counts_are_an_exact_lattice():
    q = 5e-8
    x = np.round(_motion() / q) * q
    lat = find_lattice(x, estimate_noise(x))
    assert lat.found and lat.exact
    assert lat.step == pytest.approx(q, rel=1e-9)
    assert lat.fraction == 1.0 and lat.chance == pytest.approx(0.02)
    assert lat.p_value < 1e-9
    assert lat.step_error > 0
    # counts are this record's only noise: a coarse lattice
    assert lat.coarse


def test_a_fine_logger_grid_under_a_noisy_signal_is_not_coarse():
    q = 5e-8
    rng = np.random.default_rng(8)
    x = np.round((_motion() + 1e-6 * rng.standard_normal(4000)) / q) * q
    lat = find_lattice(x, estimate_noise(x))
    assert lat.found and lat.exact and not lat.coarse


def test_counts_with_noise_added_after_them():
    q, sigma = 2e-6, 0.2e-6
    rng = np.random.default_rng(3)
    x = np.round(_motion() / q) * q + sigma * rng.standard_normal(4000)
    lat = find_lattice(x, estimate_noise(x))
    assert lat.found and not lat.exact
    assert lat.step == pytest.approx(q, rel=1e-3)
    assert abs(lat.step - q) <= 5 * lat.step_error
    assert lat.jitter == pytest.approx(sigma, rel=0.2)
    assert lat.fraction > 0.6 and lat.chance == 0.5 and lat.p_value < 1e-9
    assert lat.coarse  # a 2 um staircase under 0.2 um noise


def test_no_lattice_in_an_unquantized_noisy_signal():
    rng = np.random.default_rng(4)
    x = _motion() + 0.2e-6 * rng.standard_normal(4000)
    assert not find_lattice(x, estimate_noise(x)).found


def test_a_constant_velocity_pitch_is_no_lattice():
    """20 um per sample: the raw samples sit on 5 um and 10 um lattices, the sensor does not."""
    rng = np.random.default_rng(5)
    t = np.arange(4000) / RATE
    x = 0.02 * t + 0.05e-6 * rng.standard_normal(4000)
    assert not find_lattice(x, estimate_noise(x)).found


def test_autocorrelation_time_of_white_and_ar1_series():
    rng = np.random.default_rng(6)
    white = rng.standard_normal(20000)
    assert autocorrelation_time(white) == pytest.approx(1.0, abs=0.15)
    phi = 0.8
    ar = np.empty(20000)
    ar[0] = 0.0
    e = rng.standard_normal(20000)
    for i in range(1, len(ar)):
        ar[i] = phi * ar[i - 1] + e[i]
    assert autocorrelation_time(ar) == pytest.approx((1 + phi) / (1 - phi), rel=0.2)


def test_a_failed_run_scores_far_above_the_nominal_misfit(paper_spec):
    from fi_design.measured import measurement_from_arrays
    from fi_design.reconciliation.comparison import FAIL_FACTOR, Comparison, ModelRun
    from fi_design.reconciliation.noise import noise_levels
    from fi_design.simulation.run import simulate

    res = simulate(paper_spec, True)
    rng = np.random.default_rng(7)
    n = len(res.time)
    data = measurement_from_arrays(res.time[:3000], res.reference[:3000],
                                   res.position[:3000] + 1e-6 * rng.standard_normal(3000),
                                   res.force[:3000] + 1e-3 * rng.standard_normal(3000))
    lat = find_lattice(data.position, estimate_noise(data.position))
    cmp = Comparison(paper_spec, data, False, noise_levels(paper_spec, data, False, lat), lat,
                     None, "closed")
    nominal = cmp.run([])
    cmp.finish_setup(nominal, 1000)
    r = cmp.residuals(nominal)
    chi2 = float(r @ r)
    cmp.set_fail_level(chi2)
    nan = np.full(cmp.n, math.nan)
    failed = ModelRun(nan, nan, None, ok=False, message="solution diverged")
    rf = cmp.residuals(failed)
    assert float(rf @ rf) == pytest.approx(FAIL_FACTOR ** 2 * max(chi2, cmp.n_points))
    assert float(rf @ rf) > 50 * chi2
    assert n > 3000


def _fast_record(spec, rate: float):
    """The spec's own motion at ``rate``, with sensor noise: a record logged fast."""
    from fi_design.measured import measurement_from_arrays
    from fi_design.simulation.run import simulate
    from fi_design.spec.file import with_values

    res = simulate(with_values(spec, {"simulation.output_rate": rate}))
    rng = np.random.default_rng(5)
    n = len(res.time)
    return measurement_from_arrays(res.time, res.reference,
                                   res.position + 0.2e-6 * rng.standard_normal(n),
                                   res.force + 2e-3 * rng.standard_normal(n),
                                   res.deflection + 0.02e-6 * rng.standard_normal(n))


def test_a_record_logged_faster_than_the_model_needs_is_thinned():
    """A 10 kHz record of an 8 Hz loop is compared at 1 kHz (every 10th sample, as recorded);
    the conclusion says so. Every run of the model had a sample per record sample, and every
    evaluation of a fit kept its run: 17 GB for two million samples."""
    from fi_design.reconciliation import reconcile
    from fi_design.spec.file import load_spec

    from conftest import EXAMPLES

    spec = load_spec(EXAMPLES / "measured_stage.yaml")
    record = _fast_record(spec, 10_000.0)
    result = reconcile(spec, record, candidates=["viscous_friction"])
    assert result.measurement.n == math.ceil(record.n / 10)
    assert f"({record.n} samples at 10000 Hz) was compared at every 10th sample" \
        in result.conclusion
    assert result.effect == "none"


def test_the_thinning_and_its_bound():
    from fi_design.errors import DataError
    from fi_design.measured import measurement_from_arrays
    from fi_design.reconciliation.records import MAX_SAMPLES, for_the_model

    n = 300_000  # 30 s at 10 kHz
    t = np.arange(n) * 1e-4
    m = measurement_from_arrays(t, np.zeros(n), 1e-3 * np.sin(t))
    kept, note = for_the_model(m, 8.0)  # 1 kHz needed: 30 000 samples
    assert kept.n == 30_000 and "every 10th sample" in note
    kept, note = for_the_model(m, 0.5)  # 1 kHz still (the floor)
    assert kept.n == 30_000
    with pytest.raises(DataError, match=f"at most {MAX_SAMPLES}") as err:
        for_the_model(m, 200.0)  # 4 kHz at least: 120 000 samples
    assert "at most 25 s of the record" in str(err.value)
    at_1khz = measurement_from_arrays(t[::10], np.zeros(n // 10), 1e-3 * np.sin(t[::10]))
    same, note = for_the_model(at_1khz, 8.0)
    assert same is at_1khz and note == ""


def test_a_closed_loop_force_scale_names_the_specs_masses_beside_the_column():
    """examples/measured_trace.csv (a 2 kg stage) reconciled against examples/emps_axis.yaml
    (a 100 kg axis) read "the measured force is 0.0392 times the model's ... Check force_N's
    unit (N) and the logger's gain ... correct the column and reconcile again": a right
    column blamed for a wrong spec. The model's force follows the spec's masses, so the
    factor says as much about them; the message now names both."""
    from fi_design.reconciliation.diagnosis import _message, force_check

    t = np.linspace(0.0, 2.0, 400)
    model = 50.0 * np.sin(2 * np.pi * t)
    measured = 0.04 * model + 0.01 * np.random.default_rng(0).standard_normal(len(t))
    cmp = SimpleNamespace(has_force=True, meas=SimpleNamespace(force=measured),
                          noise=SimpleNamespace(force=0.01))
    check = force_check(cmp, SimpleNamespace(ok=True, force=model))
    assert check.cause.name == "force_scale" and check.scale == pytest.approx(0.04, rel=0.01)
    assert "force_N's unit (N)" in check.cause.detail
    assert "the spec's masses" in check.cause.detail
    text = _message(4460.0, 4460.0, 0.19, "", [check.cause], check)
    assert text.endswith("correct the column (or the spec) and reconcile again.")


def test_open_loop_structure_causes_name_no_controller(paper_spec):
    """An open-loop replay (drive="force") has no controller: the structure diagnosis of the
    same residual names the measured force where a closed loop names the controller, and
    the mechanics' state (not the integrator) as the initial state."""
    from fi_design.measured import measurement_from_arrays
    from fi_design.reconciliation.comparison import Comparison, ModelRun
    from fi_design.reconciliation.diagnosis import diagnose
    from fi_design.reconciliation.noise import noise_levels
    from fi_design.simulation.run import simulate

    res = simulate(paper_spec, False)
    n = 2000
    rng = np.random.default_rng(11)
    data = measurement_from_arrays(res.time[:n], res.reference[:n],
                                   res.position[:n] + 1e-7 * rng.standard_normal(n),
                                   res.force[:n] + 1e-3 * rng.standard_normal(n))
    lat = find_lattice(data.position, estimate_noise(data.position))
    text = {}
    for drive in ("closed", "force"):
        noise = noise_levels(paper_spec, data, False, lat, force_is_input=drive == "force")
        cmp = Comparison(paper_spec, data, False, noise, lat, None, drive)
        # a model whose position rings fast and starts off: far above the noise
        t = cmp.t - cmp.t[0]
        x = data.position + 2e-6 * np.sin(2 * np.pi * 40.0 * t) + 5e-6 * np.exp(-t / 0.02)
        f = res.force[:n] + 0.5 * np.sin(2 * np.pi * 40.0 * t) if drive == "closed" else \
            np.full(n, np.nan)
        nominal = ModelRun(x, f, None, ok=True, message="")
        cmp.finish_setup(nominal, 1000)
        r = cmp.residuals(nominal)
        d = diagnose(cmp, nominal, float(r @ r), best_explained=0.0)
        assert d.mismatch, drive
        text[drive] = ({c.name: c.detail for c in d.causes}, d.message)
    closed, _ = text["closed"]
    causes, message = text["force"]
    assert "controller" in closed and closed["controller"].endswith(
        "where the controller shapes the response: check the controller description (gains, "
        "the derivative's input and filter, sample rate, delay).")
    assert closed["initial_state"].endswith(
        "check the state the replay starts from (position, velocity, the controller's "
        "integrator).")
    assert set(causes) == {"measured_force", "initial_state", "mass", "disturbance"}
    assert causes["measured_force"].endswith(
        "where the recorded force alone drives the open-loop replay: check force_N (its timing "
        "against position_m, the logger's filter, the drive's gain) and fast dynamics of the "
        "mechanics the spec lacks (a resonance, a compliance).")
    assert causes["initial_state"].endswith(
        "check the state of the mechanics the open-loop replay starts from (position and "
        "velocity from the record, the friction's presliding state).")
    assert causes["disturbance"].endswith("(a load, a cable, a drift, or an offset of force_N).")
    assert "measured force" in message
    assert not any("controller" in s for s in (message, *causes.values()))


@pytest.mark.parametrize("reference, inactive, blind",
                         [(5.0, None, True), (None, None, False), (None, 17.0, True)])
def test_a_parameter_without_a_standard_error_is_not_shown_to_differ(reference, inactive, blind):
    from fi_design.reconciliation.significance import _verdict
    from fi_design.reconciliation.spaces import Space

    space = Space("force_saturation", [], dict, references={"limit": reference, "amplitude": 0.0},
                  inactive_at={} if inactive is None else {"limit": inactive})
    outcome = SimpleNamespace(run=SimpleNamespace(ok=True, message=""), at_bound=(),
                              space=space)
    st = SimpleNamespace(value=60.0, n_effective=500.0)
    # the amplitude lies 4 standard errors out: without the limit the candidate passes
    verdict = _verdict(outcome, st, 40.0, 0.9, {"limit": None, "amplitude": 4.0}, 10.0, None)
    assert any("no standard error for limit" in r for r in verdict.reasons) is blind
    assert len(verdict.reasons) == int(blind)


def test_a_single_finding_states_its_misfit_once():
    """'The measurement shows X (...; misfit 2052 -> 0.98). With it the misfit drops from 2052
    to 0.98 noise units.': one effect's misfit was said twice (and with an ASCII arrow); two
    effects keep each step's misfit, the arrow a real one."""
    from types import SimpleNamespace

    from fi_design.reconciliation.workflow import _conclusion

    def step(name, value, before, after):
        return SimpleNamespace(name=name, parameters={"offset": value},
                               uncertainty={"offset": 0.01}, misfit_before=before,
                               misfit_after=after)

    clean = SimpleNamespace(mismatch=False)
    n = 1000
    one = _conclusion([step("force_offset", 0.5, 40.0, 1.0)], [], 1600.0 * n, 1.0 * n, n, [],
                      clean)
    assert one.count("40") == 1 and "->" not in one, one
    two = _conclusion([step("force_offset", 0.5, 40.0, 5.0), step("force_offset", 0.2, 5.0,
                                                                  1.0)],
                      [], 1600.0 * n, 1.0 * n, n, [], clean)
    assert "misfit 40 \u2192 5)" in two and "misfit 5 \u2192 1)" in two, two
