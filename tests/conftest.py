"""Shared fixtures: repository paths and the reference specs."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: Scripts of the virtual environment running the tests (fi-design, lint-imports).
BIN = Path(sys.executable).parent


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The repository root."""
    return ROOT


@pytest.fixture(scope="session")
def paper_spec_path() -> Path:
    """examples/paper_setup.yaml: the paper-like stage with a friction isolator."""
    return EXAMPLES / "paper_setup.yaml"


@pytest.fixture(scope="session")
def paper_spec(paper_spec_path):
    """The validated :class:`~fi_design.spec.Spec` of examples/paper_setup.yaml."""
    from fi_design.specfile import load_spec

    return load_spec(paper_spec_path)
