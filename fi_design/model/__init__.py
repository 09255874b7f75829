"""The spec resolved once: the model every analysis reads.

A :class:`~fi_design.spec.Spec` mirrors the YAML file; several of its values
are left to defaults that depend on other values (the bristle, joint and
limiter damping, the drive stiffness step 3 proposes) or are derived from it
(the loop's controller, the crossover of the hardware's gains). :func:`resolve`
works all of them out once and returns a :class:`Model`: a frozen value with
every number the linear analysis, the simulation, the confirmation, the
verdict and the studies need, in SI. Like pvlib's ``ModelChain``, the choices
are made once and every step runs on the resolved model.

A study, a robustness draw or a search candidate varies the model by a method
of the model that returns a new, checked one, never by rebuilding it from the
spec by hand:

- :meth:`Model.varied` is the one general way: any spec values at their
  dotted paths (``{"isolator.stroke": 1e-4, "controller.crossover": 12.0}``),
  the spec validated again (:func:`fi_design.spec.paths.with_values`) and
  resolved once; the new model's spec holds the values, so everything that
  reads the spec (the robustness study of the sign-off) sees them.
- :meth:`Model.at` is its fast form for the physical values an analysis
  sweeps (crossover, stiffness, stroke, joint damping, friction model,
  effects, masses, delay, filters, the computed modes' scale): the spec is
  neither validated nor resolved again and the guide, once worked out, is
  kept; the model's spec stays as it was and :attr:`Model.changed` lists what
  differs from it.

:meth:`Model.plant` gives the kernel's parameters of one plant.

The public entry points (:func:`fi_design.design`, :func:`fi_design.simulate`,
the studies, the recommendation) take a spec and resolve it once at their edge
(:func:`as_model`); they take a model as well. The analyses below them take a
model only.

Units: masses kg, stiffnesses N/m, dampings N s/m, forces N, velocities m/s,
lengths m, the crossover Hz.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path
from typing import Any

from .. import effects as _effects
from .. import spec as _spec
from ..display import quantity
from ..effects import apply_effects
from ..errors import ArgumentError, SimulationError, SpecError
from ..controller.pid import at_crossover, control_law
from ..kernel.layout import PlantParameters
from ..mechanism.geometry import StageBody, stage_body
from ..results.controller import ControlLaw, Filter
from ..results.friction import FrictionLaw
from ..results.mechanism import GRAVITY, Mode
from ..results.steps import FlexureResult
from .checks import (checked_effects, checked_filters, filter_fields, finite,
                     positive)

__all__ = ["FrictionLaw", "Joint", "Limiter", "Model", "resolve", "as_model", "require_model",
           "apply_effects", "given_mode"]

#: Friction models of the spec (``friction.model``).
FRICTION_MODELS = ("lugre", "switch")
#: Coulomb friction the kernel takes for a spec without any (``friction.coulomb: 0``, static
#: friction alone, Armstrong-Helouvry's case), as a fraction of Fs [-]: LuGre's bristle rate
#: dz/dt = v - sigma0 |v| z / g(v) needs g(v) = Fc + (Fs - Fc) exp(-(v/vs)^2) > 0 at every
#: speed, so g is kept at or above 0.1 % of Fs (with Fs = 4 N a sliding friction of 4 mN).
COULOMB_FLOOR = 1e-3


# --------------------------------------------------------------------------- parts


@dataclass(frozen=True)
class Joint:
    """The isolator's joint: drive stiffness, damping and stroke.

    Attributes
    ----------
    stiffness : float
        Drive stiffness k [N/m]: the spec's, else the one step 3 proposes.
    damping : float
        Joint damping c [N s/m]: the spec's, else damping ratio
        :data:`fi_design.spec.JOINT_DAMPING_RATIO` of the joint mode.
    stroke : float
        One-sided stroke s before the limiter engages [m].
    stiffness_given : bool
        Whether the spec gives the stiffness; if not it is the proposed
        k_max / 2 and follows the stroke (:meth:`Model.at`).
    damping_given : bool
        Whether the spec gives the damping; if not it keeps the joint mode's
        damping ratio when the stiffness changes.
    """

    stiffness: float
    damping: float
    stroke: float
    stiffness_given: bool = True
    damping_given: bool = True


@dataclass(frozen=True)
class Limiter:
    """The stroke limiter (end stop) of the joint.

    Attributes
    ----------
    stiffness : float
        Contact stiffness k_stop [N/m].
    damping : float
        Contact damping c_stop [N s/m] (the spec's default filled in).
    """

    stiffness: float
    damping: float


# --------------------------------------------------------------------------- the model


@dataclass(frozen=True, eq=False)
class Model:
    """A spec resolved into the numbers every analysis reads (SI).

    Build it with :func:`resolve`; vary it with :meth:`varied` (any spec
    value by its dotted path, resolved again) or its fast form :meth:`at`
    (the physical values, the spec kept). The physical values live here, and
    only here: read them from the model, not from ``spec``, which may differ
    after :meth:`at`.

    Attributes
    ----------
    spec : fi_design.spec.Spec
        The spec it was resolved from: its name, motion, requirements and
        simulation settings hold for the model; its physical values may
        differ after :meth:`at`.
    m1 : float
        Stage mass [kg] (actuator side, carries the sensor).
    m2 : float
        Cart mass [kg] (bearing side, friction acts on it).
    friction : FrictionLaw
        The bearing's friction.
    offset : float
        Constant load force on the stage [N] (m1 a1 = u - offset - ...).
    joint : Joint or None
        The isolator's joint; None for a stage without isolator.
    limiter : Limiter or None
        The isolator's end stop; None without isolator.
    given_modes : tuple of fi_design.results.mechanism.Mode
        The parasitic modes the spec gives (``isolator.parasitic_modes``,
        measured values): they override the guide's computed modes.
    body : StageBody
        The stage as a rigid body (its inertia and the sensor's and
        actuator's offsets), for the flexure guide.
    law : fi_design.results.controller.ControlLaw
        The loop's controller: the rule's PID at the crossover or the
        hardware's gains, with sampling, delay, saturation and feedforward.
    effects : tuple
        Effect entries of the model (the spec's ``effects`` items), applied
        in order by :meth:`plant`.
    changed : tuple of str
        The spec paths whose values :meth:`at` changed, in order (empty: the
        spec as resolved, also after :meth:`varied`). A study that varies the
        spec does not see them.
    mode_scale : float
        Factor on the frequencies of the guide's computed modes [-] (1: as
        computed; a reserve check lowers them).
    """

    spec: _spec.Spec
    m1: float
    m2: float
    friction: FrictionLaw
    offset: float
    joint: Joint | None
    limiter: Limiter | None
    given_modes: tuple[Mode, ...]
    body: StageBody
    law: ControlLaw
    effects: tuple = ()
    changed: tuple[str, ...] = ()
    mode_scale: float = 1.0

    # ---- the flexure guide and the modes the loop sees

    @property
    def flexure_spec(self):
        """The spec's ``isolator.flexure`` (a guide drawn or to size), or None."""
        iso = self.spec.isolator
        return None if self.joint is None or iso is None else iso.flexure

    @cached_property
    def flexure(self) -> FlexureResult | None:
        """The isolator's leaf-spring guide as a mechanism, or None without a flexure section.

        A guide drawn in the spec is evaluated; one given by bounds is sized
        for the joint's stiffness and stroke (:func:`fi_design.mechanism.sizing.size_guide`:
        k_max, the stress, ``requirements.buckling_factor`` and every parasitic mode at
        ``parasitic_separation`` x the loop's crossover, :attr:`sizing_crossover`, as
        step 3 judges it). Worked out on first use and kept by :meth:`at` while the
        joint stays.
        """
        flex = self.flexure_spec
        if flex is None:
            return None
        from ..mechanism.sizing import drawn_guide, size_guide

        req = self.requirements
        common = dict(stroke=self.joint.stroke, cart_mass=self.m2,
                      stop_stiffness=self.limiter.stiffness,
                      maximum_stiffness=_spec.stiffness_limit(self.spec, self.joint.stroke),
                      required_frequency=req.parasitic_separation * self.sizing_crossover,
                      required_buckling=req.buckling_factor)
        if flex.drawn:
            return drawn_guide(flex, self.body, **common)
        return size_guide(flex, self.body, target_stiffness=self.joint.stiffness, **common)

    @property
    def stiffness_scatter(self) -> float:
        """The drive stiffness's scatter the robustness study draws [-]:
        ``requirements.robustness.stiffness``, else the flexure's stock thickness tolerance
        (k goes with t^3), else 5 %."""
        given = self.requirements.robustness.stiffness
        if given is not None:
            return given
        fx = self.flexure if self.joint is not None else None
        if fx is not None and fx.mechanics is not None and fx.thickness:
            return 3.0 * fx.thickness_tolerance / fx.thickness
        return 0.05

    @property
    def sizing_crossover(self) -> float:
        """The loop's crossover a guide is sized against [Hz]: the highest 0 dB crossing of the
        rigid limit cases in the loop's band (with the cart stuck and the joint free it lies
        well above the crossover the PID is tuned for: the joint's resonance lifts |L|), else
        the controller's crossover (:func:`fi_design.mechanism.plants.rigid_loop_crossover`).
        """
        from ..mechanism.plants import rigid_loop_crossover

        top = rigid_loop_crossover(self)
        return self.crossover if top is None else top

    @cached_property
    def modes(self) -> tuple[Mode, ...]:
        """The parasitic modes the loop sees, by frequency.

        The guide's computed ones (its stage's five and its leaves' own) and
        the given ones (``isolator.parasitic_modes``, measured): a given mode
        with a guide direction replaces the computed mode of that direction, a
        ``structure`` mode adds to them, and given modes without a direction
        replace them all. Without a guide, the given ones.
        """
        given = self.given_modes
        fx = self.flexure if self.joint is not None else None
        if fx is None or fx.mechanics is None or any(m.direction == "given" for m in given):
            return given
        replaced = {m.direction for m in given}
        # a mode the weight has made unstable (0 Hz: a buckled guide, which step 3 fails) is
        # no resonance of the loop
        kept = tuple(m if self.mode_scale == 1.0 else replace(m, frequency=m.frequency
                                                                * self.mode_scale)
                     for m in fx.mechanics.parasitic_modes
                     if m.direction not in replaced and m.frequency > 0.0)
        return tuple(sorted(kept + given, key=lambda m: m.frequency))

    # ---- views

    @property
    def total_mass(self) -> float:
        """m1 + m2 [kg]."""
        return self.m1 + self.m2

    @property
    def held_weight(self) -> float:
        """The weight the actuator holds on a vertical drive axis [N], which the simulation
        does not carry: (m1 + m2) g where ``isolator.flexure.orientation`` is
        ``vertical_axis`` (the stage's weight directly, the cart's through the joint), else 0."""
        iso = self.spec.isolator
        flexure = None if iso is None else iso.flexure
        if flexure is None or flexure.orientation != "vertical_axis":
            return 0.0
        return self.total_mass * GRAVITY

    @property
    def departures(self) -> tuple[str, ...]:
        """Where this model departs from its spec: the paths :meth:`at` changed, and
        ``mode_scale`` when the guide's modes are scaled; empty for the spec's own model.

        What reads the spec (a study varying it by paths, the search, the sign-off's
        robustness study) would not see these values: such callers refuse a model that
        departs, naming them."""
        return self.changed + (("mode_scale",) if self.mode_scale != 1.0 else ())

    @property
    def has_isolator(self) -> bool:
        """Whether the model has the isolator's joint."""
        return self.joint is not None

    @property
    def joint_damping_ratio(self) -> float | None:
        """The joint mode's damping ratio c / (2 sqrt(|k| m1 m2 / (m1 + m2))) [-]; None
        without isolator."""
        j = self.joint
        if j is None:
            return None
        return j.damping / (2.0 * math.sqrt(abs(j.stiffness) * self.m1 * self.m2
                                            / (self.m1 + self.m2)))

    @property
    def static_error_bound(self) -> float | None:
        """The largest position error a loop without integrator can rest at [m].

        ``(Fs + |offset|) / kp`` with the larger static friction of the two
        directions (:data:`fi_design.results.stage.STATIC_ERROR_FORMULA`): the
        cart stays put while the loop's force, kp e plus the load offset, stays
        below static friction, so any rest within it is the loop's static
        error, not a stuck stage. None when the loop integrates.
        """
        f = self.friction
        return self.law.static_error(max(f.static(1.0), f.static(-1.0)) + abs(self.offset))

    @property
    def crossover(self) -> float:
        """The loop's (design) crossover [Hz]: the rule's fc, or the gains' own."""
        return self.law.crossover

    @property
    def sample_period(self) -> float:
        """Controller period [s]; 0 for continuous time."""
        return self.law.sample_period

    @property
    def delay(self) -> float:
        """Computational delay of the controller [s] (``controller.delay``)."""
        return self.law.delay

    @property
    def loop_delay(self) -> float:
        """The loop's delay [s]: ``controller.delay`` with the model's effects on it (a
        ``time_delay`` adds its delay), the delay :meth:`plant` gives the simulation and the
        linear analysis models (:func:`fi_design.loop.linear.delay_time`)."""
        return _effects.effect_value(self.effects, "delay", self.law.delay)

    @property
    def requirements(self) -> _spec.Requirements:
        """The spec's ``requirements`` (margins, hunting metric, robustness)."""
        return self.spec.requirements

    # ---- variants

    def varied(self, values: Mapping[str, Any]) -> "Model":
        """The model of this model's spec with values at dotted spec paths, resolved once.

        The one general way to vary a design: a study axis, a robustness
        draw, a search candidate. The spec is validated again with the values
        (:func:`fi_design.spec.paths.with_values`) and resolved
        (:func:`resolve`) once, so the new model's spec holds them: whatever
        reads the spec (the sign-off's robustness study, the report) sees the
        same design as the analyses. For the physical values it names,
        :meth:`at` is the fast form (no validation of the whole spec, the
        guide kept).

        Parameters
        ----------
        values : mapping of str to value
            Dotted spec path (``"isolator.stroke"``,
            ``"effects[type=time_delay].delay"``) to the new value: an SI
            number, a string with units (``"0.3 mm"``) or None to clear an
            optional value, as the YAML file takes it.

        Returns
        -------
        Model
            A new model with :attr:`changed` empty; this one is unchanged.

        Raises
        ------
        SpecError
            An unknown path or a value the spec refuses; the message names
            the path.
        ArgumentError
            This model was varied with :meth:`at` (its values are not in its
            spec, so they would be lost): vary the resolved model instead.

        Examples
        --------
        >>> from fi_design.spec.file import load_spec
        >>> model = resolve(load_spec("examples/paper_setup.yaml"))
        >>> m = model.varied({"isolator.stroke": "0.5 mm", "controller.crossover": 10.0})
        >>> m.joint.stroke, m.crossover, m.spec.isolator.stroke, m.changed
        (0.0005, 10.0, 0.0005, ())
        """
        if self.departures:
            raise ArgumentError(f"this model differs from its spec at "
                                f"{', '.join(self.departures)} (Model.at): "
                                "vary the model resolved from the spec, with every value "
                                "in Model.varied")
        from ..spec.paths import with_values

        return resolve(with_values(self.spec, values))

    def at(self, *, crossover: float | None = None, stiffness: float | None = None,
           stroke: float | None = None, damping: float | None = None,
           friction_model: str | None = None, effects=None,
           masses: tuple[float, float] | None = None, delay: float | None = None,
           mode_scale: float | None = None, filters=None) -> "Model":
        """The same model with some physical values changed, checked like the spec checks them.

        The fast form of :meth:`varied` for the values an analysis sweeps: the
        spec is neither validated nor resolved again, the guide once worked
        out is kept while the joint stays; the model's spec stays as it was
        and :attr:`changed` names the paths that now differ from it.

        Parameters
        ----------
        crossover : float, optional
            Shift the loop to this crossover [Hz]: the rule retunes, explicit
            gains scale in frequency (:func:`fi_design.controller.pid.at_crossover`).
        stiffness : float, optional
            Drive stiffness k [N/m]. A damping the spec does not give keeps
            the joint mode's damping ratio.
        stroke : float, optional
            One-sided stroke [m]. A stiffness the spec does not give is the
            proposed one of the new stroke (k_max / 2). On a model without
            isolator, ``stroke`` (and ``stiffness``, else the proposed one)
            adds an isolator with the spec's default damping and limiter.
        damping : float, optional
            Joint damping c [N s/m].
        friction_model : {"lugre", "switch"}, optional
            The friction model.
        effects : sequence of effect entries, optional
            Effect entries (spec ``effects`` items) replacing the model's,
            applied in order: an entry of a type listed before sets its
            values again (or, for an additive parameter, adds to them), as
            the reconciliation stacks a candidate on the spec's effects.
        masses : (float, float), optional
            The true stage and cart masses m1, m2 [kg]: the plant changes, the
            controller keeps its tuning; the flexure guide (its geometry kept)
            carries the new stage, and a joint the guide defines follows its
            net stiffness.
        delay : float, optional
            The loop's computational delay [s].
        mode_scale : float, optional
            Factor on the guide's computed modes' frequencies [-].
        filters : sequence of fi_design.results.controller.Filter, optional
            The drive's filter chain replacing the law's (``controller.filters``).

        Returns
        -------
        Model
            A new model; this one is unchanged.

        Raises
        ------
        SpecError
            A value the spec would refuse (not positive, not finite, an
            unknown friction model, an entry that is not an effect entry,
            ``joint_damping`` without isolator), or an isolator value for a
            model without isolator and without ``stroke``; the message names
            the spec path.
        """
        model = self
        if stiffness is not None or stroke is not None or damping is not None:
            model = self._with_joint(stiffness, stroke, damping)
        paths = [path for path, value in (
            ("controller.crossover", crossover), ("isolator.stiffness", stiffness),
            ("isolator.stroke", stroke), ("isolator.damping", damping),
            ("friction.model", friction_model), ("effects", effects),
            ("controller.filters", filters), ("controller.delay", delay),
            ("stage.mass", None if masses is None else masses[0]),
            ("cart.mass", None if masses is None else masses[1])) if value is not None]
        law, friction = model.law, model.friction
        if crossover is not None:
            law = at_crossover(law, positive(crossover, "controller.crossover", "Hz"))
        if filters is not None:
            law = replace(law, filters=checked_filters(filters, law.sample_period))
        if friction_model is not None:
            if friction_model not in FRICTION_MODELS:
                raise SpecError(f"must be one of {', '.join(FRICTION_MODELS)}, got "
                                f"{friction_model!r}", path="friction.model")
            friction = replace(friction, model=friction_model)
        entries = model.effects if effects is None else checked_effects(effects, model.joint)
        changed = self.changed + tuple(p for p in paths if p not in self.changed)
        if delay is not None:
            d = finite(delay, "controller.delay", "s")
            if d < 0.0:
                raise SpecError(f"must be at least 0 s, got {delay!r}", path="controller.delay")
            law = replace(law, delay=d)
        scale = model.mode_scale if mode_scale is None else positive(mode_scale, "mode_scale",
                                                                     "-")
        out = replace(model, law=law, friction=friction, effects=entries, changed=changed,
                      mode_scale=scale)
        if masses is not None:
            return out._with_masses(*masses)
        if model is self:  # the joint stays: so do the guide and its modes, once worked out
            for name in ("flexure",) + (("modes",) if mode_scale is None else ()):
                if name in self.__dict__:
                    out.__dict__[name] = self.__dict__[name]
        return out

    def _with_masses(self, m1: float, m2: float) -> "Model":
        """The model with the true masses changed: the guide as built carries the new stage."""
        m1 = positive(m1, "stage.mass", "kg")
        m2 = positive(m2, "cart.mass", "kg")
        b = self.body
        f = m1 / b.mass
        body = replace(b, mass=m1, inertia=tuple(i * f for i in b.inertia))
        out = replace(self, m1=m1, m2=m2, body=body)
        fx = self.flexure
        if fx is not None and fx.mechanics is not None:
            from ..mechanism.sizing import reevaluate

            g = replace(fx.guide, stage_mass=m1, stage_inertia=body.inertia, cart_mass=m2)
            moved = reevaluate(fx, g)
            out.__dict__["flexure"] = moved
            if self.joint is not None and self._guide_defines_stiffness:
                out = replace(out, joint=replace(self.joint,
                                                 stiffness=moved.mechanics.net_drive_stiffness))
                out.__dict__["flexure"] = moved
        return out

    @property
    def _guide_defines_stiffness(self) -> bool:
        """Whether the joint's stiffness is the drawn guide's own (not the spec's number)."""
        iso = self.spec.isolator
        return (iso is not None and iso.stiffness is None and iso.flexure is not None
                and iso.flexure.drawn and "isolator.stiffness" not in self.changed)

    def _with_joint(self, stiffness, stroke, damping) -> "Model":
        """The model with the joint's values changed (an isolator added when it has none)."""
        j = self.joint
        if j is None and stroke is None:
            raise SpecError("the model has no isolator: give its stroke to add one",
                            path="isolator.stroke")
        s = j.stroke if stroke is None else positive(stroke, "isolator.stroke", "m")
        given_k = stiffness is not None or (j is not None and j.stiffness_given)
        if stiffness is not None:
            k = positive(stiffness, "isolator.stiffness", "N/m")
        elif given_k:
            k = j.stiffness
        else:
            k = _spec.proposed_stiffness(self.spec, s)
        given_c = damping is not None or (j is not None and j.damping_given)
        if damping is not None:
            c = finite(damping, "isolator.damping", "N*s/m")
            if c < 0.0:
                raise SpecError(f"must be at least {quantity(0.0, 'N*s/m')}, got {damping!r}",
                                path="isolator.damping")
        elif given_c:
            c = j.damping
        else:
            c = _spec.default_joint_damping(k, self.m1, self.m2)
        joint = Joint(stiffness=k, damping=c, stroke=s, stiffness_given=given_k,
                      damping_given=given_c)
        if j is not None:
            return replace(self, joint=joint)
        lim = _spec.Limiter()  # the spec's defaults: no modes, the default end stop
        return replace(self, joint=joint, given_modes=(),
                       limiter=Limiter(lim.stiffness,
                                       _spec.default_limiter_damping(lim.stiffness, self.m1)))

    # ---- the kernel's parameters

    def plant(self, isolated: bool) -> PlantParameters:
        """The kernel's parameters of one plant, the model's effects applied.

        Parameters
        ----------
        isolated : bool
            The two-mass plant with joint and limiter (True) or one rigid
            mass m1 + m2 (False).

        Returns
        -------
        fi_design.kernel.layout.PlantParameters
            The controller from the nominal masses; the effects then change
            the true plant (a mass error does not retune the controller).

        Raises
        ------
        SimulationError
            ``isolated`` for a model without isolator.
        """
        if isolated and self.joint is None:
            raise SimulationError("the spec has no isolator: cannot simulate the isolated plant")
        law, f = self.law, self.friction
        if isolated:
            j, lim = self.joint, self.limiter
            joint = dict(k=j.stiffness, c=j.damping, s=j.stroke, k_stop=lim.stiffness,
                         c_stop=lim.damping)
        else:
            joint = dict(k=0.0, c=0.0, s=0.0, k_stop=0.0, c_stop=0.0)
        params = PlantParameters(
            m1=self.m1, m2=self.m2, **joint, Fs=f.Fs, Fc=max(f.Fc, COULOMB_FLOOR * f.Fs),
            vs=f.vs, sigma0=f.sigma0,
            sigma1=f.sigma1, sigma2=f.sigma2, **law.kernel_form(),
            Fc_neg=math.nan if f.Fc_neg is None else f.Fc_neg,
            sigma2_neg=math.nan if f.sigma2_neg is None else f.sigma2_neg,
            offset=self.offset, ff_mass=law.ff_mass, ff_viscous=law.ff_viscous,
            ff_coulomb=law.ff_coulomb, delay=law.delay, force_limit=law.force_limit,
            isolated=1.0 if isolated else 0.0, switch_model=1.0 if f.model == "switch" else 0.0)
        if law.sample_period > 0.0:
            params = replace(params, sample_period=law.sample_period, **law.discrete_form())
        if law.filters:
            params = replace(params, **filter_fields(law.filters, law.sample_period))
        return apply_effects(params, self.effects)


# --------------------------------------------------------------------------- resolving


def resolve(spec: _spec.Spec | str | Path | Mapping[str, Any]) -> Model:
    """Resolve a spec into its :class:`Model`, every default and derived value worked out once.

    Parameters
    ----------
    spec : fi_design.spec.Spec, path or mapping
        A validated spec, or a YAML path or mapping for
        :func:`fi_design.spec.file.load_spec` (what :func:`fi_design.design` takes).

    Returns
    -------
    Model

    Raises
    ------
    ArgumentError
        ``spec`` is none of these (None, a number, a list, a :class:`Model`).
    fi_design.errors.SpecFileError, fi_design.errors.SpecError
        As :func:`~fi_design.spec.file.load_spec`, for a path or mapping.

    Examples
    --------
    >>> from fi_design.spec.file import load_spec
    >>> model = resolve(load_spec("examples/paper_setup.yaml"))
    >>> model.crossover, model.joint.stiffness, round(model.joint.damping, 2)
    (8.0, 6667.0, 4.62)
    >>> round(model.at(crossover=10.0).law.kp, 1)
    3333.7
    >>> resolve("examples/paper_setup.yaml").crossover  # a path (or a mapping) is loaded
    8.0
    """
    from ..spec.file import as_spec

    spec = as_spec(spec)
    f = spec.friction
    friction = FrictionLaw(model=f.model, Fs=f.static, Fc=f.coulomb, vs=f.stribeck_velocity,
                           sigma0=f.bristle_stiffness, sigma1=_spec.bristle_damping(spec),
                           sigma2=f.viscous, Fc_neg=f.coulomb_negative,
                           sigma2_neg=f.viscous_negative)
    iso = spec.isolator
    joint = limiter = None
    modes: tuple = ()
    body = stage_body(spec.stage)
    if iso is not None:
        k = _spec.drive_stiffness(spec)
        given = iso.stiffness is not None
        if iso.flexure is not None and iso.flexure.drawn and not given:
            k = _drawn_stiffness(iso.flexure, body, spec)
        joint = Joint(stiffness=k, damping=_spec.joint_damping(spec, k), stroke=iso.stroke,
                      stiffness_given=given or (iso.flexure is not None and iso.flexure.drawn),
                      damping_given=iso.damping is not None)
        limiter = Limiter(stiffness=iso.limiter.stiffness, damping=_spec.limiter_damping(spec))
        modes = tuple(given_mode(m) for m in iso.parasitic_modes)
    return Model(spec=spec, m1=spec.stage.mass, m2=spec.cart.mass, friction=friction,
                 offset=f.offset, joint=joint, limiter=limiter, given_modes=modes, body=body,
                 law=control_law(spec), effects=tuple(spec.effects))


def _drawn_stiffness(flexure, body: StageBody, spec: _spec.Spec) -> float:
    """The net drive stiffness of a guide the spec draws, gravity included [N/m]."""
    from ..mechanism.geometry import leaf_guide
    from ..mechanism.sizing import net_stiffness

    g = leaf_guide(flexure, body, length=flexure.length, width=flexure.width,
                   thickness=flexure.thickness, cart_mass=spec.cart.mass)
    # a guide the weight buckles has a negative net stiffness: step 3 fails it, and the
    # simulation shows the stage leaning on its end stop
    return float(net_stiffness(g, g.length, g.width, g.thickness))


def given_mode(mode: _spec.ParasiticMode) -> Mode:
    """A parasitic mode of the spec as the loop's :class:`~fi_design.results.mechanism.Mode`."""
    return Mode(name=mode.name, frequency=mode.frequency, damping_ratio=mode.damping_ratio,
                direction=mode.direction or "given", coupling=1.0,
                participation=1.0 if mode.collocated else -1.0, source="given",
                collocated=mode.collocated,
                antiresonance=_spec.antiresonance(mode) if mode.collocated else None)


def as_model(spec_or_model, name: str = "spec") -> Model:
    """A model as given, or the spec resolved (:func:`resolve`); anything else is refused
    naming the argument ``name`` and a Model among what it takes."""
    from ..spec.file import as_spec

    if isinstance(spec_or_model, Model):
        return spec_or_model
    return resolve(as_spec(spec_or_model, name, model=True))


def require_model(value: Any) -> Model:
    """``value``, checked to be a :class:`Model`.

    The analyses take a model only; the entry points (:func:`fi_design.design`,
    :func:`fi_design.simulate`, the stage-level answers, the studies, the
    recommendation) resolve a spec once at their edge (:func:`as_model`).

    Raises
    ------
    ArgumentError
        ``value`` is not a model (a spec, say): resolve it first.
    """
    if not isinstance(value, Model):
        raise ArgumentError(f"expected a Model, got {type(value).__name__}: resolve a spec "
                            "once with fi_design.resolve(spec) and pass the model")
    return value
