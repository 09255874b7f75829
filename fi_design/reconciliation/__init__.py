"""Reconciliation: where do model and measurement disagree, and which effect is missing?

:func:`reconcile` compares the nominal model of a spec with a measured record
(:mod:`fi_design.measured`), names the physical effect of the catalogue
(docs/effects.md, :mod:`fi_design.effects`) that explains the
disagreement, fits its parameters with honest uncertainties, and shows the gap
before and after; or answers ``none``, and says when the model's structure,
not a missing effect, is the problem.

The work is split by job:

=================  ==========================================================
module             job
=================  ==========================================================
``lattice``        the lattice of the measured positions (quantization read
                   from the data: step, share of samples on it, a binomial test)
``noise``          noise per channel; autocorrelation time and effective samples
``records``        evidence in the record; thinned to the rate the model needs
``comparison``     replay on the record, segments, the weighted residual
``signatures``     what each effect would leave in the nominal residual
``spaces``         each candidate's coordinates, bounds, starts and references
``fitting``        bounded least squares, widened bounds, joint refinement
``significance``   honest uncertainties and the tests a finding must pass
``gaps``           gap metrics before and after
``diagnosis``      structure diagnosis when no effect explains the gap
``results``        (in :mod:`fi_design.results.reconciliation`) the result values
``specout``        spec entries and the corrected spec file
``workflow``       :func:`reconcile`, stringing the steps together
=================  ==========================================================

The library never prints; pass ``progress`` to follow the work.
"""

from .comparison import MAX_POINTS
from .noise import NOISE_FLOOR, estimate_noise
from ..results.reconciliation import (Candidate, Cause, Diagnosis, EffectStep, GapMetric,
                                      Lattice, ModelTrace, NoiseLevels, ReconcileResult,
                                      SearchRound, Segment, Signature)
from .significance import THRESHOLD
from .specout import entry_input, fixed_spec_text, make_entry, spec_with_entries
from .workflow import reconcile

__all__ = ["reconcile", "ReconcileResult", "Candidate", "Cause", "Diagnosis", "EffectStep",
           "GapMetric", "Lattice", "ModelTrace", "NoiseLevels", "SearchRound", "Segment",
           "Signature", "fixed_spec_text", "spec_with_entries", "make_entry", "entry_input",
           "estimate_noise", "THRESHOLD", "MAX_POINTS", "NOISE_FLOOR"]
