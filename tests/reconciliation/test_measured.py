"""Measured-data files (docs/interfaces.md): good layouts load, bad ones name column and row."""

from __future__ import annotations

import numpy as np
import pytest

from fi_design.errors import DataError
from fi_design.measured import load_measurement, measurement_from_arrays, to_csv_text

HEADER = "time_s,reference_m,position_m,force_N,deflection_m"


def _rows(n=30, dt=1e-3):
    return [f"{i * dt:.6f},{1e-4 * i:.6e},{1e-4 * i + 1e-7:.6e},{0.1 * i:.4f},{1e-6:.3e}"
            for i in range(n)]


def _write(tmp_path, text, name="trace.csv"):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_good_file_loads(tmp_path):
    m = load_measurement(_write(tmp_path, HEADER + "\n" + "\n".join(_rows()) + "\n"))
    assert m.n == 30 and m.uniform
    assert m.columns == ("time_s", "reference_m", "position_m", "force_N", "deflection_m")
    assert m.force[3] == pytest.approx(0.3)
    assert not m.time.flags.writeable


def test_columns_by_header_any_order_extra_and_comments(tmp_path):
    lines = ["# recorded on stage 42", "# sample rate 1 kHz",
             "Position_m,temperature_C,time_s,reference_m"]
    lines += [f"{1e-5 * i},{21.5},{i * 1e-3},{1e-5 * i}" for i in range(25)]
    m = load_measurement(_write(tmp_path, "\n".join(lines) + "\n"))
    assert m.columns == ("time_s", "reference_m", "position_m")
    assert m.force is None and m.deflection is None
    assert m.position[5] == pytest.approx(5e-5)


def test_non_uniform_sampling_accepted(tmp_path):
    t = np.cumsum(np.r_[0.0, np.random.default_rng(0).uniform(0.5e-3, 1.5e-3, 40)])
    lines = [HEADER.rsplit(",", 2)[0]] + [f"{x:.9f},0,0" for x in t]
    m = load_measurement(_write(tmp_path, "\n".join(lines)))
    assert not m.uniform and m.n == 41


def test_round_trip_through_csv_text(tmp_path):
    m = measurement_from_arrays(np.arange(25) * 1e-3, np.zeros(25), np.linspace(0, 1e-3, 25),
                                force_N=np.ones(25))
    again = load_measurement(_write(tmp_path, to_csv_text(m, comment="two\nlines")))
    assert np.allclose(again.position, m.position) and again.columns == m.columns


@pytest.mark.parametrize("text,column,row,words", [
    ("", None, None, "empty file"),
    ("# only a comment\n", None, None, "empty file"),
    (HEADER + "\n", None, None, "no data rows"),
    ("time_s,position_m\n" + "\n".join(f"{i},0" for i in range(30)), "reference_m", None,
     "missing"),
    ("time_s,reference_m,position_m,position_m\n" + "\n".join(f"{i},0,0,0" for i in range(30)),
     "position_m", None, "duplicate"),
    ("time_ms,reference_m,position_m\n" + "\n".join(f"{i},0,0" for i in range(30)), "time_ms",
     None, "unit 'ms'"),
    ("time_s,reference_m,position_mm\n" + "\n".join(f"{i},0,0" for i in range(30)), "position_mm",
     None, "unit 'mm'"),
    (HEADER + "\n" + "\n".join(_rows()[:5] + ["0.005,1e-4,nan,0,0"] + _rows()[6:]),
     "position_m", 6, "not a finite number"),
    (HEADER + "\n" + "\n".join(_rows()[:7] + ["0.007,1e-4,,0,0"] + _rows()[8:]),
     "position_m", 8, "empty cell"),
    (HEADER + "\n" + "\n".join(_rows()[:2] + ["0.002,0.2 mm,0,0,0"] + _rows()[3:]),
     "reference_m", 3, "carries a unit"),
    (HEADER + "\n" + "\n".join(_rows()[:2] + ["0.002,abc,0,0,0"] + _rows()[3:]),
     "reference_m", 3, "not a number"),
    (HEADER + "\n" + "\n".join(_rows()[:10] + ["0.005,0,0,0,0"] + _rows()[11:]), "time_s", 11,
     "does not increase"),
    (HEADER + "\n" + "\n".join(_rows()[:4] + ["0.004,0,0"] + _rows()[5:]), None, 5, "field"),
    (HEADER + "\n" + "\n".join(_rows(10)), "time_s", None, "too short"),
    (HEADER + "\n" + "\n".join(_rows()[:3] + ["0.003,15.0,0,0,0"] + _rows()[4:]), "reference_m", 4,
     "implausibly large"),
])
def test_bad_files_name_column_and_row(tmp_path, text, column, row, words):
    with pytest.raises(DataError) as info:
        load_measurement(_write(tmp_path, text))
    err = info.value
    assert words in str(err)
    assert err.column == column
    assert err.row == row
    if column:
        assert column in str(err)
    if row is not None:
        assert f"row {row}" in str(err)
    assert "trace.csv" in str(err)


@pytest.mark.parametrize("cell,words", [
    ("nan", "value nan is not a finite number"), ("-inf", "value -inf is not a finite number"),
    ("0x10", "value '0x10' is not a number"), ("1e3x", "value '1e3x' carries a unit"),
    ("2 m/s^2", "value '2 m/s^2' carries a unit"),
])
def test_a_bad_cell_is_said_in_plain_words(tmp_path, cell, words):
    """Numpy's repr (np.float64(nan)) and a hexadecimal number read as "carries a unit" were
    the messages."""
    lines = [HEADER] + _rows()[:4] + [f"0.004,{cell},0,0,0"] + _rows()[5:]
    with pytest.raises(DataError) as err:
        load_measurement(_write(tmp_path, "\n".join(lines) + "\n"))
    assert words in str(err.value) and "np." not in str(err.value), str(err.value)
    assert err.value.column == "reference_m" and err.value.row == 5
    if cell in ("nan", "-inf"):  # arrays are checked alike
        with pytest.raises(DataError, match=f"value {cell} is not"):
            reference = np.r_[np.zeros(4), float(cell), np.zeros(25)]
            measurement_from_arrays(np.arange(30) * 1e-3, reference, np.zeros(30))


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(DataError, match="no such file"):
        load_measurement(tmp_path / "nope.csv")
    with pytest.raises(DataError, match="directory"):
        load_measurement(tmp_path)


def test_binary_file(tmp_path):
    p = tmp_path / "trace.csv"
    p.write_bytes(b"\xff\xfe\x00\x81" * 10)
    with pytest.raises(DataError, match="not a text file"):
        load_measurement(p)


def test_arrays_checked_like_files():
    t = np.arange(30) * 1e-3
    with pytest.raises(DataError) as info:
        measurement_from_arrays(t, np.zeros(30), np.zeros(29))
    assert info.value.column == "position_m"
    bad = np.zeros(30)
    bad[7] = np.inf
    with pytest.raises(DataError) as info:
        measurement_from_arrays(t, np.zeros(30), np.zeros(30), force_N=bad)
    assert (info.value.column, info.value.row) == ("force_N", 8)


def test_disturbance_column_loads_and_round_trips(tmp_path):
    lines = [HEADER + ",disturbance_N"] + [r + f",{0.5 if 10 <= i < 15 else 0.0}"
                                           for i, r in enumerate(_rows())]
    m = load_measurement(_write(tmp_path, "\n".join(lines) + "\n"))
    assert m.columns[-1] == "disturbance_N"
    assert m.disturbance[12] == 0.5 and m.disturbance[0] == 0.0
    again = load_measurement(_write(tmp_path, to_csv_text(m), name="again.csv"))
    assert np.array_equal(again.disturbance, m.disturbance)


def test_disturbance_nan_names_column_and_row(tmp_path):
    lines = [HEADER + ",disturbance_N"] + [r + (",nan" if i == 6 else ",0")
                                           for i, r in enumerate(_rows())]
    with pytest.raises(DataError) as err:
        load_measurement(_write(tmp_path, "\n".join(lines) + "\n"))
    assert err.value.column == "disturbance_N" and err.value.row == 7


def test_disturbance_with_other_unit_refused(tmp_path):
    lines = [HEADER + ",disturbance_kN"] + [r + ",0" for r in _rows()]
    with pytest.raises(DataError, match="disturbance_N"):
        load_measurement(_write(tmp_path, "\n".join(lines) + "\n"))


def test_emps_record_loads_as_documented(emps_record):
    """The real EMPS record: 24,841 rows at 1 kHz, starting in motion, in whole encoder counts."""
    m = emps_record
    assert m.n == 24841 and m.uniform and m.sample_period == pytest.approx(1e-3)
    counts = m.position / 5e-8
    assert np.max(np.abs(counts - np.round(counts))) < 1e-6
    r0 = (m.reference[1] - m.reference[0]) / (m.time[1] - m.time[0])
    v0 = (m.position[5] - m.position[0]) / (m.time[5] - m.time[0])
    assert r0 == pytest.approx(13.4e-3, rel=0.05) and v0 > 5e-3   # it starts in motion


def test_a_text_column_beside_the_numbers_is_ignored(tmp_path):
    """Numbers are read at numpy's speed; a file numpy refuses (a column of words) is read
    cell by cell instead, with the same result."""
    lines = ["time_s,reference_m,position_m,note"]
    lines += [f"{i * 1e-3},{1e-5 * i},{1e-5 * i},run {i} ok" for i in range(25)]
    m = load_measurement(_write(tmp_path, "\n".join(lines) + "\n"))
    assert m.n == 25 and m.columns == ("time_s", "reference_m", "position_m")
    assert m.position[7] == pytest.approx(7e-5)


def test_thinned_keeps_every_nth_sample_as_recorded():
    from fi_design.measured import thinned

    m = measurement_from_arrays(np.arange(100) * 1e-4, np.zeros(100), np.arange(100) * 1e-6,
                                force_N=np.ones(100))
    t = thinned(m, 10)
    assert t.n == 10 and t.columns == m.columns
    assert np.array_equal(t.position, m.position[::10]) and t.time[1] == pytest.approx(1e-3)
    assert thinned(m, 1) is m


def test_columns_are_written_a_chunk_at_a_time(monkeypatch):
    """A record of millions of rows is written in chunks, not held as one string: same text."""
    import io

    import fi_design.measured as measured

    cols = {"time_s": np.arange(10) * 1e-3, "position_m": np.linspace(0, 1e-3, 10)}
    whole = measured.columns_csv(cols, comment="c")
    monkeypatch.setattr(measured, "CHUNK_ROWS", 3)
    out = io.StringIO()
    measured.write_columns_csv(out, cols, comment="c")
    assert out.getvalue() == whole and whole.count("\n") == 12


@pytest.mark.parametrize("raw, words", [
    # a Latin-1 micro sign in a comment: it read "not a text file", no line
    (b"# x in \xb5m\ntime_s,reference_m,position_m\n0,0,0\n", ["line 1", "0xb5", "UTF-8"]),
    # spaces between the columns: it read "unit 's reference_m position_m' is not accepted"
    (b"time_s reference_m position_m\n0 0 0\n", ["one field", "separated by spaces"]),
    # a decimal comma beside ';': it read "value '0,001' is not a number"
    (b"time_s;reference_m;position_m\n0,001;0;0\n", ["decimal comma", "'0.001'", "row 1"]),
], ids=["latin-1", "spaces", "decimal-comma"])
def test_a_csv_in_a_neighbouring_format_says_what_to_change(tmp_path, raw, words):
    p = tmp_path / "trace.csv"
    p.write_bytes(raw)
    with pytest.raises(DataError) as e:
        load_measurement(p)
    for w in words:
        assert w in str(e.value), str(e.value)


@pytest.mark.parametrize("header, words", [
    # it read "required column is missing" with no word on time_s
    ("time [s],reference [m],position [m]",
     ["column 'time [s]'", "give the column as 'time_s'", "without '[s]'"]),
    ("time_s [s],reference_m,position_m", ["give the column as 'time_s'", "without '[s]'"]),
    ("Time (s),reference_m,position_m", ["give the column as 'time_s'", "without '(s)'"]),
    ("time_s,reference_m,position [mm]", ["unit 'mm' is not accepted", "'position_m' in m"]),
    # it read "unit 'm' is not accepted": the unit is right, the name is not the layout's
    ("time_s,reference_m,pos_m", ["column 'pos_m'", "not a column name of the layout",
                                  "give the column as 'position_m'"]),
], ids=["time-brackets", "name-and-brackets", "parentheses", "unit-in-brackets", "pos_m"])
def test_a_header_in_a_neighbouring_layout_names_the_column_to_give(tmp_path, header, words):
    rows = [f"{i * 1e-3:.3f},0,0" for i in range(30)]
    with pytest.raises(DataError) as e:
        load_measurement(_write(tmp_path, "\n".join([header, *rows]) + "\n"))
    for w in words:
        assert w in str(e.value), str(e.value)
    assert "is not accepted" not in str(e.value) or "mm" in str(e.value), str(e.value)


@pytest.mark.parametrize("comment", ["# paused here", "# paused, here, at 0.01 s, 3"])
def test_a_comment_after_the_header_says_comments_come_before_it(tmp_path, comment):
    """A '#' line among the data read "row 11: has 1 field(s), the header has 5" (or, with
    as many commas as the header, "value '# paused' is not a number")."""
    rows = _rows()
    text = "\n".join([HEADER, *rows[:10], comment, *rows[10:]]) + "\n"
    with pytest.raises(DataError) as e:
        load_measurement(_write(tmp_path, text))
    assert e.value.row == 11
    assert "comment line after the header" in str(e.value)
    assert "only before the header row" in str(e.value)


def _moving(n=2000, dt=1e-3):
    """A record of a smooth back-and-forth move (20 mm, 1 Hz) with 0.1 µm noise."""
    t = np.arange(n) * dt
    r = 0.01 * (1.0 - np.cos(2.0 * np.pi * t))
    x = r + 1e-7 * np.random.default_rng(3).standard_normal(n)
    return t, r, x


def test_a_position_jump_is_refused_naming_the_row_step_and_speed():
    """An encoder wrap (the position 50 mm off from one row on) or a glitch of one sample was
    replayed and identified as if the stage had moved: identify read the EMPS record with
    such a wrap as 0.43 kg with 61 % of the force unexplained, blaming "a force the model
    lacks". The step is refused with its rows, size and speed."""
    from fi_design.measured import check_position_steps

    t, r, x = _moving()
    check_position_steps(measurement_from_arrays(t, r, x))
    wrapped = x + np.where(np.arange(len(t)) > 1200, 0.05, 0.0)
    with pytest.raises(DataError) as e:
        check_position_steps(measurement_from_arrays(t, r, wrapped, source="wrap.csv"))
    text = " ".join(str(e.value).split())
    assert (e.value.column, e.value.row) == ("position_m", 1202)
    assert "wrap.csv" in text and "between row 1201 (1.2 s) and row 1202 (1.201 s)" in text
    assert "steps by 50.06 mm" in text and "a speed of 50060 mm/s" in text, text
    assert "x the fastest the record moves otherwise (62.9 mm/s)" in text, text
    glitch = x.copy()
    glitch[700] += 2e-3  # one sample 2 mm off, back at the next
    with pytest.raises(DataError) as e:
        check_position_steps(measurement_from_arrays(t, r, glitch))
    assert e.value.row == 701


def test_real_and_example_records_have_no_position_jump(emps_record):
    """No false alarm on the records at hand: the real EMPS axis (quantized to 0.05 µm, always
    moving), the example trace (noisy, at rest between moves) and a quantized hold, whose
    rare one-count steps are the record's own motion; a stage that follows a step of its
    reference steps with it."""
    from conftest import EXAMPLES

    from fi_design.measured import check_position_steps

    check_position_steps(emps_record)
    check_position_steps(load_measurement(EXAMPLES / "measured_trace.csv"))
    t = np.arange(1000) * 1e-3
    hold = np.where(t > 0.5, 1e-6, 0.0)  # one encoder count, once
    check_position_steps(measurement_from_arrays(t, np.zeros_like(t), hold))
    step = np.where(t > 0.5, 1e-3, 0.0)  # a 1 mm step reference, followed within a sample
    check_position_steps(measurement_from_arrays(t, step, step))


#: Encoder count of the hunting record [m].
COUNT = 1e-6


@pytest.fixture(scope="module")
def hunting_record():
    """A stick-slip limit cycle recorded by a 1 um encoder at 1 kHz, simulated apart from the
    package: the paper's stage without its isolator (2 kg, LuGre) under its rule PID at 8 Hz
    (tests/independent.py, solve_ivp), a 1 mm move, then 2 s of hunting: long stops that
    creep by one count now and then, and breakaways into slips of about 100 samples. The
    controller sees the true position (its reading the encoder, a solve_ivp start at every
    count or sample, costs seconds: the slow test below). At rtol 1e-5 every count is the
    one of generate's 1e-8 (the position within 5 nm), in 0.3 s of CPU instead of 1.5 s."""
    return _hunting(dict(rule=dict(fc=8.0)))


def _hunting(controller, **options):
    from independent import generate

    friction = dict(Fs=4.0, Fc=1.0, vs=3e-3, sigma0=1e6, sigma1=1414.0, sigma2=20.0)
    return generate(2.0, 0.0, friction=friction, controller=controller,
                    moves=[dict(distance=1e-3, velocity=0.05, acceleration=1.0)], t_end=2.0,
                    rate=1000.0, position_resolution=COUNT, rtol=1e-5, **options)


def _runs(moving):
    """(start, length) of each run of True in ``moving``."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], moving.astype(int), [0]))))
    return [(int(a), int(b - a)) for a, b in zip(edges[::2], edges[1::2])]


def test_a_quantized_hunting_record_of_an_independent_solver_has_no_position_jump(
        hunting_record):
    """No false alarm on a record the package did not make: a stage at rest on whole counts
    (a speed of zero, then one count in one sample) that breaks away into a slip, the
    jump detector's hardest case, passes the check and the replay's."""
    from fi_design.measured import check_position_steps
    from fi_design.simulation.replay import check_record

    rec = hunting_record
    counts = np.round(rec.position / COUNT)
    assert np.allclose(rec.position / COUNT, counts, rtol=0.0, atol=1e-6)  # whole counts
    steps = np.abs(np.diff(counts))
    slips = [(a, n) for a, n in _runs(steps > 0) if n >= 20 and rec.time[a] > 0.5]
    assert len(slips) >= 2, slips  # it hunts: breakaways after the move
    assert np.count_nonzero(steps == 0) > 0.7 * len(steps)  # and sticks most of the time
    assert np.count_nonzero(steps == 1) > 20  # creeping by one count at rest
    m = rec.measurement()
    check_position_steps(m)
    check_record(m, crossover=8.0)


@pytest.mark.slow
def test_a_hunting_record_of_a_sampled_loop_reading_the_encoder_has_no_position_jump():
    """The hunting record's loop sampled at 1 kHz and reading the 1 um encoder (the
    quantization effect) hunts alike and passes alike (about 3 s: 2000 solve_ivp starts)."""
    from fi_design.measured import check_position_steps
    from fi_design.simulation.replay import check_record

    rec = _hunting(dict(rule=dict(fc=8.0), sample_rate=1000.0),
                   effects={"quantization": {"resolution": COUNT}})
    steps = np.abs(np.diff(np.round(rec.position / COUNT)))
    assert len([a for a, n in _runs(steps > 0) if n >= 20 and rec.time[a] > 0.5]) >= 2
    m = rec.measurement()
    check_position_steps(m)
    check_record(m, crossover=8.0)


def test_a_wrap_in_a_quantized_hunting_record_is_refused(hunting_record):
    """The same record with a 16-bit counter's wrap (2^16 counts) in the middle of its last
    slip, where the stage moves fastest, is refused at that row, by the replay's check too."""
    from fi_design.measured import check_position_steps
    from fi_design.simulation.replay import check_record

    rec = hunting_record
    steps = np.abs(np.diff(rec.position))
    slip = np.flatnonzero(rec.time[1:] > 1.5)
    j = int(slip[np.argmax(steps[slip])]) + 1  # the sample after the slip's largest step
    assert steps[j - 1] > 10 * COUNT  # moving fast there
    wrapped = rec.position + np.where(np.arange(rec.time.size) >= j, 2 ** 16 * COUNT, 0.0)
    for check in (check_position_steps, lambda m: check_record(m, crossover=8.0)):
        m = measurement_from_arrays(rec.time, rec.reference, wrapped, force_N=rec.force)
        with pytest.raises(DataError, match="a jump of the position") as e:
            check(m)
        assert (e.value.column, e.value.row) == ("position_m", j + 1)


def test_a_gap_in_the_time_is_told_from_jitter():
    """The check identify refuses non-uniform sampling with is the one replays refuse a gap
    with: a step of 5 median steps or more, longer than what the caller accepts."""
    from fi_design.measured import check_time_steps

    t, r, x = _moving()
    gap = np.where(np.arange(len(t)) >= 1000, t + 0.5, t)
    m = measurement_from_arrays(gap, r, x, source="gap.csv")
    with pytest.raises(DataError) as e:
        check_time_steps(m, longest=0.0625, needs="the replay cannot take it", parts="do so")
    text = " ".join(str(e.value).split())
    assert (e.value.column, e.value.row) == ("time_s", 1001)
    assert ("a gap in the record: no sample for 0.501 s between row 1000 (0.999 s) and row 1001 "
            "(1.5 s), 501 x the median step (0.001 s)") in text, text
    assert "split the record at row 1001" in text and "do not interpolate" in text
    check_time_steps(m, longest=1.0, needs="-", parts="-")  # shorter than what is accepted
    jitter = t + np.where(np.arange(len(t)) % 7 == 3, 4e-4, 0.0)
    m = measurement_from_arrays(jitter, r, x)
    check_time_steps(m, longest=0.0, needs="-", parts="-")  # any sampling but a gap
    with pytest.raises(DataError, match="non-uniform sampling: .* resample"):
        check_time_steps(m, jitter=0.01, needs="uniform samples needed", parts="-")
