"""The design spec: validated, immutable, in SI.

A spec mirrors the YAML file key for key (docs/interfaces.md), so one dotted
path (``friction.static``, ``isolator.stroke``) names a quantity in the file, in
error messages, in ``fi-design sweep --x PATH=...`` and in JSON. Every physical
field accepts an SI number or a string with units; after validation it holds an
SI float (frequencies in Hz, phase margins in degrees, gain margins in dB).

Defaults live here and only here: the ``Field`` defaults of the sections, plus
four that depend on other values, computed by the functions of
:mod:`.defaults` (:func:`bristle_damping`, :func:`joint_damping`,
:func:`limiter_damping`, :func:`proposed_stiffness`). ``fi-design schema``
prints them all.

The package, one job a module: :mod:`.fields` (quantities with units, plain
text, the strict base model), :mod:`.sections` (every section of the file),
:mod:`.filters` (the controller's filter chain and
the drive's units), :mod:`.requirements` (what the design must meet, the hunting
metric, the scatter, the search and its reserves), :mod:`.document` (the :class:`Spec` itself, its effects list and the checks
across sections) and :mod:`.defaults` (derived defaults and warnings). Around the spec itself:
:mod:`.units` (pint at the YAML boundary), :mod:`.file` (reading a spec file,
its origin and hash), :mod:`.errors` (pydantic's errors worded with the path,
line and column), :mod:`.paths` (the values at dotted paths) and :mod:`.edit`
(a spec file written back with changed values, comments kept).
"""

from __future__ import annotations

from .defaults import (CROSSOVER_AGREEMENT, JOINT_DAMPING_RATIO, antiresonance, bristle_damping,
                       default_joint_damping, default_limiter_damping, design_crossover,
                       drive_stiffness, gains_crossover, joint_damping, limiter_damping,
                       proposed_stiffness, stiffness_limit, tuning_mass, warnings_for)
from .document import EFFECT_MODELS, EffectEntry, Spec
from .fields import OptQ, Q, StrictModel, Text
from .filters import BUTTERWORTH, FILTER_TYPES, Drive, FilterEntry, LowPass, Notch
from .requirements import (Hunting, Positioning, RecommendBounds, Requirements, Reserve, Ripple,
                           Robustness)
from .sections import (MAX_OUTPUT_SAMPLES, MAX_STEPS, REPORT_KINDS, Body, Bounds,
                       Controller, CrossoverScan, DocumentIds, Family, Feedforward, Flexure,
                       Friction, Gains, Isolator, Limiter, Material, Measurement, Motion, Move,
                       ParasiticMode, ReportInfo, Revision, Simulation, Stage, move_duration)

__all__ = [
    "BUTTERWORTH", "Drive", "FILTER_TYPES", "FilterEntry", "LowPass", "Notch",
    "Body", "Bounds", "CROSSOVER_AGREEMENT", "Controller", "CrossoverScan", "DocumentIds",
    "EFFECT_MODELS", "EffectEntry", "Family", "Feedforward", "Flexure", "Friction", "Gains",
    "Hunting", "Isolator", "JOINT_DAMPING_RATIO", "Limiter", "MAX_OUTPUT_SAMPLES",
    "MAX_STEPS", "Material", "Measurement", "Motion", "Move", "OptQ",
    "ParasiticMode", "Positioning", "Q", "REPORT_KINDS", "RecommendBounds", "ReportInfo",
    "Requirements", "Reserve",
    "Revision", "Ripple", "Robustness", "Simulation", "Spec", "Stage", "StrictModel", "Text",
    "antiresonance", "bristle_damping", "default_joint_damping", "default_limiter_damping",
    "design_crossover", "drive_stiffness", "gains_crossover", "joint_damping",
    "limiter_damping", "move_duration", "proposed_stiffness", "stiffness_limit",
    "tuning_mass", "warnings_for",
]
