"""The loop as linear models: the four limit cases, their margins, the notch, the responses.

:mod:`~fi_design.loop.linear` builds the limit-case plants and the loop of each
with python-control and reads every 0 dB and -180 deg crossing;
:mod:`~fi_design.loop.achievable` scans the crossover for the highest at which
every case keeps its margins (the achievable crossover);
:mod:`~fi_design.loop.notch` finds the parasitic mode that limits the achievable
crossover and what a notch there would allow; :mod:`~fi_design.loop.responses`
computes the frequency responses the report draws (dense at every resonance,
sampled loops up to Nyquist).
"""
