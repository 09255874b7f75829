"""The catalogue of physical effects the model can carry (docs/effects.md).

Effects are data. Each :class:`Effect` has a stable name, a one-line physical
description and its :class:`Parameter` entries (unit, fitting bounds, neutral
value). The simulation kernel implements every effect once, with a neutral
default; an effect only sets kernel parameters (``Parameter.kernel_field``),
so adding one to a spec never changes the compiled code.

Effects compose with ``+`` into an :class:`EffectSet`, which refuses two
effects that set the same kernel parameter (like lmfit's composite models
refuse colliding parameter names).

A spec lists applied effects under ``effects:`` as ``{type: NAME, PARAM: value,
...}``; see :func:`fi_design.spec.Spec`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Mapping

from .display import quantity, with_error


@dataclass(frozen=True)
class Parameter:
    """One parameter of an effect.

    Attributes
    ----------
    name : str
        Key in the spec's effect entry and in result dictionaries.
    unit : str
        SI unit (``"1"`` for a plain fraction, ``"rad"`` for phases).
    description : str
        What it is, in one line.
    kernel_field : str
        Name of the :class:`fi_design.kernel.layout.PlantParameters` field it sets.
    bounds : tuple of float
        Search range for the reconciliation fit, SI. When ``relative`` is true,
        factors applied to the nominal value instead.
    neutral : float or None
        The value that leaves the model unchanged; ``None`` means "the nominal
        spec value" (for effects that correct a spec parameter).
    relative : bool
        Whether ``bounds`` are factors on the nominal value.
    log : bool
        Whether a fit should search this parameter on a logarithmic scale.
    periodic : bool
        Whether the parameter is a phase (wraps at 2 pi, searched on a grid).
    required : bool
        Whether a spec entry must give it (optional ones take ``neutral``).
    combine : str
        ``"set"``: the value replaces the kernel parameter; ``"add"``: it adds
        to the nominal one (an extra delay on top of the controller's).
    limits : tuple of (str, float)
        The physically possible values, as pydantic field constraints
        (``(("gt", 0.0),)``: above zero; ``(("ge", 0.0), ("lt", 1.0))``); a
        spec entry outside them is refused. Empty: any finite value.
    """

    name: str
    unit: str
    description: str
    kernel_field: str
    bounds: tuple[float, float]
    neutral: float | None = 0.0
    relative: bool = False
    log: bool = False
    periodic: bool = False
    required: bool = True
    combine: str = "set"
    limits: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class Effect:
    """A named physical effect: parameters and how it enters the model.

    Attributes
    ----------
    name : str
        Stable name (the interface: docs/effects.md).
    description : str
        How the effect enters the equations, one line.
    parameters : tuple of Parameter
        Its parameters.
    """

    name: str
    description: str
    parameters: tuple[Parameter, ...]

    @property
    def kernel_fields(self) -> tuple[str, ...]:
        """Kernel parameters this effect sets."""
        return tuple(p.kernel_field for p in self.parameters)

    def parameter(self, name: str) -> Parameter:
        """Return the parameter called ``name`` (KeyError if absent)."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    def __add__(self, other: "Effect | EffectSet") -> "EffectSet":
        return EffectSet((self,)) + other


@dataclass(frozen=True)
class EffectSet:
    """Several effects applied together; no two may set the same kernel field."""

    effects: tuple[Effect, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        seen: dict[str, str] = {}
        for eff in self.effects:
            for f in eff.kernel_fields:
                if f in seen:
                    raise ValueError(f"effects '{seen[f]}' and '{eff.name}' both set '{f}'")
                seen[f] = eff.name

    def __add__(self, other: "Effect | EffectSet") -> "EffectSet":
        more = other.effects if isinstance(other, EffectSet) else (other,)
        return EffectSet(self.effects + tuple(more))

    @property
    def names(self) -> tuple[str, ...]:
        """Names of the effects, in order."""
        return tuple(e.name for e in self.effects)


_TWO_PI = 2.0 * math.pi
#: Limits of a parameter that must be above zero (a length, a mass, a resolution, a force limit).
_POSITIVE = (("gt", 0.0),)
#: Limits of a parameter that must not be negative (a friction, a damping, a delay).
_NOT_NEGATIVE = (("ge", 0.0),)

CATALOGUE: dict[str, Effect] = {e.name: e for e in (
    Effect("viscous_friction", "the bearing's viscous coefficient sigma2 differs from nominal", (
        Parameter("viscous", "N*s/m", "true viscous friction coefficient sigma2", "sigma2",
                  (0.0, 500.0), neutral=None, limits=_NOT_NEGATIVE),)),
    Effect("stribeck_velocity", "the Stribeck velocity vs differs from nominal", (
        Parameter("stribeck_velocity", "m/s", "true Stribeck velocity vs", "vs",
                  (1e-5, 0.1), neutral=None, log=True, limits=_POSITIVE),)),
    Effect("position_dependent_friction",
           "Fs and Fc scaled by 1 + a sin(2 pi x2 / wavelength + phase) along the rail", (
        Parameter("amplitude", "1", "relative amplitude a of the friction variation",
                  "pdf_amplitude", (0.0, 0.9), limits=(("ge", 0.0), ("lt", 1.0))),
        Parameter("wavelength", "m", "spatial period of the variation", "pdf_wavelength",
                  (2e-4, 0.05), neutral=1.0, log=True, limits=_POSITIVE),
        Parameter("phase", "rad", "phase of the variation at x2 = 0", "pdf_phase",
                  (-math.pi, math.pi), periodic=True, required=False),)),
    Effect("force_ripple", "extra force A sin(2 pi x1 / pitch + phase) on the stage (motor cogging)", (
        Parameter("amplitude", "N", "ripple force amplitude A", "ripple_amplitude", (0.0, 10.0)),
        Parameter("pitch", "m", "spatial period of the ripple", "ripple_pitch",
                  (2e-4, 0.05), neutral=1.0, log=True, limits=_POSITIVE),
        Parameter("phase", "rad", "phase of the ripple at x1 = 0", "ripple_phase",
                  (-math.pi, math.pi), periodic=True, required=False),)),
    Effect("cable_force", "extra force -k_c (x1 - x1(0)) - F0 on the stage (cable slab)", (
        Parameter("stiffness", "N/m", "cable stiffness k_c", "cable_stiffness", (-500.0, 500.0)),
        Parameter("preload", "N", "constant cable force F0", "cable_preload", (-10.0, 10.0),
                  required=False),)),
    Effect("time_delay", "the actuator force u is applied a delay later", (
        Parameter("delay", "s", "extra loop delay", "delay", (0.0, 0.02), combine="add",
                  limits=_NOT_NEGATIVE),)),
    Effect("quantization", "the controller sees round(x1 / q) q", (
        Parameter("resolution", "m", "position quantization step q", "quantization",
                  (1e-8, 1e-4), log=True, limits=_NOT_NEGATIVE),)),
    Effect("force_saturation", "the actuator force is clipped to +-limit", (
        Parameter("limit", "N", "actuator force limit", "force_limit", (0.1, 1000.0),
                  neutral=math.inf, log=True, limits=_POSITIVE),)),
    Effect("mass_error", "the true stage and cart masses differ from nominal", (
        Parameter("stage_mass", "kg", "true stage mass m1", "m1", (0.5, 2.0), neutral=None,
                  relative=True, required=False, limits=_POSITIVE),
        Parameter("cart_mass", "kg", "true cart mass m2", "m2", (0.5, 2.0), neutral=None,
                  relative=True, required=False, limits=_POSITIVE),)),
    Effect("joint_damping", "the joint damping c of the isolator differs from nominal", (
        Parameter("damping", "N*s/m", "true joint damping c", "c", (0.0, 200.0), neutral=None,
                  limits=_NOT_NEGATIVE),)),
    Effect("force_offset", "a constant load force on the stage, m1 a1 = u - offset - ... "
                           "(drive offset, an inclined axis)", (
        Parameter("offset", "N", "constant load force on the stage", "offset", (-10.0, 10.0),
                  neutral=None),)),
    Effect("friction_asymmetry", "Coulomb and viscous friction differ when the cart slides in "
                                 "the negative direction (static friction scales with Coulomb)", (
        Parameter("coulomb_negative", "N", "Coulomb friction in the negative direction",
                  "Fc_neg", (0.25, 4.0), neutral=None, relative=True, log=True,
                  limits=_NOT_NEGATIVE),
        Parameter("viscous_negative", "N*s/m", "viscous friction in the negative direction",
                  "sigma2_neg", (0.25, 4.0), neutral=None, relative=True, log=True,
                  required=False, limits=_NOT_NEGATIVE),)),
)}

#: Stable effect names, in catalogue order.
EFFECT_NAMES: tuple[str, ...] = tuple(CATALOGUE)


def get(name: str) -> Effect:
    """Return the catalogue entry ``name``.

    Raises
    ------
    KeyError
        With the list of known names, when ``name`` is not in the catalogue.
    """
    try:
        return CATALOGUE[name]
    except KeyError:
        raise KeyError(f"unknown effect {name!r}; known: {', '.join(EFFECT_NAMES)}") from None


def apply_effects(params, entries):
    """The kernel's parameters with effect entries set (neutral values change nothing).

    Parameters
    ----------
    params : fi_design.kernel.layout.PlantParameters
        The nominal plant's parameters.
    entries : sequence
        Effect entries (a spec's ``effects`` items), applied in order (:func:`effect_value`).

    Returns
    -------
    fi_design.kernel.layout.PlantParameters
    """
    fields = dict.fromkeys(par.kernel_field for entry in entries
                           for par in get(entry.type).parameters
                           if getattr(entry, par.name) is not None)
    changes = {f: effect_value(entries, f, getattr(params, f)) for f in fields}
    return replace(params, **changes) if changes else params


def effect_value(entries, kernel_field: str, nominal: float) -> float:
    """The value of one kernel parameter once effect entries set it (SI).

    An entry setting it replaces the value, or, for an additive parameter
    (``combine="add"``: a ``time_delay`` on ``controller.delay``), adds to
    ``nominal``; of several entries setting it the last counts.
    """
    value = float(nominal)
    for entry in entries:
        for par in get(entry.type).parameters:
            given = getattr(entry, par.name)
            if par.kernel_field != kernel_field or given is None:
                continue
            value = float(nominal + given if par.combine == "add" else given)
    return value


def values_text(name: str, values: Mapping[str, float | None],
                errors: Mapping[str, float | None] | None = None, *, sep: str = " ") -> str:
    """The values of an effect for a reader, each with its standard error in one unit.

    Parameters
    ----------
    name : str
        Effect name (catalogue entry); a name it does not know gives plain numbers.
    values : mapping of str to float or None
        Parameter name to SI value (None: left out).
    errors : mapping of str to float or None, optional
        Parameter name to its standard error (SI).
    sep : str, optional
        Between number and unit (a no-break space in reports).

    Returns
    -------
    str
        ``amplitude = 0.25 ± 1.1 × 10⁻⁵, wavelength = 5 ± 3.5 × 10⁻⁵ mm, phase = 0.8 rad``.
    """
    units = {p.name: p.unit for p in CATALOGUE[name].parameters} if name in CATALOGUE else {}
    return ", ".join(f"{k} = {with_error(v, (errors or {}).get(k), units.get(k, ''), sep=sep)}"
                     for k, v in values.items() if v is not None)



def entries_text(entries, *, sep: str = " ") -> str:
    """A spec's effect entries for a reader: each name and its values.

    Parameters
    ----------
    entries : sequence
        Effect entries (the spec's ``effects`` items: a ``type`` naming a
        catalogue entry, its parameters as attributes, SI).
    sep : str, optional
        Between number and unit (a no-break space in reports).

    Returns
    -------
    str
        ``time_delay (delay = 0.002 s), quantization (resolution = 1 µm)``;
        empty without entries.
    """
    out = []
    for e in entries:
        values = {p.name: getattr(e, p.name, None) for p in get(e.type).parameters}
        out.append(f"{e.type} ({values_text(e.type, values, sep=sep)})")
    return ", ".join(out)


#: Effects the linear analysis models as well: a ``time_delay`` delays the actuator force like
#: ``controller.delay`` does (the simulation adds the two), so the limit cases' margins and the
#: achievable crossover include it (:attr:`fi_design.model.Model.loop_delay`).
LINEAR_EFFECTS: tuple[str, ...] = ("time_delay",)


def simulated_only(entries, *, sep: str = " ") -> str:
    """Which effects the simulation carries and the linear analysis does not, as a clause.

    Effects only set parameters of the simulation; of them the linear steps
    (the rule's gains, the limit cases' margins, the achievable crossover)
    model the loop delay a ``time_delay`` adds (:data:`LINEAR_EFFECTS`), and
    analyse the loop without the others.

    Parameters
    ----------
    entries : sequence
        The spec's effect entries (:func:`entries_text`).
    sep : str, optional
        Between number and unit.

    Returns
    -------
    str
        ``the simulation carries the spec's effect quantization (resolution = 1 µm);
        the linear analysis (the gains, the margins, the crossover) leaves it
        out``; empty when the linear analysis models every entry (or there is none).
    """
    left = [e for e in entries if e.type not in LINEAR_EFFECTS]
    if not left:
        return ""
    one = len(left) == 1
    return (f"the simulation carries the spec's effect{'' if one else 's'} "
            f"{entries_text(left, sep=sep)}; the linear analysis (the gains, the margins, "
            f"the crossover) leaves {'it' if one else 'them'} out")


def delay_words(delay: float, entries=(), *, sep: str = " ") -> str:
    """The loop's delay in words: ``no delay``, ``delay 0.001 s`` (``controller.delay``), or
    with a ``time_delay`` effect of ``entries``, which delays the loop as well (in the
    simulation and the linear analysis), ``delay 0.001 s + 0.002 s of the effect time_delay``.

    Parameters
    ----------
    delay : float
        ``controller.delay`` [s].
    entries : sequence, optional
        The spec's effect entries.
    sep : str, optional
        Between number and unit.
    """
    parts = [quantity(delay, "s", sep=sep)] if delay else []
    parts += [f"{quantity(e.delay, 's', sep=sep)} of the effect time_delay"
              for e in entries if e.type == "time_delay"]
    return "delay " + " + ".join(parts) if parts else "no delay"
