"""One provenance header and one spec hash: every JSON result writes the same keys the same way."""

from __future__ import annotations

import ast
import hashlib
import json
from pathlib import Path

import fi_design
from fi_design.provenance import current_source, header
from fi_design.spec.file import load_spec, origin

PACKAGE = Path(fi_design.__file__).parent


def test_header_keys_and_values(paper_spec, paper_spec_path):
    h = header(spec=paper_spec)
    assert list(h) == ["fi_design_version", "fi_design_source", "spec_sha256"]
    assert h["fi_design_version"] == fi_design.__version__
    assert h["fi_design_source"] == current_source().to_dict()
    # a spec read from a file: the digest of its bytes, what sha256sum prints
    assert h["spec_sha256"] == hashlib.sha256(paper_spec_path.read_bytes()).hexdigest()
    assert list(header()) == ["fi_design_version", "fi_design_source"]
    assert header("9.9", spec="abc")["spec_sha256"] == "abc"
    assert header("9.9")["fi_design_version"] == "9.9"


def test_spec_hash_of_a_mapping_and_of_code(paper_spec):
    raw = origin(paper_spec).raw
    from_mapping = load_spec(raw)
    canonical = json.dumps(raw, sort_keys=True, default=str)
    assert from_mapping.sha256() == hashlib.sha256(canonical.encode()).hexdigest()
    built = paper_spec.model_copy()
    built._origin = None
    values = json.dumps(built.model_dump(mode="json"), sort_keys=True, default=str)
    assert built.sha256() == built.content_sha256() == hashlib.sha256(values.encode()).hexdigest()
    # the content digest ignores how the spec was written
    assert paper_spec.content_sha256() == from_mapping.content_sha256() == built.sha256()


def test_no_to_dict_writes_the_header_by_hand():
    """The keys of the header are written in a result's JSON by fi_design.provenance.header only
    (the report's appendix names the spec's hash for its template: not a JSON header)."""
    keys = {"fi_design_version", "fi_design_source", "spec_sha256"}
    by_hand = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "provenance.py":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        dumps = [f for f in ast.walk(tree) if isinstance(f, ast.FunctionDef) and f.name == "to_dict"]
        for node in (n for f in dumps for n in ast.walk(f)):
            if isinstance(node, ast.Dict):
                for k in node.keys:
                    if isinstance(k, ast.Constant) and k.value in keys:
                        by_hand.append(f"{path.relative_to(PACKAGE)}:{k.lineno} {k.value}")
    assert not by_hand, "write the provenance with fi_design.provenance.header: " + ", ".join(by_hand)


def test_no_spec_hashed_outside_the_spec():
    """One spec hash: Spec.sha256 (the file's bytes, else provenance.json_sha256 of its values)."""
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.relative_to(PACKAGE).as_posix() == "spec/document.py":
            continue  # Spec.content_sha256, the one place
        text = path.read_text(encoding="utf-8")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Call) and "sha256" in ast.unparse(node.func) and \
                    "model_dump" in ast.unparse(node):
                offenders.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert not offenders, offenders
