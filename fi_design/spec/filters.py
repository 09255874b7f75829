"""The controller's filter chain and the drive's units, key for key as in the YAML file.

``controller.filters`` is a drive's filter chain: notch and low-pass filters in
series with the PID, acting on its output (the current command), in the order
given. ``controller.drive`` gives the drive's own units, so that the hand-off
prints the gains in encoder counts and amperes beside SI.

A notch ``N(s) = (s^2 + 2 zeta_z w s + w^2) / (s^2 + 2 zeta_p w s + w^2)``,
``w = 2 pi frequency``, is given by its -3 dB ``width`` (``zeta_p = width / (2
frequency)``, the width of the full notch) and, optionally, its ``depth``
(the attenuation at its centre, ``zeta_z = zeta_p 10^(-depth/20)``; default a
full notch, ``zeta_z = 0``), or by the ``damping`` pair ``[zeta_z, zeta_p]``.
A low-pass is ``w / (s + w)`` (order 1) or ``w^2 / (s^2 + 2 damping w s + w^2)``
(order 2).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, Union

from pydantic import Discriminator, Field, Tag, model_validator

from ..display import number, quantity
from ..results.controller import DEFAULT_FILTER_NAMES
from .fields import OptQ, Q, StrictModel, Text

__all__ = ["Notch", "LowPass", "FilterEntry", "Drive", "FILTER_TYPES", "BUTTERWORTH"]

#: Damping of a second-order low-pass when the spec gives none: Butterworth, 1 / sqrt(2).
BUTTERWORTH = 0.7071067811865476


class Notch(StrictModel):
    """A notch filter: ``(s^2 + 2 zeta_z w s + w^2) / (s^2 + 2 zeta_p w s + w^2)``."""

    type: Literal["notch"] = Field(description="notch")
    name: Text = Field(DEFAULT_FILTER_NAMES["notch"], description="Label used in reports.")
    frequency: Q("Hz") = Field(gt=0, description="Centre frequency [Hz].")
    width: OptQ("Hz") = Field(None, gt=0, description="-3 dB bandwidth of the full notch [Hz]: "
                                                       "pole damping width / (2 frequency). "
                                                       "Give it or damping.")
    depth: OptQ("dB") = Field(None, gt=0, description="Attenuation at the centre [dB], with "
                                                      "width. Default a full notch (undamped "
                                                      "zeros).")
    damping: Union[tuple[float, float], None] = Field(
        None, description="[zeta of the zeros, zeta of the poles] [-], 0 <= zeros < poles <= "
                          "2; instead of width and depth.")

    @model_validator(mode="after")
    def _width_or_damping(self) -> "Notch":
        if (self.width is None) == (self.damping is None):
            raise ValueError("give the notch's width (and optionally its depth) or its damping "
                             "pair [zeta of the zeros, zeta of the poles], not both")
        if self.damping is not None:
            if self.depth is not None:
                raise ValueError("depth goes with width; with a damping pair the zeros' "
                                 "damping sets the depth")
            zz, zp = self.damping
            if not 0.0 <= zz < zp <= 2.0:
                raise ValueError("damping must be [zeta of the zeros, zeta of the poles] with "
                                 f"0 <= zeros < poles <= 2, got [{number(zz, 6)}, {number(zp, 6)}]")
        elif self.width > 4.0 * self.frequency:
            raise ValueError(f"width {quantity(self.width, 'Hz', 6)} is more than 4 times the "
                             f"frequency {quantity(self.frequency, 'Hz', 6)} (pole damping above "
                             "2)")
        return self

    @property
    def zeta_pole(self) -> float:
        """Damping of the notch's poles [-]."""
        return self.damping[1] if self.damping is not None else self.width / (2 * self.frequency)

    @property
    def zeta_zero(self) -> float:
        """Damping of the notch's zeros [-] (0: a full notch)."""
        if self.damping is not None:
            return self.damping[0]
        return 0.0 if self.depth is None else self.zeta_pole * 10.0 ** (-self.depth / 20.0)


class LowPass(StrictModel):
    """A low-pass filter: ``w / (s + w)`` or ``w^2 / (s^2 + 2 damping w s + w^2)``."""

    type: Literal["low_pass"] = Field(description="low_pass")
    name: Text = Field(DEFAULT_FILTER_NAMES["low_pass"], description="Label used in reports.")
    frequency: Q("Hz") = Field(gt=0, description="Corner frequency [Hz].")
    order: Literal[1, 2] = Field(2, description="1 or 2. Default 2.")
    damping: float | None = Field(None, gt=0, le=2, description="Damping ratio of a "
                                                                "second-order low-pass [-]. "
                                                                "Default 1/sqrt(2) "
                                                                "(Butterworth).")

    @model_validator(mode="after")
    def _damping_of_order_2(self) -> "LowPass":
        if self.order == 1 and self.damping is not None:
            raise ValueError("a first-order low-pass has no damping; give order: 2 or leave "
                             "damping out")
        return self


#: The filter types ``controller.filters`` knows.
FILTER_TYPES = {"notch": Notch, "low_pass": LowPass}


def _filter_tag(value: Any) -> str | None:
    if isinstance(value, dict):
        return value.get("type")
    return getattr(value, "type", None)


FilterEntry = Annotated[
    Union[tuple(Annotated[m, Tag(n)] for n, m in FILTER_TYPES.items())],
    Discriminator(_filter_tag, custom_error_type="unknown_filter",
                  custom_error_message="unknown filter type; known: " + ", ".join(FILTER_TYPES)),
]


class Drive(StrictModel):
    """The drive's units: the gains in encoder counts and amperes beside SI (the hand-off)."""

    motor_constant: Q("N/A") = Field(gt=0, description="Force constant of the motor [N/A].")
    encoder_resolution: Q("m") = Field(gt=0, description="Length of one encoder count [m], "
                                                         "after any interpolation.")
    current_scaling: OptQ("A") = Field(None, gt=0, description="Amperes per unit of the "
                                                               "drive's current command [A]. "
                                                               "Default 1 A: gains in A per "
                                                               "count.")
