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
"with" against "without".
"""

from __future__ import annotations

import numpy as np

from . import spec as _spec
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
    res_iso = simulate(spec_iso, isolated=True)
    res_non = simulate(spec, isolated=False)
    iso = PlantVerdict.of("isolated", res_iso)
    non = PlantVerdict.of("non_isolated", res_non)
    scans = {"isolated": scan_crossover(spec_iso, True, progress=progress),
             "non_isolated": scan_crossover(spec, False, progress=progress)}
    cfg = spec.simulation.crossover_scan
    mins = {"isolated": scans["isolated"].minimum, "non_isolated": scans["non_isolated"].minimum,
            "resolution": cfg.step, "scan": [cfg.start, cfg.stop]}
    land = landing(spec_iso, res_iso)
    say("cross-checking with the other friction model ...")
    other_iso = PlantVerdict.of("isolated", simulate(_other_model(spec_iso), isolated=True))
    other_non = PlantVerdict.of("non_isolated", simulate(_other_model(spec), isolated=False))
    agree = _hunts(other_iso) == _hunts(iso) and _hunts(other_non) == _hunts(non)
    checks = _checks(spec, iso, non, mins, land, agree, other_iso, other_non, suggested)
    return Confirmation(isolated=iso, non_isolated=non, min_hunting_free_crossover=mins,
                        scans=scans, landing=land,
                        cross_check={"isolated": other_iso, "non_isolated": other_non},
                        models_agree=agree, suggested_isolator=suggested, checks=tuple(checks),
                        results={"isolated": res_iso, "non_isolated": res_non})


def _fmt_f(f: float | None) -> str:
    return "not found" if f is None else f"{f:g} Hz"


def _checks(spec, iso, non, mins, land, agree, other_iso, other_non, suggested) -> list[Check]:
    fc = _spec.design_crossover(spec)
    step = "simulation (paper section 2.3)"
    label = "suggested isolator" if suggested else "isolated design"
    mi, mn = iso.metrics, non.metrics
    out = [
        Check("simulation_isolated", mi.verdict == "settled", float(mi.hunting_cycles), 0.0,
              "cycles", f"{label} at {fc:g} Hz: {mi.verdict} ({mi.reason})", step),
        Check("simulation_non_isolated", None, float(mn.hunting_cycles), None, "cycles",
              f"without isolator at {fc:g} Hz: {mn.verdict} ({mn.reason})", step),
    ]
    m_iso, m_non = mins["isolated"], mins["non_isolated"]
    res = mins["resolution"]
    out.append(Check(
        "min_crossover_isolated", None if m_iso is None else fc >= m_iso, m_iso, fc, "Hz",
        f"{label} stays hunting-free from {_fmt_f(m_iso)} (scan resolution {res:g} Hz); "
        f"design crossover {fc:g} Hz", step))
    out.append(Check(
        "min_crossover_non_isolated", None, m_non, None, "Hz",
        f"without isolator hunting-free from {_fmt_f(m_non)} (scan resolution {res:g} Hz)",
        step))
    if mn.verdict != "hunting":
        out.append(Check("isolator_needed", None, None, None, "-",
                         f"the stage without isolator does not hunt at {fc:g} Hz "
                         f"({mn.verdict}): the isolator is not needed at this crossover", step))
    if land is not None:
        ok = (not land.on_limiter) and land.force < land.static_friction
        out.append(Check(
            "landing_force", ok, land.force, land.static_friction, "N",
            f"the cart lands at {land.deflection * 1e6:.3g} um joint deflection "
            f"({'on the limiter' if land.on_limiter else 'inside the stroke'}): flexure force "
            f"k min(|d|, s) = {land.force:.3g} N against Fs = {land.static_friction:.3g} N "
            f"(the rule's bound k s = {land.rule_force:.3g} N)", "step 3 refinement: landing"))
    if not agree:
        out.append(Check(
            "friction_model_cross_check", None, None, None, "-",
            f"the {other_iso.friction_model} model disagrees: isolated "
            f"{other_iso.metrics.verdict}, without isolator {other_non.metrics.verdict}", step,
            status=Status.WARN))
    return out
