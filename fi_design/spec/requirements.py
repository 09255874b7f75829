"""The spec's requirements section: margins, the hunting metric, robustness, the search, reserves.
"""

from __future__ import annotations

from typing import Any, Literal, Union

from pydantic import Field, field_validator, model_validator

from ..display import quantity
from .fields import OptQ, Q, StrictModel


class Hunting(StrictModel):
    """Settings of the hunting metric (paper section 2.3)."""

    window_start: Q("s") = Field(10.0, ge=0, description="Start of the counting window [s]. "
                                                         "Default 10 s.")
    window_length: Q("s") = Field(10.0, gt=0, description="Length of the window [s]. "
                                                          "Default 10 s.")
    min_distance: Q("s") = Field(0.5, gt=0, description="Minimum time between peaks [s]. "
                                                        "Default 0.5 s.")
    min_height: Q("m") = Field(1e-4, gt=0, description="Minimum peak height of x1 - r [m]. "
                                                       "Default 0.1 mm.")
    settle_band: Q("m") = Field(1e-5, gt=0, description="Error band for 'settled' and the "
                                                        "settling time [m], below "
                                                        "min_height. Default 10 µm.")
    horizon: Q("s") = Field(300.0, gt=0, le=1e5,
                            description="Stage-level hunting: the longest time after a move to "
                                        "wait for the stage to come to rest or repeat a cycle "
                                        "[s]; runs stop as soon as either is certain. Default "
                                        "300 s.")

    @model_validator(mode="after")
    def _band_below_cycles(self) -> "Hunting":
        if self.settle_band >= self.min_height:
            from ..display import quantities

            band, height = quantities((self.settle_band, self.min_height), "m", 6)
            raise ValueError(
                f"settle_band = {band} is not below min_height = "
                f"{height}: a cycle within the band would count as rest "
                "(the stage judged settled while it hunts); give a band below the least peak "
                "height that counts as a cycle")
        return self


class Ripple(StrictModel):
    """Friction that varies along the rail: Fs and Fc times 1 + a sin(2 pi x2 / wavelength + phase)."""

    amplitude: Q("1") = Field(gt=0, lt=1, description="Relative amplitude a of Fs and Fc along "
                                                      "the rail [-] (e.g. 10 %).")
    wavelength: Q("m") = Field(gt=0, description="Spatial period of the variation [m].")


class Robustness(StrictModel):
    """The scatter under which the design must stay hunting-free (part of the verdict).

    The design command draws 'samples' variants of the stage (friction, and
    optionally the masses, the joint's stiffness and the loop delay), each a
    draw of every scattered value together, simulates the stage as specified
    after every move of its family, and compares the probability that some
    move does not settle with 'hunting_probability'. Friction is drawn
    jointly: Coulomb friction Fc and the gap Fs - Fc, each clipped at zero, so
    static friction is never below Coulomb friction and no draw is dropped.
    """

    coulomb: Q("1") = Field(0.2, ge=0, lt=1, description="Scatter of Coulomb friction Fc, a "
                                                         "fraction of its value [-]: the "
                                                         "standard deviation of a normal draw, "
                                                         "the half-width of a uniform one. "
                                                         "Default 20 %.")
    gap: Q("1") = Field(0.2, ge=0, lt=1, description="Scatter of the friction gap Fs - Fc, a "
                                                     "fraction of its value [-]; static "
                                                     "friction is Fc plus the drawn gap. "
                                                     "Default 20 %.")
    mass: Q("1") = Field(0.05, ge=0, lt=0.5, description="Scatter of the true stage and cart "
                                                         "masses, each a fraction of its value "
                                                         "[-]; the controller keeps its tuning. "
                                                         "Default 5 %.")
    stiffness: OptQ("1") = Field(None, ge=0, lt=0.5,
                                     description="Scatter of the joint's drive stiffness, a "
                                                 "fraction [-]. Default: the flexure's stock "
                                                 "thickness tolerance (k goes with t^3), 5 % "
                                                 "without a flexure section.")
    delay: Q("1") = Field(0.2, ge=0, lt=1, description="Scatter of the loop delay "
                                                       "(controller.delay), a fraction of its "
                                                       "value [-]. Default 20 %.")
    distribution: Literal["normal", "uniform"] = Field(
        "normal", description="Distribution of the scatter: 'normal' (default) or 'uniform'.")
    ripple: Ripple | None = Field(None, description="Optional friction ripple along the rail "
                                                    "(every sample draws its phase); null: "
                                                    "none.")
    samples: int = Field(100, ge=0, le=100_000, description="Samples drawn (each simulated with "
                                                            "and without the isolator, a few ms "
                                                            "each); 0 skips the robustness check. "
                                                            "Default 100.")
    seed: int = Field(0, ge=0, description="Seed of the draws: the same seed gives the same "
                                           "samples. Default 0.")
    hunting_probability: Q("1") = Field(0.05, ge=0, le=1, description="Largest acceptable "
                                                                      "probability of hunting "
                                                                      "[-]. Default 5 %.")
    confidence: float = Field(0.95, gt=0, lt=1, description="Level of the Wilson interval of the "
                                                            "probability [-]. Default 0.95.")


class RecommendBounds(StrictModel):
    """Bounds of the recommendation's search (``fi-design recommend``); null: the default range."""

    stroke: Union[tuple[Q("m"), Q("m")], None] = Field(
        None, description="[min, max] stroke [m], e.g. the travel the mechanism allows; default "
                          "a third to three times the spec's stroke (0.1 to 1 mm without one).")
    stiffness: Union[tuple[Q("N/m"), Q("N/m")], None] = Field(
        None, description="[min, max] drive stiffness [N/m]; default up to k_max.")
    crossover: Union[tuple[Q("Hz"), Q("Hz")], None] = Field(
        None, description="[min, max] controller crossover [Hz] (a spec tuned by the rule); "
                          "default up to the achievable crossover.")
    filters: bool = Field(
        False, description="Whether the search may add a notch to controller.filters at the "
                           "parasitic mode that limits the spec's loop, where the notch lifts "
                           "the achievable crossover (a spec tuned by the rule).")

    @field_validator("stroke", "stiffness", "crossover")
    @classmethod
    def _ordered(cls, pair: Any, info: Any) -> Any:
        if pair is not None and not 0 < pair[0] <= pair[1]:
            unit = {"stroke": "m", "stiffness": "N/m", "crossover": "Hz"}[info.field_name]
            raise ValueError(f"must be [min, max] with 0 < min <= max, got [{quantity(pair[0], unit)}"
                             f", {quantity(pair[1], unit)}] (a number without a unit is read in "
                             f"{unit})")
        return pair


class Reserve(StrictModel):
    """Reserves a recommended design keeps beyond the requirements (``fi-design recommend``).

    The recommendation's loop meets the margins with these added, its
    crossover stays at most 'crossover' times the achievable one, and it
    passes (no move hunts, margins met) with the masses, the computed modes and
    the delay off by these fractions and the drive stiffness at its stock
    tolerance.
    """

    gain_margin: Q("dB") = Field(1.0, ge=0, description="Gain margin beyond "
                                                        "requirements.gain_margin [dB]. "
                                                        "Default 1 dB.")
    phase_margin: Q("deg") = Field(5.0, ge=0, lt=90, description="Phase margin beyond "
                                                                 "requirements.phase_margin "
                                                                 "[deg]. Default 5 deg.")
    crossover: Q("1") = Field(0.95, gt=0, le=1, description="The crossover at most this times "
                                                          "the achievable one [-]. Default "
                                                          "0.95.")
    mass: Q("1") = Field(0.15, ge=0, lt=0.5, description="The design passes with the masses "
                                                        "this fraction off, either way [-]. "
                                                        "Default 15 %.")
    modes: Q("1") = Field(0.10, ge=0, lt=0.5, description="... and with the computed modes this "
                                                         "fraction lower [-]. Default 10 %.")
    delay: Q("1") = Field(0.5, ge=0, description="... and with the loop delay this fraction "
                                                "longer [-]. Default 50 %.")


class Positioning(StrictModel):
    """What the stage is for: settling after each move of the family, and the error it rests at.

    Judged over every move of ``motion.family`` (and the spec's own motion) of
    the spec's own plant: a stage that never hunts can still fail it.
    """

    band: OptQ("m") = Field(None, gt=0, description="Settle band on |x1 - r| [m]: in position "
                                                     "once the error stays inside it. Default: "
                                                     "requirements.hunting.settle_band.")
    settle_time: OptQ("s") = Field(None, gt=0, description="Longest time after the end of each "
                                                            "move until the error stays within "
                                                            "the band [s]; null: not required.")
    static_error: OptQ("m") = Field(None, ge=0, description="Largest error |x1 - r| the stage "
                                                             "may rest at after each move [m]; "
                                                             "null: not required.")

    @model_validator(mode="after")
    def _something(self) -> "Positioning":
        if self.settle_time is None and self.static_error is None:
            raise ValueError("give settle_time, static_error or both: a band alone requires "
                             "nothing")
        return self


class Requirements(StrictModel):
    """Design requirements and metric settings."""

    friction_gap: Q("N") = Field(1.0, gt=0, description="Fs - Fc above which hunting is a risk "
                                                        "[N]. Default 1 N (paper).")
    parasitic_separation: float = Field(3.0, ge=1, description="Parasitic modes must lie above "
                                                               "this times the loop's "
                                                               "crossover (the highest 0 dB "
                                                               "crossing of the limit cases, "
                                                               "which may lie above "
                                                               "controller.crossover). "
                                                               "Default 3.")
    phase_margin: Q("deg") = Field(30.0, ge=0, lt=180, description="Minimum phase margin "
                                                                  "[deg]. Default 30 deg.")
    gain_margin: Q("dB") = Field(6.0, ge=0, description="Minimum gain margin [dB]. Default 6 dB.")
    modulus_margin: float | None = Field(None, gt=0, le=1, description="Minimum modulus margin "
                                                                       "min|1 + L| [-]; null: "
                                                                       "not required.")
    hunting_margin: float = Field(1.2, ge=1, description="The design crossover must lie at "
                                                         "least this factor above the "
                                                         "stage-level hunting-free crossover "
                                                         "(the fold of the hunting cycle) [-]. "
                                                         "Default 1.2.")
    reserve: Reserve = Field(default_factory=lambda: Reserve(),
                             description="Reserves a recommended design keeps beyond the "
                                         "requirements.")
    end_stop_force: OptQ("N") = Field(None, gt=0, description="Largest contact force the "
                                                              "isolator's end stop may see over "
                                                              "the move family [N]; null: "
                                                              "reported, not judged.")
    buckling_factor: float = Field(3.0, ge=1, description="The flexure guide's buckling load "
                                                          "must be at least this times the "
                                                          "weight it carries [-]. Default 3.")
    stiffness_safety: float = Field(1.0, ge=1, description="k_max = Fs / (safety * stroke). "
                                                           "Default 1 (the paper's rule).")
    hunting: Hunting = Field(default_factory=Hunting)
    robustness: Robustness = Field(default_factory=Robustness)
    positioning: Positioning | None = Field(None, description="Settle time and static error "
                                                             "after every move of the family "
                                                             "(optional).")
    recommend: RecommendBounds = Field(default_factory=RecommendBounds,
                                       description="Bounds of the recommendation's search.")
