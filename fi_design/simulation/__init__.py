"""Nonlinear simulation of the stage: the run, its hunting metric, replays of records.

:mod:`~fi_design.simulation.run` simulates a spec or a model with the compiled
kernel (:func:`~fi_design.simulation.run.simulate`) along the reference motion
(:mod:`fi_design.trajectory`); :mod:`~fi_design.simulation.metrics` is the
paper's hunting metric of a trace; :mod:`~fi_design.simulation.replay` replays
a measured record through the plant.
"""
