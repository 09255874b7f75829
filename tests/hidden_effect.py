"""Generator of measured traces with a hidden effect, for the reconciliation tests.

A "true" stage is the spec plus one hidden effect (or none), simulated with
the spec's own moves (the exact profile, not the sampled one the
reconciliation replays). Sensor noise is added to what a data logger would
record: position (after quantization, when the hidden effect quantizes: the
logger sees the encoder the controller sees), commanded force and deflection.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fi_design.measured import Measurement, measurement_from_arrays
from fi_design.simulation.run import simulate
from fi_design.spec import EFFECT_MODELS
from fi_design.spec.file import load_spec

from conftest import EXAMPLES

#: Realistic sensor noise (standard deviations): encoder-like position, force from the
#: controller output, capacitive deflection sensor.
NOISE = {"position": 0.2e-6, "force": 2e-3, "deflection": 0.02e-6}


@dataclass(frozen=True)
class Case:
    """One hidden-effect case: the stage, the moves, the effect and the tolerance."""

    id: str
    isolated: bool
    effect: dict | None  # {"type": ..., params}; None: noise only
    check: dict  # parameter -> relative tolerance (or ("abs", value))
    moves: tuple = ({"distance": "10 mm", "velocity": "50 mm/s", "acceleration": "1 m/s^2"},)
    duration: float = 6.0
    crossover: float = 8.0
    force: bool = True
    deflection: bool = True
    seed: int = 1
    overrides: tuple = ()  # ((dotted key, value), ...) of the spec


def base_spec(case: Case):
    """The spec the reconciliation sees: the paper stage (with or without isolator), no effect."""
    return load_spec(spec_mapping(case))


def spec_mapping(case: Case) -> dict:
    """The spec of :func:`base_spec` as a YAML-ready mapping."""
    import yaml

    src = EXAMPLES / ("paper_setup.yaml" if case.isolated else "no_isolator.yaml")
    raw = yaml.safe_load(src.read_text())
    raw["motion"] = {"moves": [dict(m) for m in case.moves], "duration": f"{case.duration} s"}
    raw["controller"]["crossover"] = f"{case.crossover} Hz"
    raw["requirements"] = dict(raw.get("requirements") or {})
    raw["requirements"]["hunting"] = {"window_start": f"{case.duration / 2} s",
                                      "window_length": f"{case.duration / 2} s"}
    for key, value in case.overrides:
        node = raw
        parts = key.split(".")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = value
    return raw


def measure(case: Case, spec=None) -> Measurement:
    """Simulate the true stage of ``case`` and record it with noise."""
    spec = spec if spec is not None else base_spec(case)
    effects = []
    q = None
    if case.effect is not None:
        e = dict(case.effect)
        if "phase" in e:
            e["phase"] = f"{e['phase']} rad"
        effects = [EFFECT_MODELS[e["type"]].model_validate(e)]
        if e["type"] == "quantization":
            q = float(effects[0].resolution)
    # tight tolerance: the "true" stage carries no integration error of its own
    res = simulate(spec, case.isolated, effects=effects, rtol=1e-8)
    assert res.success, res.message
    rng = np.random.default_rng(case.seed)
    n = len(res.time)
    x = np.asarray(res.position)
    if q:
        x = np.round(x / q) * q
    pos = x + NOISE["position"] * rng.standard_normal(n)
    force = np.asarray(res.force) + NOISE["force"] * rng.standard_normal(n) if case.force else None
    defl = None
    if case.isolated and case.deflection:
        defl = np.asarray(res.deflection) + NOISE["deflection"] * rng.standard_normal(n)
    return measurement_from_arrays(res.time, res.reference, pos, force, defl,
                                   source=f"hidden:{case.id}")


def parameter_error(case: Case, fitted: dict) -> dict:
    """Relative (or absolute) error of every checked parameter."""
    out = {}
    for name, tol in case.check.items():
        true = case.effect[name]
        got = fitted.get(name)
        if isinstance(tol, tuple):
            d = got - true
            if name == "phase":
                d = (d + np.pi) % (2 * np.pi) - np.pi
            out[name] = (abs(d), tol[1])
        else:
            out[name] = (abs(got - true) / abs(true), tol)
    return out
