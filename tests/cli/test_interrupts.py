"""Interrupts: never lost, never turned into another error, never cutting a held step in two.

Each case reproduces in one process a window an adversarial run found by sending SIGINT to
`fi-design sweep` at random instants (the same, at many instants, is in tests/cli/test_pools.py).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

import pytest
from typer.testing import CliRunner

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX signals")

runner = CliRunner()


@pytest.fixture(autouse=True)
def _found_as_a_process_starts():
    """These tests take the process's signal handling as a process starts with it (the
    default Ctrl-C handler, no block of fi_design.interrupts open); one that finds it
    otherwise says what an earlier test or fixture of this process left behind, rather than
    failing as if the code under test had (twice in one loaded run: DID NOT RAISE)."""
    from fi_design.interrupts import _STATE

    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler, \
        f"SIGINT's handler found as {signal.getsignal(signal.SIGINT)!r}"
    assert (_STATE.make, _STATE.depth, _STATE.pending, _STATE.received) == (None, 0, [], []), \
        f"fi_design.interrupts found with a block open: {vars(_STATE)!r}"
    yield


def _sigint_here() -> None:
    """Ctrl-C to this process; its handler runs at the next bytecode of the main thread."""
    os.kill(os.getpid(), signal.SIGINT)
    for _ in range(1000):  # a C-level handler only trips a flag: give it a bytecode to run at
        pass


class _Finalizer:
    """An object whose finalizer runs when Ctrl-C's handler does: Python prints the
    KeyboardInterrupt raised inside it ("Exception ignored in ...") and carries on."""

    def __del__(self) -> None:
        _sigint_here()


# the finalizer's KeyboardInterrupt is printed and dropped: the very thing under test
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_an_interrupt_swallowed_by_a_finalizer_still_stops_the_run(paper_spec_path, tmp_path,
                                                                  monkeypatch):
    """The run went on to its end, wrote its output and exited 0."""
    import fi_design.simulation.run as simulation

    real = simulation.simulate

    def simulate(*args, **kwargs):
        _Finalizer()  # collected at once: Ctrl-C lands inside its finalizer
        return real(*args, **kwargs)

    monkeypatch.setattr(simulation, "simulate", simulate)
    _stopped_before_its_output(paper_spec_path, tmp_path)


def _stopped_before_its_output(paper_spec_path, tmp_path) -> None:
    """`fi-design simulate --json` ends with 130, the interruption's message and no file."""
    out = tmp_path / "out.json"
    result = runner.invoke(app(), ["simulate", str(paper_spec_path), "--json", str(out)])
    assert result.exit_code == 130, result.output
    assert "interrupted; no output was written" in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_an_interrupt_swallowed_while_the_arguments_are_parsed_stops_the_command(
        paper_spec_path, tmp_path, monkeypatch):
    """A Ctrl-C 0.2 s into a sweep was raised inside importlib's weakref callback while the
    command line was built: dropped, and the command's own block began with no signal
    received, so the sweep ran to its end, wrote map.csv and exited 0."""
    from fi_design.cli.parts import DefaultCommandGroup

    real = DefaultCommandGroup.parse_args

    def parse_args(self, ctx, args):
        _Finalizer()  # collected at once: Ctrl-C lands inside its finalizer
        return real(self, ctx, args)

    monkeypatch.setattr(DefaultCommandGroup, "parse_args", parse_args)
    _stopped_before_its_output(paper_spec_path, tmp_path)


def test_a_signal_swallowed_before_a_successful_exit_is_raised():
    """A block that ends by sys.exit(0) (click's end of a command line) after a swallowed
    signal ended the run with exit 0."""
    from fi_design.interrupts import signals_to_exceptions

    with pytest.raises(KeyboardInterrupt):
        with signals_to_exceptions(lambda signum: KeyboardInterrupt()):
            try:
                _sigint_here()
            except KeyboardInterrupt:
                pass  # swallowed, as a finalizer or a C callback does
            raise SystemExit(0)
    with pytest.raises(SystemExit):  # an exit with its own code is left alone
        with signals_to_exceptions(lambda signum: KeyboardInterrupt()):
            try:
                _sigint_here()
            except KeyboardInterrupt:
                pass
            raise SystemExit(3)


def test_an_error_raised_by_an_interruption_is_the_interruption(paper_spec_path, tmp_path,
                                                               monkeypatch):
    """Ctrl-C inside the import of a compiled module is `ImportError: initialization failed`
    (pybind11 modules), and stopping an interrupted pool met `OSError: [Errno 9] Bad file
    descriptor`: both were reported as internal errors (exit 1) instead of the interruption."""
    import errno

    import fi_design.simulation.run as simulation

    for error in (ImportError("initialization failed"),
                  OSError(errno.EBADF, "Bad file descriptor")):
        def simulate(*args, error=error, **kwargs):
            try:
                raise KeyboardInterrupt
            except KeyboardInterrupt:
                raise error  # noqa: B904 -- raised while handling it, as the libraries do

        monkeypatch.setattr(simulation, "simulate", simulate)
        out = tmp_path / "out.json"
        result = runner.invoke(app(), ["simulate", str(paper_spec_path), "--json", str(out)])
        assert result.exit_code == 130, result.output
        assert "interrupted; no output was written" in result.stderr
        assert "internal error" not in result.stderr and not out.exists()


def test_an_interrupt_outside_a_study_says_so(paper_spec_path, tmp_path, monkeypatch):
    """typer turned a KeyboardInterrupt into a silent exit 130; the CLI says what was written."""
    import fi_design.simulation.run as simulation

    def simulate(*args, **kwargs):
        _sigint_here()
        raise AssertionError("Ctrl-C did not stop the run")

    monkeypatch.setattr(simulation, "simulate", simulate)
    result = runner.invoke(app(), ["simulate", str(paper_spec_path)])
    assert result.exit_code == 130, result.output
    assert "interrupted; no output was written and no temporary file is left" in result.stderr


@pytest.mark.parametrize("command_line", [True, False])
def test_an_interrupt_delivered_to_another_thread_leaves_no_temporary_file(tmp_path,
                                                                           monkeypatch,
                                                                           command_line):
    """The main thread held the signals by its mask while it made the temporary file; the
    kernel then delivered Ctrl-C to another thread (a pool's manager thread, a progress
    bar), whose handler raised in the main thread anyway, before the file was known to the
    cleanup: `.out.json.XXXX.tmp` stayed behind."""
    import tempfile

    from fi_design import output

    stop = threading.Event()
    other = threading.Thread(target=stop.wait, daemon=True)
    other.start()
    real = tempfile.mkstemp

    def mkstemp(*args, **kwargs):
        made = real(*args, **kwargs)
        signal.pthread_kill(other.ident, signal.SIGINT)
        # the other thread runs the C handler when it is scheduled (late on a loaded
        # machine); the main thread raises at its next check, inside this loop
        deadline = time.monotonic() + 1.0
        while time.monotonic() < deadline:
            time.sleep(0.001)
        return made

    monkeypatch.setattr(output.tempfile, "mkstemp", mkstemp)
    out = tmp_path / "out.json"
    try:
        with pytest.raises(KeyboardInterrupt):
            if command_line:
                from fi_design.cli.parts import _signal_exception
                from fi_design.interrupts import signals_to_exceptions

                with signals_to_exceptions(_signal_exception):
                    output.write_atomic(out, "{}")
            else:
                output.write_atomic(out, "{}")
    finally:
        stop.set()
    assert list(tmp_path.iterdir()) == []


def test_a_held_block_gets_its_signal_at_the_end():
    from fi_design.cli.parts import Terminated, _signal_exception
    from fi_design.interrupts import held, received, signals_to_exceptions

    steps = []
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Terminated) as err:
        with signals_to_exceptions(_signal_exception):
            with held():
                os.kill(os.getpid(), signal.SIGTERM)
                for _ in range(1000):
                    pass
                steps.append("the block ran on")
                assert received() == (signal.SIGTERM,)
    assert steps == ["the block ran on"] and err.value.signum == signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) is before  # restored
    assert received() == ()


def app():
    from fi_design.cli.app import app as the_app

    return the_app


def test_an_interrupt_between_two_outputs_names_the_one_written(paper_spec_path, tmp_path,
                                                                 monkeypatch):
    from fi_design import output

    real = output.write_atomic

    def write_atomic(path, data):
        _sigint_here()
        return real(path, data)

    monkeypatch.setattr(output, "write_atomic", write_atomic)
    csv, js = tmp_path / "trace.csv", tmp_path / "out.json"
    result = runner.invoke(app(), ["simulate", str(paper_spec_path), "--csv", str(csv),
                                   "--json", str(js)])
    assert result.exit_code == 130, result.output
    assert f"interrupted; it had written {csv} and no temporary file is left" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["trace.csv"]


def test_a_signal_while_held_swaps_its_handlers_leaves_none_of_them_behind(monkeypatch):
    """Outside the command line, held() swapped SIGINT's handler for a recording one, then
    SIGTERM's; an interruption between the two (here: the second swap raises) left the
    recording handler installed for good, and every later Ctrl-C of the process was
    recorded into a list nobody reads instead of stopping it."""
    from fi_design.interrupts import held

    before = signal.getsignal(signal.SIGINT)
    real = signal.signal
    raised = []

    def swap(signum, handler):
        if signum == signal.SIGTERM and not raised:
            raised.append(signum)
            raise KeyboardInterrupt  # Ctrl-C's exception at that very bytecode
        return real(signum, handler)

    monkeypatch.setattr(signal, "signal", swap)
    with pytest.raises(KeyboardInterrupt):
        with held():
            raise AssertionError("the block ran although held() did not start")
    monkeypatch.undo()
    assert raised == [signal.SIGTERM]
    assert signal.getsignal(signal.SIGINT) is before


@pytest.mark.parametrize("command_line", [True, False])
def test_a_ctrl_c_as_the_handlers_are_restored_leaves_none_of_the_others_swapped(monkeypatch,
                                                                               command_line):
    """Both blocks restored SIGINT's handler first: a Ctrl-C right after it raised there, and
    SIGTERM's and SIGHUP's swapped handlers stayed installed (held()'s recording one took a
    later SIGTERM into a list nobody reads), and signals_to_exceptions() left its state set:
    every later held() of the process took itself for the command line's and held nothing."""
    from fi_design.cli.parts import _signal_exception
    from fi_design.interrupts import SIGNALS, held, signals_to_exceptions

    before = {s: signal.getsignal(s) for s in SIGNALS}
    real = signal.signal

    def restore(signum, handler):
        out = real(signum, handler)
        if signum == signal.SIGINT and handler is before[signal.SIGINT]:
            raise KeyboardInterrupt  # Ctrl-C at the first bytecode after the restore
        return out

    with pytest.raises(KeyboardInterrupt):
        with signals_to_exceptions(_signal_exception) if command_line else held():
            monkeypatch.setattr(signal, "signal", restore)
    monkeypatch.undo()
    assert {s: signal.getsignal(s) for s in SIGNALS} == before


def test_a_signal_inside_the_import_machinery_comes_again_outside_it():
    """A Ctrl-C whose exception was raised as importlib's weakref callback returned from
    taking the global import lock (before its ``try``) left the lock held: every other
    thread's import then waited for ever, and a design run with an HTML report hung. A signal
    that comes while importlib's own code runs is delivered again once the main thread has
    left it, and raises there."""
    from types import SimpleNamespace

    from fi_design.interrupts import _on_signal, received, signals_to_exceptions

    in_bootstrap = SimpleNamespace(f_code=SimpleNamespace(
        co_filename="<frozen importlib._bootstrap>"))
    raised_inside = []
    with pytest.raises(KeyboardInterrupt):
        with signals_to_exceptions(lambda signum: KeyboardInterrupt()):
            try:
                _on_signal(signal.SIGINT, in_bootstrap)  # held back: no exception here
            except KeyboardInterrupt:
                raised_inside.append(True)
                raise
            assert received() == (signal.SIGINT,)
            deadline = time.monotonic() + 5.0
            while time.monotonic() < deadline:  # delivered again; raises at a bytecode here
                time.sleep(0.001)
            pytest.fail("the signal held back in the import machinery never came again")
    assert not raised_inside, "raised inside importlib's code"
