"""The design guideline: the four steps, the verdict on the simulated stage, the conclusion.

:mod:`~fi_design.guideline.steps` runs the four steps (friction gap, achievable
crossover, maximum drive stiffness, PID) on a :class:`~fi_design.model.Model`
and, through :func:`~fi_design.guideline.evaluate.evaluate`, the nonlinear
confirmation; :mod:`~fi_design.guideline.verdict` judges the design on the
simulated stage (the hunting margin, robustness, the sign-off's verdict).
The recommendation (:mod:`fi_design.recommend`) and the sign-off that joins
both (:mod:`fi_design.signoff`) sit above this package.
"""
