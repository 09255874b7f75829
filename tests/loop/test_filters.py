"""The drive's filters: in the spec, in the four limit cases, sampled as a drive samples them,
the mode that limits the crossover and what a notch there allows, every crossing, the plots.

Independent answers: python-control's own margins and ``c2d`` on controllers built here from
their textbook forms, crossings found on a dense grid, the drawn figure's data.
"""

from __future__ import annotations

import math
import re

import control
import numpy as np
import pytest

from fi_design.loop import linear
from fi_design.loop.achievable import achievable_crossover
from fi_design.controller import (controller_polynomials, discrete_controller,
                                  filter_polynomials, pid_polynomials, tustin_biquad)
from fi_design.controller.discrete import pid_z
from fi_design.errors import SpecError
from fi_design.guideline.evaluate import evaluate as design
from fi_design.guideline.steps import step2_crossover
from fi_design.model import resolve

from conftest import variant

NOTCH = {"type": "notch", "name": "tilt notch", "frequency": "150 Hz", "width": "75 Hz"}
M = 2.0  # the paper setup's tuning mass m1 + m2 [kg]


def _rule_pid(fc: float):
    """The paper's rule (docs/model.md) written out in python-control."""
    wc = 2 * math.pi * fc
    ks, wd, wt, wi = M * wc ** 2 / 3, wc / 3, 3 * wc, wc / 10
    return ks * control.tf([1, wi], [1, 0]) * control.tf([1 / wd, 1], [1 / wt, 1])


def _notch(f0: float, width: float):
    w = 2 * math.pi * f0
    return control.tf([1, 0, w * w], [1, 2 * (width / (2 * f0)) * w, w * w])


def _control_margins(model, fc: float, notch=None) -> dict:
    """python-control's margins of each case: the rule's PID and the notch built here in series
    with the library's state-space plant of the case."""
    out = {}
    for lc in linear.limit_cases(model):
        L = _rule_pid(fc) * control.ss2tf(lc.plant) * (1 if notch is None else notch)
        gm, pm, _sm, _wpc, _wgc, _wms = control.stability_margins(L, returnall=True)
        db = 20 * np.log10(np.asarray(gm, float))
        db = db[np.isfinite(db) & (np.abs(db) < 100)]  # crossings at 1e-10 or 1e20: numerics
        stable = bool(np.all(np.real(control.poles(control.feedback(L, 1))) < 0))
        out[lc.name] = {"gm": float(np.min(np.abs(db))) if db.size else math.inf,
                        "pm": float(np.min(np.abs(pm))), "stable": stable}
    return out


def _passes(margins: dict) -> bool:
    return all(m["stable"] and m["gm"] >= 6.0 and m["pm"] >= 30.0 for m in margins.values())


# --------------------------------------------------------------------------- spec


def test_filters_and_drive_read_from_the_spec(paper_spec):
    spec = variant(paper_spec, **{"controller.filters": [
        NOTCH, {"type": "notch", "frequency": "300 Hz", "width": "60 Hz", "depth": "20 dB"},
        {"type": "notch", "frequency": "400 Hz", "damping": [0.01, 0.2]},
        {"type": "low_pass", "frequency": "1 kHz", "order": 1}],
        "controller.drive": {"motor_constant": "20 N/A", "encoder_resolution": "1 um",
                             "current_scaling": "10 mA"}})
    law = resolve(spec).law
    n1, n2, n3, lp1 = law.filters
    assert (n1.kind, n1.frequency, n1.zeta_pole, n1.zeta_zero) == ("notch", 150.0, 0.25, 0.0)
    assert n1.width == pytest.approx(75.0) and math.isinf(n1.depth)
    assert n2.zeta_zero == pytest.approx(0.1 * 10 ** (-1)) and n2.depth == pytest.approx(20.0)
    assert (n3.zeta_zero, n3.zeta_pole) == (0.01, 0.2)
    assert lp1.order == 1
    lp2 = resolve(variant(paper_spec, **{"controller.filters": [
        {"type": "low_pass", "frequency": "2 kHz"}]})).law.filters[0]
    assert (lp2.order, lp2.zeta_pole) == (2, pytest.approx(2 ** -0.5))
    d = law.drive
    assert (d.motor_constant, d.encoder_resolution, d.current_scaling) == (20.0, 1e-6, 0.01)
    # the filters keep their frequencies when the loop shifts
    assert resolve(spec).at(crossover=15.0).law.filters == law.filters


def test_a_filter_left_unnamed_is_not_quoted_by_its_default_name(paper_spec):
    """An unnamed notch read "notch 'notch' at 150 Hz" in the checks and the report, and
    "notch 'notch' 150 Hz" in the console's gains caption; an unnamed low-pass
    "low-pass 'low-pass'". The default name is left out; a given one is quoted."""
    from fi_design.console.design import _filter_words

    spec = variant(paper_spec, **{"controller.filters": [
        {"type": "notch", "frequency": "150 Hz", "width": "75 Hz"}, NOTCH,
        {"type": "low_pass", "frequency": "1 kHz", "order": 1},
        {"type": "low_pass", "name": "anti-alias", "frequency": "2 kHz"}]})
    words = [(f.describe(), _filter_words(f.to_dict())) for f in resolve(spec).law.filters]
    before_number = [(re.match(r"(.*?)( at)? \d", d).group(1),
                      re.match(r"(.*?) \d", c).group(1)) for d, c in words]
    assert before_number == [
        ("notch", "notch"), ("notch 'tilt notch'", "notch 'tilt notch'"),
        ("first-order low-pass", "low-pass"),
        ("second-order low-pass 'anti-alias'", "low-pass 'anti-alias'")], words


@pytest.mark.parametrize("entry, words", [
    ({"type": "notch", "frequency": "150 Hz"}, "width"),
    ({"type": "notch", "frequency": "150 Hz", "width": "10 Hz", "damping": [0, 0.1]}, "not both"),
    ({"type": "notch", "frequency": "150 Hz", "damping": [0.2, 0.1]}, "zeros < poles"),
    ({"type": "low_pass", "frequency": "1 kHz", "order": 1, "damping": 0.7}, "no damping"),
    ({"type": "band_stop", "frequency": "1 kHz"}, "unknown filter type"),
    ({"type": "notch", "frequency": "150 mm", "width": "10 Hz"}, "frequency"),
])
def test_a_bad_filter_is_named(paper_spec, entry, words):
    with pytest.raises(SpecError, match=words) as err:
        variant(paper_spec, **{"controller.filters": [entry]})
    assert "controller.filters[0]" in str(err.value)


def test_at_most_four_filters(paper_spec):
    with pytest.raises(SpecError, match="at most 4") as err:
        variant(paper_spec, **{"controller.filters": [NOTCH] * 5})
    assert "controller.filters" in str(err.value)


def test_a_filter_above_nyquist_is_refused(paper_spec):
    with pytest.raises(SpecError, match="Nyquist"):
        variant(paper_spec, **{"controller.sample_rate": "1 kHz",
                               "controller.filters": [{"type": "low_pass",
                                                       "frequency": "600 Hz"}]})


# --------------------------------------------------------------------------- the loop


def test_the_filters_are_in_series_with_the_pid(paper_spec):
    spec = variant(paper_spec, **{"controller.filters": [NOTCH]})
    law = resolve(spec).law
    s = 2j * math.pi * np.geomspace(1, 1000, 50)
    num, den = controller_polynomials(law)
    C = np.polyval(num, s) / np.polyval(den, s)
    want = np.array([complex(np.squeeze(_rule_pid(8.0)(x) * _notch(150.0, 75.0)(x)))
                     for x in s])
    np.testing.assert_allclose(C, want, rtol=1e-9)


def test_a_notch_at_the_tilt_mode_lifts_the_achievable_crossover(paper_spec):
    """The paper setup's 150 Hz stage tilt limits the crossover through the gain margin of
    case 4 at its resonance; a notch there gain-stabilises it. python-control's own margins
    on the same plant, with the PID and the notch built here, agree on both boundaries."""
    model = resolve(paper_spec)
    plain = achievable_crossover(model)
    assert plain.kind == "margin" and plain.case == "stuck_limited"
    assert plain.criterion == "gain margin"
    notched = achievable_crossover(resolve(variant(paper_spec, **{"controller.filters": [NOTCH]})))
    assert notched.frequency > 2.5 * plain.frequency
    N = _notch(150.0, 75.0)
    below, above = (_control_margins(model, plain.frequency * f) for f in (0.99, 1.01))
    assert _passes(below) and not _passes(above)
    assert above["stuck_limited"]["gm"] < 6.0 <= below["stuck_limited"]["gm"]
    assert _passes(_control_margins(model, plain.frequency * 1.01, N))  # the notch lifts it
    assert _passes(_control_margins(model, notched.frequency * 0.99, N))
    assert not _passes(_control_margins(model, notched.frequency * 1.01, N))


def test_step_2_names_the_tilt_mode_and_what_a_notch_allows(paper_spec):
    xo = step2_crossover(resolve(paper_spec))
    assert xo.limiting_mode == "stage tilt" and xo.limiting_mode_frequency == 150.0
    assert "'stage tilt'" in xo.limited_by and "case 4" in xo.limited_by
    n = xo.notch
    assert n.notch.kind == "notch" and n.notch.frequency == 150.0
    assert n.achievable > 2.5 * xo.achievable
    # the suggestion is the spec with that notch: the same crossover
    spec = variant(paper_spec, **{"controller.filters": [
        {"type": "notch", "frequency": "150 Hz", "width": f"{n.notch.width} Hz"}]})
    assert achievable_crossover(resolve(spec)).frequency == pytest.approx(n.achievable, rel=1e-9)
    check = next(c for c in xo.checks if c.name == "crossover_achievable")
    assert "notch" in check.message and "stage tilt" in check.message


def test_with_a_notch_there_no_second_one_is_suggested(paper_spec):
    """The spec's own notch on the tilt: the crossover rises and no notch is advised again."""
    xo = step2_crossover(resolve(variant(paper_spec, **{"controller.filters": [NOTCH]})))
    assert xo.achievable > 30.0 and xo.notch is None


def test_without_the_mode_no_mode_is_named(paper_spec):
    """A delay limits the rigid loop: no mode is behind it, none is named."""
    spec = variant(paper_spec, isolator=None, **{"controller.delay": "2 ms"})
    xo = step2_crossover(resolve(spec))
    assert xo.limit_kind == "margin" and xo.limiting_mode is None and xo.notch is None


def test_every_crossing_is_reported_with_its_margins(paper_spec):
    """At 8 Hz case 2 (cart stuck, joint free) crosses 0 dB three times; each crossing and
    each -180 deg crossing is found on a dense grid independently, with its margin."""
    model = resolve(paper_spec)
    analysis = linear.analyse(model)
    f = np.geomspace(1e-4, 1e4, 400001)
    s = 2j * math.pi * f
    for case in analysis.cases:
        num, den = linear.loop_polynomials(model, case.name)
        L = np.polyval(num, s) / np.polyval(den, s)
        mag = np.log(np.abs(L))
        where = np.nonzero(np.diff(np.sign(mag)))[0]
        found = [g.frequency for g in case.gain_crossings]
        assert len(found) == len(where), case.name
        for i, g in zip(where, case.gain_crossings):
            assert g.frequency == pytest.approx(f[i], rel=1e-4)
            pm = abs((np.degrees(np.angle(L[i])) + 180.0 + 180.0) % 360.0 - 180.0)
            assert g.phase_margin_deg == pytest.approx(pm, abs=0.05)
        for p in case.phase_crossings:
            j = int(np.argmin(np.abs(f - p.frequency)))
            assert abs(np.angle(L[j], deg=True)) == pytest.approx(180.0, abs=0.1)
            assert p.gain_margin_db == pytest.approx(-20 * np.log10(abs(L[j])), abs=0.01)
    stuck = next(c for c in analysis.cases if c.name == "stuck_free")
    assert len(stuck.gain_crossings) == 3
    assert [g.in_band for g in stuck.gain_crossings] == [False, True, True]
    # the separation is judged on the loop's crossover: case 2's highest crossing, not 8 Hz
    assert analysis.loop_crossover == stuck.gain_crossings[-1].frequency
    assert analysis.loop_crossover_case == "stuck_free"
    check = next(c for c in step2_crossover(model).checks
                 if c.name == "parasitic_separation.stage tilt")
    assert check.limit == pytest.approx(3 * analysis.loop_crossover)


# --------------------------------------------------------------------------- sampled


def _sampled(paper_spec, **more):
    return variant(paper_spec, **{"controller.sample_rate": "4 kHz",
                                  "controller.delay": "250 us",
                                  "controller.filters": [
                                      NOTCH, {"type": "low_pass", "frequency": "600 Hz",
                                              "damping": 0.5},
                                      {"type": "low_pass", "frequency": "900 Hz", "order": 1}]},
                   **more)


def test_the_sampled_controller_is_c2d_of_the_continuous_one(paper_spec):
    """The PID (filtered D) is python-control's Tustin c2d of the continuous PID; each filter
    its Tustin c2d prewarped at its frequency, as drives do."""
    law = resolve(_sampled(paper_spec)).law
    T = law.sample_period
    wf = law.roll_off
    pid = (control.tf([law.kp], [1]) + control.tf([law.ki], [1, 0])
           + control.tf([law.kd * wf, 0], [1, wf]))
    ref = control.c2d(pid, T, "tustin")
    num, den = pid_z(law)
    np.testing.assert_allclose(num / den[0], np.array(ref.num[0][0]) / ref.den[0][0][0],
                               rtol=1e-10)
    np.testing.assert_allclose(den / den[0], np.array(ref.den[0][0]) / ref.den[0][0][0],
                               rtol=1e-10, atol=1e-14)
    for f in law.filters:
        w = 2 * math.pi * f.frequency
        ref = control.c2d(control.tf(*filter_polynomials(f)), T, "tustin", prewarp_frequency=w)
        b, a = tustin_biquad(f, T)
        rn, rd = np.array(ref.num[0][0]), np.array(ref.den[0][0])
        rn = np.concatenate([np.zeros(len(rd) - len(rn)), rn])
        np.testing.assert_allclose(b, rn / rd[0], rtol=1e-10, atol=1e-14)
        np.testing.assert_allclose(a, rd / rd[0], rtol=1e-10, atol=1e-14)
        # prewarped: the sampled filter is the continuous one at its own frequency
        z = np.exp(1j * w * T)
        fn, fd = filter_polynomials(f)
        assert abs(np.polyval(b, z) / np.polyval(a, z)
                   - np.polyval(fn, 1j * w) / np.polyval(fd, 1j * w)) < 1e-9


def test_the_sampled_controller_follows_the_continuous_one_below_a_tenth_of_nyquist(paper_spec):
    """The PID and the notch sampled at 4 kHz: within 1 % of the PID's gain, 0.1 dB and 0.5 deg
    of the continuous controller up to 200 Hz. (A low-pass far above the band, prewarped at its
    own corner, bends the frequency axis below it: 3 deg at 200 Hz for one at 600 Hz.)"""
    law = resolve(variant(paper_spec, **{"controller.sample_rate": "4 kHz",
                                         "controller.filters": [NOTCH]})).law
    d = discrete_controller(law)
    T = law.sample_period
    f = np.geomspace(0.05, 0.1 * 0.5 / T, 600)
    z, s = np.exp(2j * math.pi * f * T), 2j * math.pi * f
    Cd = np.polyval(d.num, z) / np.polyval(d.den, z)
    cn, cd = controller_polynomials(law)
    Cc = np.polyval(cn, s) / np.polyval(cd, s)
    pn, pd = pid_polynomials(law)
    # relative to the PID's gain (the notch's zero makes a relative error of C meaningless)
    assert np.max(np.abs(Cd - Cc) / np.abs(np.polyval(pn, s) / np.polyval(pd, s))) < 0.01
    away = np.abs(f - 150.0) > 30.0  # the ratio of two zeros is no measure at the notch
    assert np.max(np.abs(20 * np.log10(np.abs(Cd[away] / Cc[away])))) < 0.1
    assert np.max(np.abs(np.angle(Cd[away] / Cc[away], deg=True))) < 0.5


def test_an_ideal_derivative_samples_by_the_backward_difference(paper_spec):
    spec = variant(paper_spec, **{"controller.crossover": None, "controller.sample_rate": "2 kHz",
                                  "controller.gains": {"kp": 2000, "ki": 8000, "kd": 80}})
    law = resolve(spec).law
    d = discrete_controller(law)
    T = law.sample_period
    assert (d.derivative_pole, d.derivative_gain, d.integrator_gain) == (0.0, 80 / T, 8000 * T / 2)
    z = np.exp(2j * math.pi * np.array([1.0, 10.0, 100.0]) * T)
    want = 2000 + 8000 * T / 2 * (z + 1) / (z - 1) + 80 * (z - 1) / (T * z)
    np.testing.assert_allclose(np.polyval(d.num, z) / np.polyval(d.den, z), want, rtol=1e-10)


def test_gains_in_the_drive_s_units(paper_spec):
    """One count of error makes kp q newtons, that is kp q / (Kf c) units of current command."""
    spec = _sampled(paper_spec, **{"controller.drive": {
        "motor_constant": "20 N/A", "encoder_resolution": "0.5 um", "current_scaling": "1 mA"}})
    result = design(spec, confirm=False)
    law, units = result.pid.controller, result.pid.drive_gains
    per_count = 0.5e-6 / (20 * 1e-3)
    assert units.kp == pytest.approx(law.kp * per_count)
    assert units.ki == pytest.approx(law.ki * per_count)
    assert units.kd == pytest.approx(law.kd * per_count)
    assert units.integrator_gain == pytest.approx(result.pid.discrete.integrator_gain * per_count)
    assert units.units["kp"] == "unit/count" and "0.001 A" in units.current_unit
    d = result.to_dict()["pid"]["drive"]
    assert d["in_drive_units"]["kp"] == pytest.approx(units.kp)
    assert d["discrete"]["sample_rate"] == 4000.0 and len(d["discrete"]["filters"]) == 3
    assert [f["frequency"] for f in d["filters"]] == [150.0, 600.0, 900.0]
    assert d["filters"][0]["width"] == pytest.approx(75.0)


# --------------------------------------------------------------------------- plots


@pytest.mark.parametrize("more", [{}, {"controller.sample_rate": "1 kHz",
                                      "controller.delay": "250 us"}])
def test_the_drawn_sensitivity_peak_is_the_table_s(paper_spec, more):
    from fi_design import plots

    result = design(variant(paper_spec, **more), confirm=False)
    fig = plots.sensitivity_figure(result)
    ax = fig.axes[0]
    lines = [ln for ln in ax.lines if str(ln.get_label()).startswith("case ")]
    assert len(lines) == len(result.crossover.cases)
    for line, case in zip(lines, result.crossover.cases):
        drawn = float(np.max(line.get_ydata()))
        assert drawn == pytest.approx(-20 * math.log10(case.modulus_margin), abs=0.1)
    if more:  # a 1 kHz loop is drawn up to its 500 Hz Nyquist frequency, no further
        assert result.loop.frequency[-1] == pytest.approx(result.loop.nyquist) == 500.0


def test_the_nyquist_curves_are_smooth(paper_spec):
    """Near the critical point no case's curve jumps: neighbouring points lie close."""
    result = design(_sampled(paper_spec), confirm=False)
    for case in result.loop.cases:
        L = case.loop
        near = np.minimum(np.abs(L[:-1]), np.abs(L[1:])) < 4.0
        assert np.max(np.abs(np.diff(L))[near]) < 0.031


# --------------------------------------------------------------------------- the kernel


KERNEL_FILTERS = [NOTCH, {"type": "low_pass", "frequency": "600 Hz", "damping": 0.5},
                  {"type": "low_pass", "frequency": "900 Hz", "order": 1}]
INDEPENDENT_FILTERS = [dict(type="notch", frequency=150.0, width=75.0),
                       dict(type="low_pass", frequency=600.0, damping=0.5),
                       dict(type="low_pass", frequency=900.0, order=1)]


@pytest.mark.parametrize("more, controller", [
    ({}, {}),
    ({"controller.sample_rate": "4 kHz"}, {"sample_rate": 4000.0}),
    ({"controller.delay": "1 ms"}, {"delay": 1e-3}),
], ids=["continuous", "sampled", "delayed"])
def test_the_kernel_carries_the_filters_as_the_independent_simulator_does(paper_spec, more,
                                                                          controller):
    """The paper setup's 10 mm move with a notch and two low-passes: the kernel (the filters
    as states, or as the drive's biquads) against tests/independent.py (the same filters
    transcribed from their definitions, scipy's Radau); the filters move the stage by 17 um
    and more, the two agree to 2 nm in position and 0.1 mN in force. The first second holds
    the move, the cart's stick at 0.3 s, the joint's six limiter contacts and the largest
    differences and effects of the filters: the 3 s run cost three times as much (the
    independent simulator restarts at every sample or delay) and found the same maxima."""
    from independent import generate

    from fi_design.simulation.run import simulate

    spec = variant(paper_spec, **{"controller.filters": KERNEL_FILTERS}, **more)
    run = simulate(spec, isolated=True, duration=1.0)
    plain = simulate(variant(paper_spec, **more), isolated=True, duration=1.0)
    rec = generate(1.6, 0.4, friction=dict(Fs=4.0, Fc=1.0, vs=3e-3, sigma0=1e6, sigma1=1414.0,
                                           sigma2=20.0),
                   isolator=dict(k=6667.0, s=0.3e-3, c=4.62),
                   controller=dict(rule=dict(fc=8.0), filters=INDEPENDENT_FILTERS, **controller),
                   moves=[dict(distance=10e-3, velocity=50e-3, acceleration=1.0)], t_end=1.0,
                   rate=1000.0)
    assert run.success and len(run.position) == len(rec.truth.x1)
    assert rec.info["events"] >= 6  # into and out of the limiter, three times (as in 3 s)
    assert np.max(np.abs(run.position - plain.position)) > 1.5e-5  # the filters matter ...
    assert np.max(np.abs(run.position - rec.truth.x1)) < 2e-9     # ... and agree
    assert np.max(np.abs(run.force - rec.truth.command)) < 1e-4


def test_a_filter_written_as_a_spec_entry_reads_back_the_same(paper_spec):
    """Filter.spec_entry (what --write-spec and the recommendation's notch write) gives the
    chain the spec had: frequency, width and depth of a notch, order and damping of a
    low-pass."""
    chain = [dict(NOTCH, depth="20 dB"),
             {"type": "low_pass", "name": "lp2", "frequency": "400 Hz", "order": 2,
              "damping": 0.5},
             {"type": "low_pass", "name": "lp1", "frequency": "600 Hz", "order": 1}]
    law = resolve(variant(paper_spec, **{"controller.filters": chain})).law
    again = resolve(variant(paper_spec, **{"controller.filters": [f.spec_entry()
                                                                   for f in law.filters]})).law
    assert len(again.filters) == 3
    for a, b in zip(law.filters, again.filters):
        assert (a.kind, a.name, a.order) == (b.kind, b.name, b.order)
        assert (b.frequency, b.zeta_pole, b.zeta_zero) == pytest.approx(
            (a.frequency, a.zeta_pole, a.zeta_zero), rel=1e-5)
