"""Output paths: refused early, written atomically."""

from __future__ import annotations

import os

import pytest

from fi_design.errors import FiDesignError, OutputError
from fi_design.output import atomic_path, check_output, write_atomic


def test_new_file_accepted(tmp_path):
    assert check_output(tmp_path / "a.json", extensions=(".json",)) == tmp_path / "a.json"


def test_existing_file_needs_force(tmp_path):
    out = tmp_path / "a.json"
    out.write_text("x")
    with pytest.raises(OutputError, match="--force"):
        check_output(out)
    assert check_output(out, force=True) == out


def test_protected_file_refused_even_with_force(tmp_path):
    spec = tmp_path / "spec.yaml"
    spec.write_text("name: x\n")
    hard = tmp_path / "hard.yaml"
    os.link(spec, hard)
    soft = tmp_path / "soft.yaml"
    soft.symlink_to(spec)
    sub = tmp_path / "sub"
    sub.mkdir()
    for path in (spec, hard, soft, sub / ".." / "spec.yaml"):
        with pytest.raises(OutputError, match="input file"):
            check_output(path, force=True, protect=(spec, None))


def test_extension_directory_parent(tmp_path):
    with pytest.raises(OutputError, match=r"\.html or \.pdf"):
        check_output(tmp_path / "r.txt", extensions=(".html", "pdf"))
    assert check_output(tmp_path / "R.HTML", extensions=(".html",))
    with pytest.raises(OutputError, match="does not exist"):
        check_output(tmp_path / "missing" / "r.json")
    (tmp_path / "d.json").mkdir()
    with pytest.raises(OutputError, match="is a directory"):
        check_output(tmp_path / "d.json", force=True)
    (tmp_path / "outdir").mkdir()  # a folder without the suffix: told it is a folder
    with pytest.raises(OutputError, match="outdir: is a directory"):
        check_output(tmp_path / "outdir", extensions=(".html", ".pdf"))
    (tmp_path / "file").write_text("")
    with pytest.raises(OutputError, match="not a directory"):
        check_output(tmp_path / "file" / "r.json")


def test_output_error_is_fi_design_error():
    assert issubclass(OutputError, FiDesignError) and issubclass(OutputError, OSError)


def test_write_atomic_text_and_bytes(tmp_path):
    out = tmp_path / "a.txt"
    write_atomic(out, "héllo\n")
    assert out.read_text(encoding="utf-8") == "héllo\n"
    write_atomic(out, b"\x00\x01")
    assert out.read_bytes() == b"\x00\x01"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_write_atomic_keeps_mode_of_replaced_file(tmp_path):
    out = tmp_path / "a.txt"
    out.write_text("old")
    out.chmod(0o640)
    write_atomic(out, "new")
    assert out.stat().st_mode & 0o777 == 0o640


def test_new_file_gets_umask_permissions(tmp_path):
    out = tmp_path / "n.txt"
    old = os.umask(0o022)
    try:
        write_atomic(out, "x")
    finally:
        os.umask(old)
    assert out.stat().st_mode & 0o777 == 0o644


def test_failure_leaves_old_file_and_no_temporary(tmp_path):
    out = tmp_path / "a.json"
    out.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(out) as tmp:
            tmp.write_text("half")
            raise RuntimeError("writer failed")
    assert out.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]


def test_unwritable_directory(tmp_path, monkeypatch):
    # simulated: the tests may run as root, who can write anywhere
    import tempfile

    monkeypatch.setattr(os, "access", lambda path, mode: False)
    with pytest.raises(OutputError, match="not writable"):
        check_output(tmp_path / "a.json")

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", denied)
    with pytest.raises(OutputError, match="Permission denied"):
        write_atomic(tmp_path / "a.json", "x")
    assert list(tmp_path.iterdir()) == []


def test_replace_failure_leaves_no_temporary(tmp_path, monkeypatch):
    out = tmp_path / "a.json"
    out.write_text("old")

    def fail(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(OutputError, match="No space left"):
        write_atomic(out, "new")
    assert out.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]


def test_missing_directory_on_write(tmp_path):
    with pytest.raises(OutputError, match="cannot create"):
        write_atomic(tmp_path / "nope" / "a.json", "x")


# --------------------------------------------------------------------------- claims: the file
# found when a run checked its output is the one it may replace (issue 23)


def _run(fn, *args, **kwargs):
    """``fn`` in a context of its own, as each command of the CLI runs."""
    import contextvars

    return contextvars.copy_context().run(fn, *args, **kwargs)


def test_a_file_that_appears_during_the_run_is_not_replaced(tmp_path):
    out = tmp_path / "out.json"

    def run():
        check_output(out)  # absent at the check
        out.write_text("another program's file")  # appears while the run works
        with pytest.raises(OutputError, match="appeared .* --force"):
            write_atomic(out, "this run's result")

    _run(run)
    assert out.read_text() == "another program's file"
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]


def test_with_force_a_file_found_at_the_check_is_replaced(tmp_path):
    out = tmp_path / "out.json"
    out.write_text("old")

    def run():
        check_output(out, force=True)
        write_atomic(out, "new")
        write_atomic(out, "newer")  # the run may rewrite its own file

    _run(run)
    assert out.read_text() == "newer"


def test_concurrent_writers_of_one_path_one_wins_and_the_other_says_so(tmp_path):
    """Two runs checked the same output with --force; the first to finish writes it, the
    second refuses to replace a file written after its check (and says by whom: another run)."""
    import contextvars

    out = tmp_path / "out.json"
    out.write_text("before both runs")
    first, second = contextvars.copy_context(), contextvars.copy_context()
    first.run(check_output, out, force=True)
    second.run(check_output, out, force=True)
    first.run(write_atomic, out, "first")
    with pytest.raises(OutputError, match="written by another run"):
        second.run(write_atomic, out, "second")
    assert out.read_text() == "first"
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]


def test_a_stale_output_is_removed_only_as_the_check_found_it(tmp_path):
    """A directory's stale output (a study's map left out this time): refused without force;
    with it, removed after the run, unless another run wrote it since the check, or the run
    did not check it."""
    from fi_design.output import check_output_dir, remove_output

    (tmp_path / "map_C.csv").write_text("earlier study")
    (tmp_path / "map_D.csv").write_text("earlier study")
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="map_C.csv: .*earlier run.*--force"):
        _run(check_output_dir, tmp_path, ["map_A.csv"], stale=["map_B.csv", "map_C.csv"])

    def run():
        check_output_dir(tmp_path, ["map_A.csv"], force=True, stale=["map_B.csv", "map_C.csv",
                                                                     "map_D.csv"])
        (tmp_path / "map_D.csv").write_text("another run's study")  # written since the check
        return [remove_output(tmp_path / n) for n in ("map_B.csv", "map_C.csv", "map_D.csv",
                                                      "notes.txt")]

    assert _run(run) == [False, True, False, False]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map_D.csv", "notes.txt"]
    assert (tmp_path / "map_D.csv").read_text() == "another run's study"


@pytest.mark.parametrize("kwargs,flag", [({}, "--force"),
                                         ({"force_flag": "force=True"}, "force=True")])
def test_a_refused_output_dir_names_the_callers_way_to_force(tmp_path, kwargs, flag):
    """check_output_dir refused a stale file with 'use --force to remove it' even to a library
    caller, who has no such option; check_output words it as its caller passes (force_flag),
    and so does check_output_dir now, for a stale file and for an existing output."""
    from fi_design.output import check_output_dir

    (tmp_path / "map_C.csv").write_text("earlier study")
    with pytest.raises(OutputError) as stale:
        _run(check_output_dir, tmp_path, ["map_A.csv"], stale=["map_C.csv"], **kwargs)
    (tmp_path / "map_A.csv").write_text("earlier study")
    with pytest.raises(OutputError) as exists:
        _run(check_output_dir, tmp_path, ["map_A.csv"], **kwargs)
    for err, words in ((stale, "earlier run"), (exists, "file exists")):
        assert words in str(err.value) and f"use {flag} to" in str(err.value)
        assert flag == "--force" or "--force" not in str(err.value)


def test_without_a_check_a_library_write_replaces(tmp_path):
    """write_atomic alone (a script) keeps its documented meaning: it replaces."""
    out = tmp_path / "out.json"
    out.write_text("old")
    _run(write_atomic, out, "new")
    assert out.read_text() == "new"


@pytest.mark.parametrize("signum", ["SIGTERM", pytest.param("SIGINT", marks=pytest.mark.slow)])
def test_a_signal_while_the_pdf_is_written_leaves_no_temporary_file(tmp_path, signum):
    """SIGTERM (and SIGINT) while WeasyPrint writes the PDF left `.out.pdf.XXXX.tmp` behind."""
    import signal
    import subprocess
    import sys
    import time

    from conftest import BIN, EXAMPLES

    if not sys.platform.startswith("linux"):
        pytest.skip("POSIX signals")
    out = tmp_path / "out.pdf"
    proc = subprocess.Popen([str(BIN / "fi-design"), str(EXAMPLES / "paper_setup.yaml"),
                             "--no-simulation", "--report", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            if any(p.name.endswith(".tmp") for p in tmp_path.iterdir()):
                proc.send_signal(getattr(signal, signum))
                break
            time.sleep(0.002)
        else:
            pytest.fail("the temporary file of the PDF was never seen")
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode != 0, err
    assert "Traceback" not in err
    assert [p.name for p in tmp_path.iterdir()] == [], "a temporary or partial file is left"
