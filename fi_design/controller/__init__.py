"""The controller as the drive runs it: its polynomials, filters, sampled form and units.

A small package with one job a module:

- :mod:`.pid`: the tuning rule, the PID's gains from the crossover and the
  moving mass (step 4), and its forms;
- :mod:`.handoff`: the hand-off, the spec's controller written with the gains
  a drive takes;
- :mod:`.filters`: the drive's notch and low-pass filters as polynomials in s
  and, sampled, as biquads by the Tustin rule prewarped at their frequency;
- :mod:`.polynomials`: the loop's controller C(s), the PID in series with the
  filter chain, as the linear analysis takes it;
- :mod:`.discrete`: the sampled controller a drive computes each period (the
  PID's difference equation and the filters' biquads) and its C(z);
- :mod:`.drive`: the gains in the drive's own units (encoder counts, amperes).

Plain numpy on the values of :mod:`fi_design.results.controller`; no
python-control (the tests hold the sampled forms against its ``c2d``).
"""

from __future__ import annotations

from .discrete import DiscreteController, discrete_controller
from .drive import drive_gains
from .filters import chain_polynomials, filter_polynomials, tustin_biquad
from .polynomials import controller_polynomials, pid_polynomials, reference_polynomials

__all__ = ["DiscreteController", "discrete_controller", "drive_gains", "chain_polynomials",
           "filter_polynomials", "tustin_biquad", "controller_polynomials", "pid_polynomials",
           "reference_polynomials"]
