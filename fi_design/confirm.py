"""Nonlinear confirmation of the guideline's verdict (the design command's last part).

The guideline's four steps are linear and static. This module simulates the
stage with friction, with and without the isolator, at the design crossover
(paper section 2.3 and Figure 5), and adds what a reviewer wants to know:

- the verdict of each plant from the hunting metric (``settled``,
  ``hunting``, ``stuck`` or ``undetermined``);
- the lowest crossover at which each plant stops hunting, from a scan with
  the simulation (the paper's headline: the isolator needs far less
  bandwidth, 5 Hz against 14-20 Hz);
- where the cart lands: the joint deflection at rest after the move and the
  flexure force there against Fs. The paper's rule k * stroke < Fs is
  sufficient but conservative; the force the cart actually sees at rest is
  k * min(stroke, landing deflection), and once the landing deflection
  reaches the stroke the limiter carries the cart and hunting returns;
- a cross-check with the other friction model (LuGre against the
  Karnopp-type switch model), flagged when the verdicts disagree.

A spec without an isolator is confirmed against the isolator step 3 suggests
(:func:`fi_design.guideline.isolator_advice`), so the comparison is always
"with" against "without". Only the spec's own plant is judged (its checks
PASS or FAIL): the isolated one when the spec has an isolator, else the stage
without. The other plant is information, and for a spec without isolator a
recommendation (:class:`~fi_design.results.design.Recommendation`), never a
reason to pass.

A loop without integrator (``controller.gains.ki: 0`` or
``integrator_ratio: .inf``) cannot hunt by the paper's mechanism: it comes to
rest with a static error of up to (Fc + |offset|) / kp. At rest within that
error its outcome is ``static_error``, not ``stuck``
(:class:`~fi_design.results.design.PlantVerdict`).
"""

from __future__ import annotations

import numpy as np

from . import spec as _spec
from .display import quantities, quantity
from .errors import ArgumentError
from .results import Check, Status, frozen_array
from .results.design import Confirmation, CrossoverScan, Landing, PlantVerdict
from .results.simulation import SimulationResult
from .simulation import simulate

PLANTS = ("isolated", "non_isolated")


def _hunts(v: PlantVerdict) -> bool:
    return v.metrics.verdict == "hunting"


def scan_crossover(spec: _spec.Spec, isolated: bool, start: float | None = None,
                   stop: float | None = None, step: float | None = None,
                   progress=None) -> CrossoverScan:
    """Simulate a crossover grid and find the lowest crossover that stays hunting-free.

    Parameters
    ----------
    spec : Spec
        The design spec (grid from ``spec.simulation.crossover_scan`` unless
        given).
    isolated : bool
        Which plant.
    start, stop, step : float, optional
        Grid [Hz].
    progress : callable, optional
        Called with a short message before each simulation.
    """
    cfg = spec.simulation.crossover_scan
    start = cfg.start if start is None else start
    stop = cfg.stop if stop is None else stop
    step = cfg.step if step is None else step
    grid = np.arange(start, stop + 0.5 * step, step)
    done: list[tuple[float, str, int]] = []
    plant = "with isolator" if isolated else "without isolator"
    minimum = None
    for fc in grid[::-1]:
        if progress is not None:
            progress(f"scanning the crossover {plant}: {fc:g} Hz")
        m = simulate(spec, isolated=isolated, crossover=float(fc)).metrics
        done.append((float(fc), m.verdict, m.hunting_cycles))
        if m.verdict != "settled":
            break
        minimum = float(fc)
    done.reverse()
    return CrossoverScan(plant="isolated" if isolated else "non_isolated",
                         crossovers=frozen_array([d[0] for d in done]),
                         verdicts=tuple(d[1] for d in done),
                         hunting_cycles=frozen_array([d[2] for d in done], dtype=int),
                         minimum=minimum, resolution=float(step),
                         grid=(float(start), float(stop), float(step)))


def landing(spec: _spec.Spec, result: SimulationResult) -> Landing:
    """Landing deflection and flexure force of an isolated simulation."""
    k = _spec.drive_stiffness(spec)
    s = spec.isolator.stroke
    d = float(result.deflection[-1])
    return Landing(deflection=d, stroke=s, stiffness=k, force=k * min(abs(d), s),
                   static_friction=spec.friction.static, on_limiter=abs(d) >= s,
                   rule_force=k * s)


def with_isolator(spec: _spec.Spec, stroke: float, stiffness: float) -> _spec.Spec:
    """The spec with an isolator of the given stroke [m] and stiffness [N/m] added."""
    iso = _spec.Isolator(stiffness=stiffness, stroke=stroke)
    return spec.model_copy(update={"isolator": iso})


def static_error_bound(spec: _spec.Spec) -> float | None:
    """The static error a loop without integrator may leave against friction [m].

    ``(max(Fc, Fc_negative) + |offset|) / kp``: the cart comes to rest once the
    loop's force no longer overcomes the sliding friction (and the load
    offset); None when the loop integrates.

    Parameters
    ----------
    spec : Spec
        The design spec.

    Returns
    -------
    float or None
    """
    from .pid import control_law

    f = spec.friction
    fc = max(f.coulomb, f.coulomb_negative if f.coulomb_negative is not None else f.coulomb)
    return control_law(spec).static_error(fc + abs(f.offset))


def _other_model(spec: _spec.Spec) -> _spec.Spec:
    other = "switch" if spec.friction.model == "lugre" else "lugre"
    return spec.model_copy(update={"friction": spec.friction.model_copy(update={"model": other})})


def confirm(spec: _spec.Spec, suggestion: tuple[float, float] | None = None,
            progress=None) -> Confirmation:
    """Simulate both plants, scan the crossover, check the landing and cross-check.

    Parameters
    ----------
    spec : Spec
        The design spec.
    suggestion : (stroke, stiffness), optional
        Isolator to simulate when the spec has none [m, N/m]; required then.
    progress : callable, optional
        Called with a short message as the work proceeds (about 130
        simulations of a few ms each).

    Returns
    -------
    Confirmation
    """
    suggested = spec.isolator is None
    if suggested:
        if suggestion is None:
            raise ArgumentError("a spec without isolator needs a suggested (stroke, stiffness)")
        spec_iso = with_isolator(spec, *suggestion)
    else:
        spec_iso = spec
    def say(text: str) -> None:
        if progress is not None:
            progress(text)

    say("simulating the stage with and without the isolator ...")
    bound = static_error_bound(spec)
    res_iso = simulate(spec_iso, isolated=True)
    res_non = simulate(spec, isolated=False)
    iso = PlantVerdict.of("isolated", res_iso, bound)
    non = PlantVerdict.of("non_isolated", res_non, bound)
    scans = {"isolated": scan_crossover(spec_iso, True, progress=progress),
             "non_isolated": scan_crossover(spec, False, progress=progress)}
    cfg = spec.simulation.crossover_scan
    mins = {"isolated": scans["isolated"].minimum, "non_isolated": scans["non_isolated"].minimum,
            "resolution": cfg.step, "scan": [cfg.start, cfg.stop]}
    land = landing(spec_iso, res_iso)
    say("cross-checking with the other friction model ...")
    other_iso = PlantVerdict.of("isolated", simulate(_other_model(spec_iso), isolated=True),
                                bound)
    other_non = PlantVerdict.of("non_isolated", simulate(_other_model(spec), isolated=False),
                                bound)
    agree = _hunts(other_iso) == _hunts(iso) and _hunts(other_non) == _hunts(non)
    checks = _checks(spec, iso, non, mins, land, agree, other_iso, other_non, suggested)
    return Confirmation(isolated=iso, non_isolated=non, min_hunting_free_crossover=mins,
                        scans=scans, landing=land,
                        cross_check={"isolated": other_iso, "non_isolated": other_non},
                        models_agree=agree, suggested_isolator=suggested, checks=tuple(checks),
                        results={"isolated": res_iso, "non_isolated": res_non})


def _plant_text(v: PlantVerdict, label: str, fc: float) -> str:
    m = v.metrics
    if v.outcome == "static_error":
        rest, bound = quantities((abs(m.final_error), v.static_error_bound), "m", 3)
        return (f"{label} at {fc:g} Hz: at rest {rest} from its target, within the static "
                f"error (Fc + |offset|) / kp = {bound} of a loop without integrator (not stuck)")
    return f"{label} at {fc:g} Hz: {m.verdict} ({m.reason})"


def _checks(spec, iso, non, mins, land, agree, other_iso, other_non, suggested) -> list[Check]:
    """The confirmation's checks: the spec's own plant judged, the other one information."""
    fc = _spec.design_crossover(spec)
    step = "simulation (paper section 2.3)"
    integrates = iso.static_error_bound is None
    if suggested:
        own_key, labels = "non_isolated", {
            "non_isolated": "the stage as specified (without isolator)",
            "isolated": "with the suggested isolator (a recommendation, not the hardware)"}
    else:
        own_key, labels = "isolated", {
            "isolated": "the isolated design as specified",
            "non_isolated": "without the isolator (for comparison)"}
    plants = {"isolated": iso, "non_isolated": non}
    out = []
    for key in ("isolated", "non_isolated"):
        v = plants[key]
        judged = key == own_key
        out.append(Check(f"simulation_{key}", v.acceptable if judged else None,
                         float(v.metrics.hunting_cycles), 0.0 if judged else None, "cycles",
                         _plant_text(v, labels[key], fc), step))
    res = mins["resolution"]
    for key in ("isolated", "non_isolated"):
        m = mins[key]
        judged = key == own_key
        scan = (f"scan {mins['scan'][0]:g} to {mins['scan'][1]:g} Hz" if m is None
                else f"scan resolution {res:g} Hz")
        text = (f"{labels[key]}: " + ("hunting-free nowhere in the scan" if m is None
                                      else f"hunting-free from {m:g} Hz")
                + f" ({scan}); design crossover {fc:g} Hz")
        if not judged:
            out.append(Check(f"min_crossover_{key}", None, m, None, "Hz", text, step))
        elif not integrates:
            out.append(Check(f"min_crossover_{key}", None, m, fc, "Hz", text + (
                "; the loop has no integrator, so below that crossover it rests with a static "
                "error rather than hunting"), step))
        elif m is None:
            out.append(Check(f"min_crossover_{key}", False, m, fc, "Hz", text + (
                ": it does not settle even at the top of the scan"), step, status=Status.WARN))
        elif fc >= m:
            out.append(Check(f"min_crossover_{key}", True, m, fc, "Hz", text, step))
        else:
            out.append(Check(f"min_crossover_{key}", False, m, fc, "Hz", text + (
                ": the design crossover lies below the boundary, where hunting comes and goes"),
                step, status=Status.WARN))
    mn = non.metrics
    if mn.verdict != "hunting":
        out.append(Check("isolator_needed", None, None, None, "-",
                         f"the stage without isolator does not hunt at {fc:g} Hz "
                         f"({non.outcome.replace('_', ' ')}): the isolator is not needed at "
                         "this crossover", step))
    if land is not None:
        ok = (not land.on_limiter) and land.force < land.static_friction
        where = "the suggested isolator's cart" if suggested else "the cart"
        out.append(Check(
            "landing_force", None if suggested else ok, land.force, land.static_friction, "N",
            f"{where} lands at {quantity(land.deflection, 'm', 3)} joint deflection "
            f"({'on the limiter' if land.on_limiter else 'inside the stroke'}): flexure force "
            f"k min(|d|, s) = {land.force:.3g} N against Fs = {land.static_friction:.3g} N "
            f"(the rule's bound k s = {land.rule_force:.3g} N)", "step 3 refinement: landing"))
    if not agree:
        other = {"isolated": other_iso, "non_isolated": other_non}
        own_differs = _hunts(other[own_key]) != _hunts(plants[own_key])
        out.append(Check(
            "friction_model_cross_check", None, None, None, "-",
            f"the {other_iso.friction_model} model disagrees: isolated "
            f"{other_iso.metrics.verdict}, without isolator {other_non.metrics.verdict}"
            + ("" if own_differs else " (not on the stage as specified)"), step,
            status=Status.WARN if own_differs else Status.INFO))
    return out
