"""The sections of a spec, key for key as in the YAML file, with their defaults.
"""

from __future__ import annotations

import datetime
import math
from typing import Any, Literal, Union

from pydantic import Field, field_validator, model_validator

from ..display import millimetres as _mm
from ..display import number, quantity, unit_text
from ..trajectory import profile_duration
from .fields import OptQ, Q, StrictModel, Text
from .filters import Drive, FilterEntry

#: Units in the field descriptions as every output writes them (fi_design.display).
_DAMPING = unit_text("N*s/m")
_INTEGRAL = unit_text("N/(m*s)")


# --------------------------------------------------------------------------- sections


class Body(StrictModel):
    """A rigid body."""

    mass: Q("kg") = Field(gt=0, description="Mass [kg].")


Offset = tuple[Q("m"), Q("m")]


class Stage(Body):
    """The stage: the actuated rigid body the isolator's guide carries."""

    size: Union[tuple[Q("m"), Q("m"), Q("m")], None] = Field(
        None, description="Edge lengths [x, y, z] of the stage as a uniform box of its mass [m], "
                          "for its inertia on the flexure guide; x the drive direction, z along "
                          "the guide's leaves. Default: a steel cube of the stage's mass.")
    inertia: Union[tuple[Q("kg*m**2"), Q("kg*m**2"), Q("kg*m**2")], None] = Field(
        None, description="Moments of inertia [Ixx, Iyy, Izz] about the centre of mass "
                          "[kg m^2], in place of size.")
    centre_of_mass_height: OptQ("m") = Field(
        None, ge=0, description="Distance of the centre of mass beyond the guide's clamp, along "
                                "the leaves [m]. Default: half the stage's z size.")
    sensor_offset: Offset = Field(
        (0.0, 0.0), description="Where the position sensor measures x: [y, z] from the centre "
                                "of mass [m]; a tilt shows in x by the offset. Default [0, 0].")
    actuator_offset: Offset = Field(
        (0.0, 0.0), description="Where the actuator pushes along x: [y, z] from the centre of "
                                "mass [m]. Default [0, 0].")

    @model_validator(mode="after")
    def _body(self) -> "Stage":
        if self.size is not None and self.inertia is not None:
            raise ValueError("give size or inertia, not both")
        for name in ("size", "inertia"):
            value = getattr(self, name)
            if value is not None and not all(v > 0 for v in value):
                raise ValueError(f"{name} must be positive in all three directions")
        if self.inertia is not None and all(v > 0 for v in self.inertia):
            total = sum(self.inertia)
            # a rigid body's principal moments: each at most the sum of the other two
            if any(v > (total - v) * (1 + 1e-9) for v in self.inertia):
                raise ValueError("inertia is no rigid body's: each of Ixx, Iyy, Izz must be at "
                                 "most the sum of the other two")
        if self.inertia is not None and self.centre_of_mass_height is None:
            raise ValueError("inertia needs centre_of_mass_height (the size gives it otherwise)")
        return self


class Friction(StrictModel):
    """Friction of the bearing, acting on the cart (LuGre, Canudas de Wit et al. 1995)."""

    model: Literal["lugre", "switch"] = Field(
        "lugre", description="Friction model: 'lugre' (default) or 'switch' (Karnopp-type "
                             "stick-slip cross-check).")
    static: Q("N") = Field(gt=0, description="Static friction force Fs [N].")
    coulomb: Q("N") = Field(ge=0, description="Coulomb (sliding) friction force Fc [N]; 0 for "
                                              "static friction without Coulomb friction "
                                              "(simulated with 0.1 % of Fs, LuGre needs it "
                                              "above 0).")
    stribeck_velocity: Q("m/s") = Field(gt=0, description="Stribeck velocity vs [m/s].")
    viscous: Q("N*s/m") = Field(0.0, ge=0, description="Viscous friction coefficient sigma2 "
                                                        f"[{_DAMPING}]. Default 0.")
    bristle_stiffness: Q("N/m") = Field(1e6, gt=0, description="Bristle (presliding) stiffness "
                                                               "sigma0 [N/m]. Default 1e6 N/m.")
    bristle_damping: OptQ("N*s/m") = Field(
        None, ge=0, description=f"Bristle damping sigma1 [{_DAMPING}]. Default sqrt(sigma0 (m1 + m2)): "
                                "damping ratio 0.5 of the whole moving mass on the bristles.")
    coulomb_negative: OptQ("N") = Field(
        None, gt=0, description="Coulomb friction when the cart slides in the negative direction "
                                "[N]; static friction that way scales with it (Fs coulomb_negative "
                                "/ coulomb). Default: coulomb (symmetric friction).")
    viscous_negative: OptQ("N*s/m") = Field(
        None, ge=0, description=f"Viscous friction coefficient in the negative direction [{_DAMPING}]. "
                                "Default: viscous.")
    offset: Q("N") = Field(0.0, description="Constant load force on the stage [N] (drive offset, "
                                            "gravity on an inclined axis), with the sign of a "
                                            "friction force: m1 a1 = u - offset - ..., so u = "
                                            "offset holds the stage. Default 0.")

    @model_validator(mode="after")
    def _static_above_coulomb(self) -> "Friction":
        if self.static < self.coulomb:
            raise ValueError(f"static friction Fs = {quantity(self.static, 'N', 6)} must be at "
                             f"least the Coulomb friction Fc = {quantity(self.coulomb, 'N', 6)}")
        if self.coulomb == 0 and self.coulomb_negative is not None:
            raise ValueError("coulomb_negative needs a Coulomb friction above 0: static "
                             "friction in the negative direction scales with coulomb_negative / "
                             "coulomb")
        return self


class Limiter(StrictModel):
    """Compliant stroke limiter (end stop) of the joint."""

    stiffness: Q("N/m") = Field(1e6, gt=0, description="Contact stiffness k_stop [N/m]. "
                                                       "Default 1e6 N/m.")
    damping: OptQ("N*s/m") = Field(None, ge=0, description=f"Contact damping c_stop [{_DAMPING}]. "
                                                           "Default 2 * 0.2 * sqrt(k_stop m1).")


class ParasiticMode(StrictModel):
    """A parasitic resonance (a measured value), added to the linear limit cases.

    With a flexure guide the guide's own modes are computed. A given mode with
    a guide ``direction`` (x, y, z, rx, ry, rz, leaf) replaces the computed
    mode of that direction for the spec's guide; ``structure`` marks a mode of
    the stage's or frame's own structure, which the guide does not set: it is
    added to the computed modes and kept for every guide a recommendation
    tries. Given modes without a direction replace all computed modes of the
    spec's guide (they are the measured set).
    """

    name: Text = Field("mode", description="Label used in reports.")
    direction: Literal["x", "y", "z", "rx", "ry", "rz", "leaf", "structure"] | None = Field(
        None, description="The guide's direction it replaces (x, y, z, rx, ry, rz, leaf), or "
                          "structure: a mode of the stage's or frame's structure, added to the "
                          "guide's computed modes and kept for any guide. Default none: with "
                          "a flexure guide, the given modes replace all computed ones.")
    frequency: Q("Hz") = Field(gt=0, description="Resonance frequency [Hz].")
    damping_ratio: Q("1") = Field(0.01, ge=0, lt=1, description="Modal damping ratio [-]. "
                                                               "Default 0.01.")
    collocated: bool = Field(False, description="True: an antiresonance precedes the resonance "
                                                "(phase returns); false: the resonance adds a "
                                                "180 degree phase drop.")
    antiresonance: OptQ("Hz") = Field(None, gt=0, description="Antiresonance of a collocated "
                                                              "mode [Hz]. Default frequency / "
                                                              "sqrt(2).")

    @model_validator(mode="after")
    def _anti_below(self) -> "ParasiticMode":
        if self.antiresonance is not None and self.antiresonance >= self.frequency:
            raise ValueError("antiresonance must lie below the resonance frequency")
        return self


class Material(StrictModel):
    """Flexure material."""

    youngs_modulus: Q("Pa") = Field(gt=0, description="Young's modulus E [Pa].")
    allowed_stress: Q("Pa") = Field(gt=0, description="Allowed bending stress [Pa] (fatigue "
                                                      "limit with safety).")
    density: Q("kg/m**3") = Field(gt=0, description="Density [kg/m^3].")
    poisson_ratio: float = Field(0.3, gt=0, lt=0.5, description="Poisson's ratio [-] (the shear "
                                                                "modulus E / (2 (1 + nu))). "
                                                                "Default 0.3.")

    @field_validator("youngs_modulus")
    @classmethod
    def _a_solid(cls, E: float) -> float:
        if not 1e7 <= E <= 2e12:
            raise ValueError(f"{quantity(E, 'Pa', 4)} is not the modulus of a leaf spring's "
                             "material (10 MPa, a soft polymer, to 2000 GPa; steel 200 GPa): "
                             "check its unit (GPa; a number without a unit is read in Pa)")
        return E

    @field_validator("density")
    @classmethod
    def _a_solid_density(cls, rho: float) -> float:
        if not 100.0 <= rho <= 25000.0:
            raise ValueError(f"{quantity(rho, 'kg/m**3', 4)} is not the density of a solid "
                             "(100 to 25000 kg/m^3; steel 7800 kg/m^3): check its unit")
        return rho

    @field_validator("allowed_stress")
    @classmethod
    def _below_modulus(cls, stress: float, info: Any) -> float:
        E = info.data.get("youngs_modulus")
        if E is not None and stress >= 0.1 * E:
            raise ValueError(f"{quantity(stress, 'Pa', 4)} is a strain of {number(stress / E, 3)} "
                             f"at Young's modulus {quantity(E, 'Pa', 4)}, which no leaf spring "
                             "takes (steel: 300 MPa over 200 GPa, 0.0015): check its unit")
        return stress


#: The most stock thicknesses (multiples of ``thickness_step`` within the thickness bounds) the
#: sizing takes: each is a column of its grid of leaves.
MAX_STOCK = 200


def _span(value: Any) -> tuple[float, float] | None:
    """(min, max) of a leaf dimension as validated: a value is both; None where it failed."""
    return None if value is None else (value, value) if isinstance(value, float) else value


Bounds = tuple[Q("m"), Q("m")]
#: A leaf dimension: one value (the guide as drawn) or [min, max] (bounds step 3 sizes within).
Dimension = Union[Bounds, Q("m")]


class Flexure(StrictModel):
    """The isolator's parallel leaf-spring guide: drawn (one value per dimension) or sized.

    Each of length, width and thickness is one value (the guide as drawn) or
    [min, max] (step 3 sizes the guide within the bounds). The guide carries
    the stage; its stiffness in six directions, its weight and its modes
    follow from the geometry.
    """

    material: Material
    leaves: Literal[2, 4] = Field(2, description="Number of leaves: 2 (one per row) or 4 (two "
                                                 "side by side per row). Default 2.")
    length: Dimension = Field((5e-3, 100e-3), description="Leaf length L [m], or [min, max] to "
                                                          "size. Default 5 mm to 100 mm.")
    width: Dimension = Field((2e-3, 50e-3), description="Leaf width b [m], or [min, max] to "
                                                        "size. Default 2 mm to 50 mm.")
    thickness: Dimension = Field((0.05e-3, 2e-3), description="Leaf thickness t [m], or "
                                                              "[min, max] to size. Default "
                                                              "0.05 mm to 2 mm.")
    spacing: OptQ("m") = Field(None, gt=0, description=(
        "Distance between the two rows of leaves along the drive direction [m], more than the "
        "leaves' thickness. Default: the stage's x size."))
    lateral_spacing: OptQ("m") = Field(None, gt=0, description=(
        "With 4 leaves only: centre distance of the two leaves of a row [m], at least the "
        "narrowest leaf's width (the sizing keeps the leaves no wider). Default: the stage's y "
        "size less a leaf width, at least one leaf width."))
    orientation: Literal["standing", "hanging", "flat", "vertical_axis"] = Field(
        "standing", description="The guide against gravity: 'standing' (leaves vertical, the "
                                "stage on top, compressed by its weight; default), 'hanging' "
                                "(the stage below, in tension), 'flat' (leaves horizontal, the "
                                "weight across their width), 'vertical_axis' (the drive axis "
                                "vertical: the joint carries the cart's weight).")
    damping_ratio: Q("1") = Field(0.01, gt=0, lt=1, description="Modal damping ratio of the "
                                                               "guide's computed modes [-]. "
                                                               "Default 0.01.")
    thickness_step: OptQ("m") = Field(0.05e-3, gt=0, validate_default=True, description=(
        "Stock thicknesses: the leaves are sized in multiples of this [m], at most 200 of them "
        "within the thickness bounds; null sizes an unrounded thickness. Default 0.05 mm."))
    thickness_tolerance: Q("m") = Field(0.01e-3, ge=0, validate_default=True, description=(
        "Thickness tolerance of the stock, +- [m], below the smallest thickness: the drive "
        "stiffness goes with t^3. Default 0.01 mm."))

    @field_validator("length", "width", "thickness")
    @classmethod
    def _ordered(cls, value: Any, info: Any) -> Any:
        lo, hi = _span(value)
        if isinstance(value, float) and not lo > 0:
            raise ValueError(f"must be positive, got {_mm(lo)}")
        if not 0 < lo <= hi:
            raise ValueError(f"[min, max] with 0 < min <= max, got [{_mm(lo)}, {_mm(hi)}] (a "
                             "number without a unit is read in m)")
        width = info.data.get("width")
        if info.field_name == "thickness" and isinstance(value, float) and \
                isinstance(width, float) and isinstance(info.data.get("length"), float) and \
                value >= width:
            raise ValueError(f"a leaf must be thinner than it is wide: thickness {_mm(value)} "
                             f"is not below width {_mm(width)}")
        return value

    @field_validator("spacing")
    @classmethod
    def _rows_apart(cls, spacing: Any, info: Any) -> Any:
        top = (_span(info.data.get("thickness")) or (0.0, 0.0))[1]
        if spacing is not None and spacing <= top:
            raise ValueError(f"the two rows of leaves would touch: {_mm(spacing)} must exceed "
                             f"the leaves' thickness (up to {_mm(top)})")
        return spacing

    @field_validator("lateral_spacing")
    @classmethod
    def _side_by_side(cls, lateral: Any, info: Any) -> Any:
        width = _span(info.data.get("width"))
        if lateral is None or width is None:
            return lateral
        if info.data.get("leaves") == 2:
            raise ValueError("places the two leaves of a row side by side: it needs leaves: 4 "
                             "(with 2 leaves, one per row, leave it out)")
        least = width[0]
        if lateral < least:
            raise ValueError(f"the leaves of a row would overlap: {_mm(lateral)} is below the "
                             f"smallest leaf width {_mm(least)} (their centre distance must be "
                             "at least a width)")
        return lateral

    @field_validator("thickness_step")
    @classmethod
    def _few_stocks(cls, step: Any, info: Any) -> Any:
        thickness = info.data.get("thickness")
        if step is None or thickness is None or isinstance(thickness, float):
            return step
        lo, hi = thickness
        count = math.floor(hi / step + 1e-9) - math.ceil(lo / step - 1e-9) + 1
        if count > MAX_STOCK:
            raise ValueError(f"{quantity(step, 'm', 4)} gives {count} stock thicknesses from "
                             f"{_mm(lo)} to {_mm(hi)} (isolator.flexure.thickness); the sizing "
                             f"takes at most {MAX_STOCK}: a coarser step or a narrower "
                             "thickness range")
        return step

    @field_validator("thickness_tolerance")
    @classmethod
    def _below_stock(cls, tolerance: Any, info: Any) -> Any:
        thickness = _span(info.data.get("thickness"))
        if thickness is not None:
            least = thickness[0]
            if tolerance >= least:
                raise ValueError(f"must be below the smallest thickness, {_mm(least)}")
        return tolerance

    def bounds(self, name: str) -> tuple[float, float]:
        """[min, max] of a leaf dimension [m] (a drawn value is both)."""
        value = getattr(self, name)
        return (value, value) if isinstance(value, float) else value

    @property
    def drawn(self) -> bool:
        """Whether the spec draws the guide (one value per dimension) instead of sizing it."""
        return all(isinstance(getattr(self, n), float) for n in ("length", "width", "thickness"))


class Isolator(StrictModel):
    """The friction isolator: a compliant joint between stage and cart, with limiters."""

    stiffness: OptQ("N/m") = Field(None, gt=0, description="Drive stiffness k [N/m]. Omit to let "
                                                           "step 3 propose one (k_max / 2).")
    stroke: Q("m") = Field(gt=0, description="One-sided stroke s before the limiter engages [m].")
    damping: OptQ("N*s/m") = Field(None, ge=0, description=f"Joint damping c [{_DAMPING}]. Default "
                                                           "damping ratio 0.05 of the joint mode: "
                                                           "2 * 0.05 * sqrt(k m1 m2 / (m1 + m2)).")
    limiter: Limiter = Field(default_factory=Limiter)
    parasitic_modes: tuple[ParasiticMode, ...] = Field((), description="Parasitic resonances of "
                                                                        "the flexure.")
    flexure: Flexure | None = Field(None, description="Optional: the parallel leaf-spring guide "
                                                      "that realises the joint, drawn or to "
                                                      "size; its six stiffnesses, weight and "
                                                      "modes enter the design.")


class Gains(StrictModel):
    """The hardware's own controller gains, parallel form: u = kp e + ki integral(e) + kd e'."""

    kp: Q("N/m") = Field(gt=0, description="Proportional gain kp [N/m].")
    ki: Q("N/(m*s)") = Field(0.0, ge=0, description=f"Integral gain ki [{_INTEGRAL}]; 0: a PD loop "
                                                    "(no integrator). Default 0.")
    kd: Q("N*s/m") = Field(0.0, ge=0, description=f"Derivative gain kd [{_DAMPING}]. Default 0.")


class Feedforward(StrictModel):
    """Force from the reference, added to the feedback force: mass r'' + viscous r' + coulomb sign(r')."""

    mass: Q("kg") = Field(0.0, ge=0, description="Acceleration feedforward mass [kg]. Default 0.")
    viscous: Q("N*s/m") = Field(0.0, ge=0, description=f"Velocity feedforward [{_DAMPING}]. Default 0.")
    coulomb: Q("N") = Field(0.0, ge=0, description="Coulomb feedforward, times the sign of the "
                                                   "reference velocity [N]. Default 0.")


class Controller(StrictModel):
    """The position controller: the paper's PID rule (paper section 2.2) or the hardware's gains.

    Without gains the PID is tuned from the crossover by the rule; with gains
    the loop, the four limit cases, the simulation and the report use the
    given gains, and the rule's gains are shown beside them (docs/model.md).
    """

    crossover: OptQ("Hz") = Field(None, gt=0, description="Desired crossover frequency fc [Hz]; "
                                                           "the rule tunes the PID for it. "
                                                           "Optional with gains: then the "
                                                           "crossover the gains were tuned for, "
                                                           "within 10 % of where they cross the "
                                                           "tuning mass over (without it, that "
                                                           "crossover is computed).")
    gains: Gains | None = Field(None, description="The hardware's own gains; omit to tune by the "
                                                  "rule.")
    derivative_on: Literal["error", "measurement"] = Field(
        "error", description="Input of the D term: 'error' (default) or 'measurement' (-x1 only: "
                             "velocity feedback, as most industrial drives do).")
    roll_off: OptQ("Hz") = Field(None, gt=0, description="First-order low-pass of the D term "
                                                         "[Hz]. Default: with the rule its wt "
                                                         "(derivative_ratio x crossover); with "
                                                         "gains none (an ideal D, sampled when "
                                                         "sample_rate is set).")
    force_limit: OptQ("N") = Field(None, gt=0, description="Actuator saturation of the hardware "
                                                           "[N]; null: none.")
    feedforward: Feedforward | None = Field(None, description="Feedforward from the reference; "
                                                              "null: none.")
    derivative_ratio: float = Field(3.0, gt=1, description="Rule: wd = wc / ratio and wt = ratio "
                                                           "* wc. Default 3.")
    integrator_ratio: float = Field(10.0, gt=1, allow_inf_nan=True,
                                    description="Rule: wi = wc / ratio; .inf for a PD rule (no "
                                                "integrator). Default 10.")
    tuning_mass: Literal["total", "stage"] = Field(
        "total", description="Mass the rule tunes on: 'total' (m1 + m2, default) or 'stage'.")
    sample_rate: OptQ("Hz") = Field(None, gt=0, description="Sample rate of a discrete controller "
                                                            "[Hz] (zero-order hold); null for "
                                                            "continuous time.")
    delay: Q("s") = Field(0.0, ge=0, description="Computational delay [s]. Default 0.")
    pade_order: int = Field(3, ge=1, le=10, description="Order of the Pade approximation of the "
                                                        "delay in the linear analysis. Default 3.")
    filters: tuple[FilterEntry, ...] = Field((), max_length=4,
                                             description="The drive's filter chain: notch "
                                                         "and low_pass filters in series "
                                                         "with the PID, on its output, in "
                                                         "this order (at most 4). Default "
                                                         "none.")
    drive: Drive | None = Field(None, description="The drive's units (motor constant, encoder "
                                                  "resolution, current scaling): the gains in "
                                                  "counts and amperes too. Default none.")

    @model_validator(mode="after")
    def _crossover_or_gains(self) -> "Controller":
        if self.crossover is None and self.gains is None:
            raise ValueError("give the desired crossover (the PID rule tunes for it) or the "
                             "hardware's gains")
        if self.sample_rate is not None:
            for i, f in enumerate(self.filters):
                if f.frequency >= 0.5 * self.sample_rate:
                    raise ValueError(f"filters[{i}] ({f.name}) at {quantity(f.frequency, 'Hz', 6)} "
                                     "lies at or above the Nyquist frequency "
                                     f"{quantity(0.5 * self.sample_rate, 'Hz', 6)} of sample_rate")
        return self


class Move(StrictModel):
    """A point-to-point move with a trapezoidal (or jerk-limited) velocity profile."""

    distance: Q("m") = Field(description="Signed travel [m].")
    velocity: Q("m/s") = Field(gt=0, description="Maximum velocity [m/s].")
    acceleration: Q("m/s**2") = Field(gt=0, description="Maximum acceleration [m/s^2].")
    jerk: OptQ("m/s**3") = Field(None, gt=0, description="Maximum jerk [m/s^3]; null for a "
                                                         "trapezoidal velocity.")
    start: OptQ("s") = Field(None, ge=0, description="Start time [s]; null: right after the "
                                                     "previous move.")

    @model_validator(mode="after")
    def _nonzero(self) -> "Move":
        if self.distance == 0:
            raise ValueError("distance must not be zero")
        return self


class Family(StrictModel):
    """The moves the stage must settle after: hunting is judged over all of them.

    Default: ``count`` distances log-spaced from a tenth of the isolator's
    stroke (0.1 mm without isolator) to five times the spec's largest move, at
    the velocity, acceleration and jerk of the spec's largest move, in both
    directions when the friction or the loads are not symmetric. The spec's
    own motion is always judged as well.
    """

    distances: Union[tuple[Q("m"), ...], None] = Field(
        None, description="Signed move distances [m]; null: log-spaced from smallest to largest.")
    smallest: OptQ("m") = Field(None, gt=0, description="Smallest distance [m]; null: a tenth of "
                                                        "the isolator's stroke, 0.1 mm without "
                                                        "isolator.")
    largest: OptQ("m") = Field(None, gt=0, description="Largest distance [m]; null: five times the "
                                                       "spec's largest move.")
    count: int = Field(24, ge=2, le=400, description="Number of log-spaced distances. Default 24.")
    directions: Literal["auto", "both", "positive"] = Field(
        "auto", description="Move directions: both, positive only, or auto (both when the "
                            "friction or the loads are not symmetric). Default auto.")

    @field_validator("distances")
    @classmethod
    def _not_empty(cls, distances: tuple[float, ...] | None) -> tuple[float, ...] | None:
        if distances is not None and not distances:
            raise ValueError("an empty list judges no move of the family: give at least one "
                             "distance, or null (or leave the key out) for log-spaced ones")
        return distances

    @model_validator(mode="after")
    def _sane(self) -> "Family":
        if self.distances is not None and any(d == 0 for d in self.distances):
            raise ValueError("distances must not be zero")
        if self.smallest is not None and self.largest is not None and \
                self.largest <= self.smallest:
            raise ValueError("largest must be above smallest")
        return self


class Motion(StrictModel):
    """Reference motion: moves run one after another, then hold."""

    moves: tuple[Move, ...] = Field(min_length=1, description="The moves.")
    duration: Q("s") = Field(20.0, gt=0, description="Simulated time [s]; duration x "
                                                      "simulation.output_rate at most 4e6 "
                                                      "samples. Default 20 s.")
    family: Family = Field(default_factory=Family, description="The moves the stage must settle "
                                                               "after (stage-level hunting).")

    @model_validator(mode="after")
    def _in_order(self) -> "Motion":
        end = 0.0
        for i, (start, stop) in enumerate(self.spans()):
            if start < end - 1e-12:
                raise ValueError(f"moves[{i}] starts at {quantity(start, 's', 6)}, before "
                                 f"moves[{i - 1}] ends at {quantity(end, 's', 4)}")
            end = stop
        return self

    def spans(self) -> list[tuple[float, float]]:
        """Start and end time of each move [s]: a move without ``start`` follows the last."""
        out, t = [], 0.0
        for mv in self.moves:
            t0 = mv.start if mv.start is not None else t
            t = t0 + move_duration(mv)
            out.append((t0, t))
        return out

    @property
    def end_time(self) -> float:
        """End of the last move [s]."""
        return self.spans()[-1][1]


class Measurement(StrictModel):
    """What the sensors add (for reconciliation); estimated from data when absent."""

    position_noise: OptQ("m") = Field(None, ge=0, description="Position noise std [m].")
    deflection_noise: OptQ("m") = Field(None, ge=0, description="Deflection noise std [m].")
    force_noise: OptQ("N") = Field(None, ge=0, description="Force noise std [N].")


#: Most output samples of one simulation (duration x output rate): about 150 bytes each in
#: memory, so 0.6 GB; a 400 s record at 10 kHz.
MAX_OUTPUT_SAMPLES = 4_000_000
#: Largest step budget of one simulation (about a microsecond per step: minutes).
MAX_STEPS = 100_000_000


class CrossoverScan(StrictModel):
    """Where the lowest hunting-free crossover is searched: the fold of the hunting cycle,
    bisected to 0.01 Hz or 0.1 % of the crossover, whichever is larger."""

    start: Q("Hz") = Field(1.0, gt=0, description="Lowest crossover searched [Hz]. Default "
                                                  "1 Hz.")
    stop: Q("Hz") = Field(30.0, gt=0, description="Highest crossover searched [Hz] (the design "
                                                  "crossover where that is higher). Default "
                                                  "30 Hz.")
    step: OptQ("Hz") = Field(None, gt=0, description="Not used (the fold is bisected, not "
                                                     "scanned on a grid); read so that a spec "
                                                     "that gives it still loads, with a "
                                                     "warning.")

    @model_validator(mode="after")
    def _ordered(self) -> "CrossoverScan":
        if self.stop <= self.start:
            raise ValueError("stop must be above start")
        return self


class Simulation(StrictModel):
    """Settings of the nonlinear simulation."""

    tolerance: float = Field(1e-6, gt=1e-12, lt=1e-2, description="Relative tolerance of the "
                                                                  "adaptive integrator. "
                                                                  "Default 1e-6.")
    output_rate: Q("Hz") = Field(1000.0, gt=0, description="Sample rate of the output traces "
                                                           "[Hz]; motion.duration x output_rate "
                                                           "at most 4e6 samples. Default 1 kHz.")
    max_steps: int = Field(2_000_000, ge=1000, le=MAX_STEPS,
                           description="Step budget per simulation. At most 1e8.")
    crossover_scan: CrossoverScan = Field(default_factory=CrossoverScan)


#: Kinds of report, with the suffix that makes each one's document id (see ReportInfo).
REPORT_KINDS = {"design": "", "sweep": "SWEEP", "study": "STUDY", "robustness": "ROBUSTNESS",
                "reconcile": "RECONCILE", "identify": "IDENTIFY", "recommend": "RECOMMEND"}


class Revision(StrictModel):
    """One entry of the revision history, oldest first."""

    revision: Text = Field(min_length=1, description="Revision label, as report.revision.")
    date: datetime.date | None = Field(None, description="Date of the revision (YYYY-MM-DD). "
                                                         "Default none.")
    description: Text = Field("", description="What changed. Default empty.")
    author: Text | None = Field(None, description="Who made the change. Default none.")


class DocumentIds(StrictModel):
    """Document ids of the other kinds of report (default: report.document_id with the kind as
    a suffix, FI-0001-SWEEP, FI-0001-STUDY, FI-0001-ROBUSTNESS, FI-0001-RECONCILE,
    FI-0001-IDENTIFY, FI-0001-RECOMMEND)."""

    sweep: Text | None = Field(None, min_length=1, description="Document id of a sweep report "
                                                              "(fi-design sweep). Default "
                                                              "DOCUMENT_ID-SWEEP.")
    study: Text | None = Field(None, min_length=1, description="Document id of the paper study's "
                                                              "report. Default DOCUMENT_ID-STUDY.")
    robustness: Text | None = Field(None, min_length=1, description="Document id of a "
                                                                   "robustness report. Default "
                                                                   "DOCUMENT_ID-ROBUSTNESS.")
    reconcile: Text | None = Field(None, min_length=1, description="Document id of a "
                                                                  "reconciliation (gap) report. "
                                                                  "Default DOCUMENT_ID-RECONCILE.")
    identify: Text | None = Field(None, min_length=1, description="Document id of an "
                                                                 "identification report. Default "
                                                                 "DOCUMENT_ID-IDENTIFY.")
    recommend: Text | None = Field(None, min_length=1, description="Document id of a "
                                                                  "recommendation report "
                                                                  "(fi-design recommend). "
                                                                  "Default DOCUMENT_ID-RECOMMEND.")


class ReportInfo(StrictModel):
    """Title block and document control of the sign-off reports. One document id per kind of
    report: the design report has document_id, every other kind document_id with the kind as
    a suffix (FI-0001-SWEEP) unless document_ids names it; the ids must differ."""

    document_id: Text = Field("FI-0001", min_length=1,
                             description="Document id of the design report; the other "
                                         "reports derive theirs from it (see document_ids).")
    revision: Text = Field("A", min_length=1,
                          description="Revision. Default the last entry of report.revisions, "
                                      "else A; with revisions it must be the last entry's.")
    status: Text = Field("draft", description="Status (draft unless given).")
    author: Text | None = Field(None, description="Prepared by.")
    checked_by: Text | None = Field(None, description="Checked by (name in the signature block).")
    approved_by: Text | None = Field(None, description="Approved by (name in the signature "
                                                      "block).")
    revisions: tuple[Revision, ...] = Field((), description="Revision history, oldest first: "
                                                            "revision, date, description, "
                                                            "author. Default none.")
    document_ids: DocumentIds = Field(default_factory=DocumentIds,
                                      description="Document ids of the other kinds of report "
                                                  "(default: document_id-KIND).")
    map: bool = Field(False, description="Add a crossover x stroke map around the design point.")

    @model_validator(mode="before")
    @classmethod
    def _revision_from_history(cls, data: Any) -> Any:
        if isinstance(data, dict) and data.get("revision") is None and data.get("revisions"):
            last = data["revisions"][-1]
            label = last.get("revision") if isinstance(last, dict) else \
                getattr(last, "revision", None)
            if isinstance(label, str):  # a label that is no text is the entry's own error
                data = {**data, "revision": label}
        return data

    @model_validator(mode="after")
    def _document_control(self) -> "ReportInfo":
        if self.revisions:
            labels = [r.revision for r in self.revisions]
            dupes = sorted({r for r in labels if labels.count(r) > 1})
            if dupes:
                raise ValueError(f"report.revisions: revision {', '.join(dupes)} listed twice")
            if self.revision != labels[-1]:
                raise ValueError(f"report.revision: '{self.revision}' is not the last entry of "
                                 f"report.revisions ('{labels[-1]}'); list the revisions oldest "
                                 "first and end with the current one, or leave "
                                 "report.revision out")
            dates = [r.date for r in self.revisions if r.date is not None]
            if dates != sorted(dates):
                raise ValueError("report.revisions: the dates must not decrease (oldest first)")
        ids: dict[str, str] = {}
        for kind in REPORT_KINDS:
            doc = self.id_for(kind)
            if doc in ids:
                raise ValueError(f"report.document_ids.{kind}: '{doc}' is already the document "
                                 f"id of the {ids[doc]} report; every kind of report needs its "
                                 "own")
            ids[doc] = kind
        return self

    def id_for(self, kind: str) -> str:
        """The document id of a kind of report.

        Parameters
        ----------
        kind : str
            ``design``, ``sweep``, ``study``, ``robustness``, ``reconcile``,
            ``identify`` (:data:`REPORT_KINDS`), or any other word for a report
            made with the library (its upper-cased suffix).

        Returns
        -------
        str
            ``document_id`` for the design report; for the others the id given
            in ``document_ids``, else ``document_id`` and the kind's suffix
            (``FI-0001-SWEEP``).
        """
        if kind == "design":
            return self.document_id
        given = getattr(self.document_ids, kind, None)
        if given:
            return given
        suffix = REPORT_KINDS.get(kind) or "".join(c if c.isalnum() else "-"
                                                   for c in kind.upper())
        return f"{self.document_id}-{suffix}"


def move_duration(mv: Move) -> float:
    """Duration of one move [s] (trapezoidal, or jerk-limited when ``jerk`` is set)."""
    return profile_duration(mv.distance, mv.velocity, mv.acceleration, mv.jerk)
