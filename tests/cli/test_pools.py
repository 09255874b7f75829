"""The command line's worker pools: started before any progress thread, ended with their parent,
and on failure only their own workers are stopped."""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import BIN, EXAMPLES

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="the pools fork their workers on Linux only")


def _sleep(seconds: float) -> None:
    time.sleep(seconds)


def _running(pid: int) -> bool:
    """Whether a process runs (it exists and is not a zombie)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def test_the_error_path_ends_only_the_pools_own_workers():
    """A failure inside the design's pool stopped every child process of the interpreter."""
    from fi_design.cli.pools import confirmation_pool

    ctx = multiprocessing.get_context("fork")
    bystander = ctx.Process(target=_sleep, args=(30,))
    bystander.start()
    before = set(multiprocessing.active_children())
    try:
        with pytest.raises(RuntimeError, match="the work failed"):
            with confirmation_pool() as pool:
                workers = [p for p in multiprocessing.active_children() if p not in before]
                assert workers, "the pool starts its workers when entered"
                raise RuntimeError("the work failed")
        assert bystander.is_alive(), "a child process that is not the pool's was stopped"
        for worker in workers:
            worker.join(timeout=30)  # a loaded machine
            # the executor's own thread may reap the worker first (is_alive then cannot
            # tell): the process table can
            assert not worker.is_alive() or not _running(worker.pid)
    finally:
        bystander.terminate()
        bystander.join()


def test_the_design_pool_starts_before_the_spinner(paper_spec_path, tmp_path, monkeypatch,
                                                   shared_designs):
    """Fork and threads do not mix: when the spinner (a thread on a terminal) starts, the
    confirmation's workers must already be running. (Without the design search, which this
    failing spec would add after the design: its spinners come later.)"""
    from typer.testing import CliRunner

    import fi_design.console as console
    from fi_design.cli.app import app

    seen = []
    real = console.Status.__enter__

    def enter(self):
        seen.append((self._text, len(multiprocessing.active_children())))
        return real(self)

    monkeypatch.setattr(console.Status, "__enter__", enter)
    result = CliRunner().invoke(app, [str(paper_spec_path), "--no-recommend", "--json",
                                      str(tmp_path / "o.json")])
    assert result.exit_code == 0, result.output
    design = [n for text, n in seen if text.startswith("running the design")]
    assert design and design[0] >= 1, seen


def test_the_report_pool_starts_before_the_spinner(paper_spec_path, tmp_path, monkeypatch,
                                                   shared_designs):
    """A PDF's figures are drawn by a worker forked for the report: it runs when the
    report's spinner (a thread on a terminal) starts, and the PDF is written."""
    from typer.testing import CliRunner

    import fi_design.console as console
    from fi_design.cli.app import app

    seen = []
    real = console.Status.__enter__

    def enter(self):
        seen.append((self._text, len(multiprocessing.active_children())))
        return real(self)

    monkeypatch.setattr(console.Status, "__enter__", enter)
    out = tmp_path / "r.pdf"
    result = CliRunner().invoke(app, [str(paper_spec_path), "--no-recommend", "--report",
                                      str(out)])
    assert result.exit_code == 0, result.output
    report = [n for text, n in seen if text.startswith("writing the report")]
    assert report and report[0] >= 1, seen
    assert out.read_bytes().startswith(b"%PDF")


def _children(pid: int) -> set[int]:
    out = set()
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except FileNotFoundError:  # the process ended
        return out
    for task in tasks:
        try:
            with open(f"/proc/{pid}/task/{task}/children") as fh:
                out.update(int(c) for c in fh.read().split())
        except FileNotFoundError:  # a thread that ended meanwhile
            pass
    return out


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split(")")[-1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def test_sigterm_ends_a_sweep_and_its_workers(tmp_path):
    """After SIGTERM to `fi-design sweep`, its worker processes outlived it; now they end with
    it, and it exits 143 without writing the output."""
    out = tmp_path / "sweep.json"
    proc = subprocess.Popen(
        [str(BIN / "fi-design"), "sweep", str(EXAMPLES / "paper_setup.yaml"), "--x",
         "controller.crossover=2 Hz:30 Hz:400", "--jobs", "2", "--no-cache", "--json", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        workers: set[int] = set()
        while time.monotonic() < deadline and len(workers) < 2:
            time.sleep(0.1)
            workers = _children(proc.pid)
        assert len(workers) >= 2, "the sweep did not start its workers"
        time.sleep(1.0)  # the workers are inside their chunks
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "terminated" in err
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(_alive(w) for w in workers):
        time.sleep(0.1)
    assert not [w for w in workers if _alive(w)], "workers outlived their parent"
    assert not out.exists()


# --------------------------------------------------------------------------- Ctrl-C at any instant

#: Runs the CLI after its imports, saying when it is ready and when the command has finished
#: (a signal sent after that finds nothing left to interrupt).
_DRIVER = """\
import sys, time
from fi_design.cli.app import main
print("ready", flush=True)
sys.argv = ["fi-design"] + sys.argv[1:]
try:
    main()
except SystemExit as exc:
    code = exc.code
print("finished", repr(time.time()), flush=True)
sys.exit(code)
"""


_SWEEP = ["sweep", str(EXAMPLES / "paper_setup.yaml"), "--x", "controller.crossover=3 Hz:15 Hz:3",
          "--y", "isolator.stroke=0.1 mm:0.9 mm:2", "--jobs", "2", "--no-cache",
          "--csv", "map.csv"]
#: The design run: the confirmation and the robustness study's chunks on two workers while
#: this process scans the loop. Its JSON output is map.json (named map.csv, as it was, the
#: run was refused at its outputs' check, exit 2, and never designed anything).
_DESIGN = ["design", str(EXAMPLES / "paper_setup.yaml"), "--no-recommend", "--json", "map.json"]


def _interrupt(tmp_path, prefix: str, command: list[str], delay: float,
               watch=None) -> dict:
    """``command`` run by the driver in a folder of its own under ``tmp_path``, sent SIGINT
    ``delay`` s after the command line is ready (and after ``watch(pid)`` returns, when
    given). Returns its exit code, stderr, the files left, whether it had finished before the
    signal, and what ``watch`` returned (``watched``)."""
    import tempfile
    from pathlib import Path

    work = Path(tempfile.mkdtemp(prefix=f"{prefix}_{delay:.2f}_", dir=tmp_path))
    proc = subprocess.Popen([sys.executable, "-c", _DRIVER, *command],
                            cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    watched = None
    try:
        assert proc.stdout.readline().strip() == "ready"
        if watch is not None:
            watched = watch(proc)
        time.sleep(delay)
        sent = time.time()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    finished = [float(line.split()[1]) for line in out.splitlines()
                if line.startswith("finished ")]
    return dict(delay=delay, code=proc.returncode, err=err, watched=watched,
                files=sorted(p.name for p in work.iterdir()),
                before=bool(finished) and finished[0] < sent)


def _interrupted_sweep(tmp_path, delay: float, command: list[str] = _SWEEP) -> dict:
    """A 6-point sweep on 2 workers (or another ``command``), output to a file, sent SIGINT
    ``delay`` s after the command line is ready: pool start, points, the CSV written, or
    already finished."""
    return _interrupt(tmp_path, "at", command, delay)


def _check_interrupted(run: dict) -> None:
    """A Ctrl-C that came while the command ran ends it with 130 and the interruption's
    message (never an internal error, never exit 0 with the output written); a temporary
    file is never left."""
    assert not [f for f in run["files"] if f.endswith(".tmp")], run
    if run["before"]:  # the command had finished: nothing to interrupt
        return
    # -2: the interpreter's own exit by SIGINT after the message (the shell shows 130)
    assert run["code"] in (130, -signal.SIGINT), run
    assert "interrupted" in run["err"], run
    assert "internal error" not in run["err"] and "Traceback" not in run["err"], run
    assert not {"map.csv", "map.json"} & set(run["files"]) or "it had written" in run["err"], run
    assert "output file name must end with" not in run["err"], run  # the command ran


def _sweep_at(tmp_path, delays, at_once: int = 2, command: list[str] = _SWEEP) -> None:
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(at_once) as ex:
        runs = list(ex.map(lambda d: _interrupted_sweep(tmp_path, d, command), delays))
    bad = []
    for run in runs:
        try:
            _check_interrupted(run)
        except AssertionError as exc:
            bad.append(repr(run))  # the whole run, its stderr included, to read what went wrong
    assert not bad, f"{len(bad)} of {len(runs)} interruptions went wrong:\n" + "\n".join(bad)


def test_ctrl_c_at_a_few_instants_of_a_sweep(tmp_path):
    """Of six SIGINTs sent into a sweep on a loaded machine, one printed `OSError: [Errno 9]
    Bad file descriptor`, one was lost (the sweep wrote map.csv and exited 0)."""
    _sweep_at(tmp_path, [0.2, 1.2, 2.5], at_once=3)  # parsing; the pool's start; the points


def test_ctrl_c_at_a_few_instants_of_a_design_run(tmp_path):
    """The robustness study's chunks are submitted by a thread of their own while the main
    thread scans the loop: an interruption in the steps, in the study or after it ends the
    run with 130 and the interruption's message, never a thread's error."""
    _sweep_at(tmp_path, [0.4, 2.2], command=_DESIGN)  # the steps; the study


@pytest.mark.slow
def test_ctrl_c_at_many_instants_of_a_design_run(tmp_path):
    _sweep_at(tmp_path, [0.2 + 0.15 * k for k in range(30)], command=_DESIGN)


@pytest.mark.slow
def test_ctrl_c_at_many_instants_of_a_sweep(tmp_path):
    _sweep_at(tmp_path, [0.05 + 0.1 * k + 0.03 * (k % 3) for k in range(60)])


def _interrupted_report(tmp_path, delay: float, name: str = "map.pdf") -> dict:
    """The design run with a report (``name``, PDF or HTML), sent SIGINT ``delay`` s after
    the report's worker (a child forked once the design's workers exist no more) appears."""

    def report_worker(proc) -> tuple[set[int], set[int]]:
        design: set[int] = set()
        report: set[int] = set()
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None and not report:
            children = _children(proc.pid)
            if not design:
                design = children
            report = children - design
            time.sleep(0.01)
        return design, report

    run = _interrupt(tmp_path, "report", ["design", str(EXAMPLES / "paper_setup.yaml"),
                                          "--no-recommend", "--report", name],
                     delay, watch=report_worker)
    run["design"], run["report"] = run.pop("watched")
    return run


def _report_at(tmp_path, delays, name: str = "map.pdf") -> None:
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(2) as ex:
        runs = list(ex.map(lambda d: _interrupted_report(tmp_path, d, name), delays))
    bad = []
    for run in runs:
        try:
            assert run["design"] and run["report"], run  # the report's worker was seen
            assert not any(_running(w) for w in run["report"]), run
            _check_interrupted({**run, "files": [f.replace(name, "map.csv")
                                                 for f in run["files"]]})
        except AssertionError:
            bad.append(repr(run))
    assert not bad, f"{len(bad)} of {len(runs)} interruptions went wrong:\n" + "\n".join(bad)


def test_ctrl_c_while_a_pdf_report_is_written(tmp_path):
    """A Ctrl-C while the report's worker draws the figures, or while WeasyPrint lays the PDF
    out, ends the run with 130 and the interruption's message, no PDF and no temporary file,
    and the worker with it."""
    _report_at(tmp_path, [0.0, 1.0])


def test_ctrl_c_while_an_html_report_is_written(tmp_path):
    """An HTML report's figures are drawn by a worker and this process at once: a Ctrl-C
    then ends the run with 130, no HTML and no temporary file, and the worker with it."""
    _report_at(tmp_path, [0.0, 0.15], name="map.html")


@pytest.mark.slow
def test_ctrl_c_at_many_instants_of_a_pdf_report(tmp_path):
    _report_at(tmp_path, [0.1 * k for k in range(30)])


def test_a_pool_thread_taken_apart_under_it_is_not_reported(monkeypatch):
    """After an interrupted stop, a process pool's manager thread that finds its pipes closed
    (OSError) is not reported; any other thread's error still is."""
    import threading
    import types
    from concurrent.futures import process

    from fi_design.cli.pools import _quiet_pool_threads

    reported = []
    monkeypatch.setattr(threading, "excepthook", reported.append)
    _quiet_pool_threads()
    installed = threading.excepthook
    _quiet_pool_threads()  # a second stop in the same process installs nothing more
    assert threading.excepthook is installed

    class Manager(threading.Thread):
        pass

    Manager.__module__ = process.__name__
    pool_error = types.SimpleNamespace(thread=Manager(), exc_type=OSError)
    other_error = types.SimpleNamespace(thread=threading.Thread(), exc_type=OSError)
    pool_bug = types.SimpleNamespace(thread=Manager(), exc_type=ZeroDivisionError)
    for args in (pool_error, other_error, pool_bug):
        threading.excepthook(args)
    assert reported == [other_error, pool_bug]


def test_a_command_reads_its_spec_without_importing_dask(paper_spec_path):
    """pint imports dask.base at its import when dask is installed (0.15 s of every start):
    the command line imports pint with dask hidden, and dask still imports afterwards."""
    pytest.importorskip("dask")
    code = ("import sys\nfrom pathlib import Path\nfrom fi_design.cli.parts import load\n"
            f"load(Path({str(paper_spec_path)!r}))\n"
            "print('dask' in sys.modules, 'pint' in sys.modules)\n"
            "import dask.distributed, pint.compat\n"
            "print(pint.compat.HAS_DASK)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "True", "False"], out


_STUCK_DRIVER = """
import sys, threading
import fi_design.signoff as signoff

def design(*args, **kwargs):
    # a thread the interpreter would join at exit, waiting for ever (a pool's manager
    # thread reading the rest of a result its killed worker never wrote), then Ctrl-C
    threading.Thread(target=threading.Event().wait, name="stuck").start()
    raise KeyboardInterrupt

signoff.design = design
from fi_design.cli.app import main
sys.argv = ["fi-design"] + sys.argv[1:]
main()
"""


def test_an_interrupted_run_ends_with_a_thread_stuck_in_its_pool(tmp_path):
    """Once in some 30 Ctrl-Cs into a report's design run the process never ended: a worker
    killed while it wrote its result left the pool's manager thread reading on for ever, and
    the interpreter waits for that thread at exit. The run now ends with 130 and its message
    within the threads' grace, whatever thread is left."""
    started = time.monotonic()
    proc = subprocess.run([sys.executable, "-c", _STUCK_DRIVER, "design",
                           str(EXAMPLES / "paper_setup.yaml"), "--no-recommend"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 130, (proc.returncode, proc.stderr)
    assert "interrupted" in proc.stderr and "Traceback" not in proc.stderr, proc.stderr
    assert time.monotonic() - started < 30
