"""The kernel package's build seam: the digest that ties a build to the sources.

The ahead-of-time extension is used only while it was built from the package's
files as they are; the digest must therefore cover every file of the package,
found on disk, not a hand-kept list (one such list once missed the module with
the numba settings).
"""

from __future__ import annotations

import pkgutil
import shutil
from pathlib import Path

import pytest

import fi_design.kernel
from fi_design.kernel import build

PACKAGE = Path(fi_design.kernel.__file__).resolve().parent


def _copy(tmp_path: Path) -> Path:
    """A copy of the kernel package's sources (no caches, no built extension)."""
    target = tmp_path / "kernel"
    shutil.copytree(PACKAGE, target, ignore=shutil.ignore_patterns("__pycache__", "_aot.*"))
    return target


def test_the_digest_reads_every_module_of_the_package():
    """Every module the import system finds in the package (the built extension aside)."""
    modules = {m.name for m in pkgutil.iter_modules([str(PACKAGE)])} - {build.MODULE}
    read = {p.stem for p in build.source_files()}
    assert read == modules | {"__init__"}
    assert {"layout", "equations", "integrator", "jit", "build", "reference"} <= read


def test_the_digest_is_the_content_of_the_files(tmp_path):
    copy = _copy(tmp_path)
    assert build.source_digest(copy) == build.source_digest()
    for path in sorted(copy.glob("*.py")):
        original = path.read_bytes()
        path.write_bytes(original + b"\n")
        assert build.source_digest(copy) != build.source_digest(), path.name
        path.write_bytes(original)
    assert build.source_digest(copy) == build.source_digest()


def test_a_new_or_renamed_module_changes_the_digest(tmp_path):
    copy = _copy(tmp_path)
    (copy / "friction.py").write_text('"""A module nobody listed."""\n', encoding="utf-8")
    assert build.source_digest(copy) != build.source_digest()
    (copy / "friction.py").unlink()
    (copy / "jit.py").rename(copy / "numba_settings.py")
    assert build.source_digest(copy) != build.source_digest()


def test_a_built_extension_and_caches_are_not_sources(tmp_path):
    copy = _copy(tmp_path)
    (copy / "_aot.cpython-311-x86_64-linux-gnu.so").write_bytes(b"\x7fELF")
    (copy / "__pycache__").mkdir()
    (copy / "__pycache__" / "integrator.integrate-1.py311.nbi").write_bytes(b"index")
    assert build.source_digest(copy) == build.source_digest()


def test_the_package_digest_covers_the_kernel_too():
    """The code digest of results and of the study cache covers the same files."""
    from fi_design import provenance

    files = provenance.code_files()
    assert {f"fi_design/kernel/{p.name}" for p in build.source_files()} <= files.keys()


def test_the_extension_in_use_was_built_from_these_files():
    k = build.compiled()
    if k.backend != "aot":
        pytest.skip(f"the ahead-of-time kernel is not in use here: {k.reason}")
    from fi_design.kernel import _aot

    assert _aot.source_digest() == build.source_digest()
    assert set(build.FUNCTIONS) <= set(dir(_aot))
