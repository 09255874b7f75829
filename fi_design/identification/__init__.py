"""Friction identification from a measured record: guideline step 1 from data (docs/interfaces.md).

:func:`identify` estimates the moving mass, Coulomb and viscous friction and a
force offset from a measured record (position and actuator force), with
standard errors, by the inverse-dynamics least squares of robot and
machine-tool identification (IDIM-LS, Gautier and Khalil; Janot et al. for the
EMPS axis):

1. **Zero-phase low-pass.** Position, force (and joint deflection) pass a
   Butterworth filter of order :data:`FILTER_ORDER` forwards and backwards
   (:func:`scipy.signal.sosfiltfilt`: no phase lag, the magnitude squared).
   Cut-off: :data:`CROSSOVER_FACTOR` times the loop's crossover when a spec is
   given (the filter must pass the closed-loop dynamics undistorted), else
   :data:`CUTOFF_FRACTION` of the sample rate; never above
   :data:`MAX_CUTOFF_FRACTION` of it. Because every term of the equation of
   motion but the sign of the velocity is linear, filtering both sides keeps
   the equation.
2. **Central differences** of the filtered position give the velocity
   (:func:`numpy.gradient`) and the acceleration (the second central
   difference ``(x[k+1] - 2 x[k] + x[k-1]) / T^2``). ``force_N`` is usually
   a command held by the controller's zero-order hold over the sample
   interval after it; the second difference of the position of a mass
   pushed by a held force is then exactly the mean of the two force samples
   around t_k (the hold equivalent of the double integrator,
   ``T^2 (z + 1) / (2 m (z - 1)^2)``), and that mean is used. Whether the
   force is held or a sampled continuous signal is decided from the data:
   the reading that fits better (:attr:`Processing.force_hold`). A
   computational delay of the spec shifts the force by interpolation.
4. **Parallel filtering and decimation.** Every regressor column, the
   nonlinear ones (sign and one-sided parts of the velocity) included, passes
   the same low-pass as the force, then :func:`scipy.signal.decimate` (a
   Hamming-window FIR low-pass without phase shift, then every n-th sample)
   with the force alike: the equation holds on the filtered data exactly,
   away from direction changes. The factor is the largest
   whose anti-alias edge (0.8 of the new Nyquist frequency) stays at or above
   the cut-off, so it removes no band the fit uses; it thins the strongly
   correlated samples.
5. **Sample selection.** Only sliding samples are used: speed above the
   velocity threshold throughout the filters' reach (the indicator of
   sliding, filtered and decimated like the data, stays within
   :data:`SLIDE_TOLERANCE` of one;
   default threshold :data:`THRESHOLD_FRACTION` of the peak speed,
   with a spec at least :data:`STRIBECK_FACTOR` times its Stribeck velocity;
   below it friction is not Coulomb plus viscous: Stribeck effect,
   presliding, sticking); the first and last :data:`EDGE_PERIODS` cut-off periods
   are dropped (filter transients).
6. **Weighted least squares** (:func:`scipy.linalg.lstsq` on
   column-normalised regressors). One equation (a rigid stage): ordinary least
   squares. Two equations (stage and cart of an isolated stage, see below):
   each equation is weighted by the inverse of its residual variance from a
   first unweighted pass (the IDIM-WLS of Gautier).
7. **Standard errors** from the residual variance, ``s^2 (A^T W A)^-1``,
   corrected for the autocorrelation of the residuals of filtered, decimated
   data by an **effective sample count** ``n_eff = n / (1 + 2 sum rho_k)``,
   the autocorrelations ``rho_k`` summed up to the first lag at which they are
   no longer positive (the initial positive sequence); the covariance is
   scaled by ``n / n_eff``. (Not a bootstrap.)

The model (docs/model.md): the actuator force u (``force_N``,
the force that acts, an injected ``disturbance_N`` included) moves the total
mass against friction and a constant offset::

    u = M a + Fc sign(v) + Fv+ max(v, 0) + Fv- min(v, 0) + offset      (symmetric form)
    u = M a + Fc+ [v > 0] - Fc- [v < 0] + Fv+ max(v, 0) + Fv- min(v, 0)  (per-direction form)

On sliding data [v > 0] + [v < 0] = 1, so the Coulomb friction per
direction and an offset are collinear: only three of the four constants are
identifiable. The two forms fit the data identically; they are two readings
of the same direction-dependent constant force (Fc+ = Fc + offset,
Fc- = Fc - offset). They differ at standstill, which sliding data do not see.

With an isolator (a spec with one and a record with ``deflection_m``): the
flexure force k d + c d' (k, c from the spec) splits the record into the
stage equation ``u - k d - c d' = m1 a1 + offset`` and the cart equation
``k d + c d' = m2 a2 + F_f(v2)``, with the cart's motion x2 = x1 - d. Without
the spec's stiffness the flexure force is unknown: only the sum of the two
equations, ``u = m1 a1 + m2 a2 + F_f(v2) + offset``, is used, with the
masses in the spec's ratio (the total is identified, its split is not).

LuGre's dynamic parameters (static friction, Stribeck velocity, bristle
stiffness) act near zero velocity, where the fit above leaves the samples
out; :mod:`.dynamic` estimates each from the part of the record that
carries it, with the estimates above fixed and their errors propagated:
static friction from the loading branches before breakaways after a stop
(one value per event), the bristle stiffness from the same branches and
from presliding cycles, the Stribeck velocity from steady sliding at low
speed (a slow velocity sweep through zero). Where the record does not hold
the excitation the parameter is reported ``identifiable: false``, with no
value and a note naming the experiment that would identify it. (A fit of
the replayed record, :func:`fi_design.simulate` with ``record=``, to the
breakaways was built and rejected: the replay of a stick-slip record is so
sensitive to the sliding friction that sub-percent errors in it, within
their standard errors, moved the static friction by many of its own,
unpropagated, standard errors.)

Modules, one job each:

- :mod:`.results`: the result types (:class:`IdentificationResult`,
  :class:`Parameter`, :class:`Fit`, :class:`Processing`, :class:`Masses`,
  :class:`Samples`, :class:`ForcePrediction`, :class:`BranchFit`,
  :class:`SweepFit`, :class:`Dynamic`) and the parameter names;
- :mod:`.preprocess`: checks of the record, filter and decimation settings,
  the joint of an isolated stage, the prepared signals (steps 1 to 5);
- :mod:`.regression`: the inverse-dynamics least squares and its standard
  errors (steps 6 and 7);
- :mod:`.events`: rests, breakaways and reversals in the record (:func:`excitation`);
- :mod:`.lugrefit`: the least-squares fits of LuGre's presliding curve and
  Stribeck curve, with the sliding friction's errors propagated;
- :mod:`.dynamic`: static friction, Stribeck velocity, bristle stiffness;
- :mod:`.specwrite`: the spec with the identified values (``--write-spec``);
- :mod:`.pipeline`: :func:`identify`, :func:`predict_force`, :func:`segment`.
"""

from .events import excitation
from .pipeline import identify, predict_force, segment
from .preprocess import processing
from ..results.identification import (DYNAMIC, FORMS, NAMES, UNITS, BranchFit, Dynamic, Excitation,
                                      Fit, ForcePrediction, IdentificationResult, Masses,
                                      Parameter, Processing, Samples, SweepFit)
from .specwrite import (identified_spec, identified_spec_text, kept_mass_message,
                        mass_kept, spec_values)

__all__ = ["identify", "IdentificationResult", "Parameter", "Fit", "Processing", "Excitation",
           "Masses", "Samples", "ForcePrediction", "predict_force", "processing", "excitation",
           "spec_values", "identified_spec", "identified_spec_text", "mass_kept",
           "kept_mass_message", "segment", "NAMES", "UNITS",
           "FORMS", "DYNAMIC", "BranchFit", "SweepFit", "Dynamic"]
