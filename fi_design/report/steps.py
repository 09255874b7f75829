"""The four guideline steps of a design report, with their equations."""

from __future__ import annotations

import itertools
import math
from typing import Any

from ..display import NBSP
from ..effects import delay_words, simulated_only
from ..results.linear import phase_margin_judged
from .equations import equation
from .filters import num, qty, tex_num, tex_qty

__all__ = ["guideline_steps"]


def _case_number(xo: Any, name: str) -> int:
    """The paper's number of a limit case of step 2 (1 to 4)."""
    return next((i for i, c in enumerate(xo.cases, 1) if c.name == name), 0)


def guideline_steps(result: Any, figures: bool = True) -> list[dict]:
    """The four guideline steps: equations in symbols and with numbers, results, explanation.

    Parameters
    ----------
    result : fi_design.guideline.steps.DesignResult
        The design (and its simulated landing, when confirmed).
    figures : bool, optional
        Draw the equations (default); False leaves their ``svg`` None.

    Returns
    -------
    list of dict
        One per step: ``number``, ``title``, ``source``, ``equations``
        (:func:`~fi_design.report.equations.equation`), ``results`` (quantity,
        SI value, unit) and ``explanation``.
    """
    numbers = itertools.count(1)

    def eq(tex: str) -> dict:
        return equation(tex, f"eq-{next(numbers)}", figures)

    spec = result.spec
    gap = result.friction_gap
    xo = result.crossover
    st = result.stiffness
    g = result.pid.gains
    req = spec.requirements
    steps = []

    # step 1
    rel = "\\geq" if gap.hunting_risk else "<"
    steps.append({
        "number": 1, "title": "Friction gap", "source": "paper \u00a74 step 1; Figure 4A",
        "equations": [
            eq(f"\\Delta F = F_s - F_c = {tex_qty(gap.static, 'N')} - "
                      f"{tex_qty(gap.coulomb, 'N')} = {tex_qty(gap.gap, 'N')}"),
            eq(f"\\Delta F = {tex_qty(gap.gap, 'N')} \\ {rel}\\ \\Delta F_\\mathrm{{lim}}"
                      f" = {tex_qty(gap.threshold, 'N')}"),
        ],
        "results": [
            {"quantity": "friction gap Fs \u2212 Fc", "value": gap.gap, "unit": "N"},
            {"quantity": "threshold (requirements.friction_gap)", "value": gap.threshold,
             "unit": "N"},
            {"quantity": "hunting risk", "value": "yes" if gap.hunting_risk else "no",
             "unit": ""},
        ],
        "explanation": (
            "Hunting needs stick-slip: the integrator builds up force until the bearing breaks "
            "loose at static friction, the cart slips past the target because sliding friction "
            "is lower, and sticks again. The larger the gap between static and Coulomb friction, "
            "the larger the overshoot (paper Figure 4A: hunting appears above a gap of about "
            "1 N for the paper's stage). Here: " + gap.checks[0].message + "."),
    })

    # step 2
    sep = req.parasitic_separation
    loop_fc = xo.separation_crossover
    need = sep * loop_fc
    eqs = [eq(f"\\omega_c = 2\\pi f_c = 2\\pi \\times {tex_qty(xo.desired, 'Hz')} = "
                     f"{tex_qty(2 * math.pi * xo.desired, 'rad/s')}")]
    if xo.achievable is not None:
        ok = xo.desired <= xo.achievable * (1 + 1e-9)
        rel = "\\leq" if ok else ">"
        if xo.limit_kind == "scan_limit":  # the search cap: a bound, not the achievable
            eqs.append(eq(
                f"f_c = {tex_qty(xo.desired, 'Hz')}\\ {rel}\\ {tex_qty(xo.achievable, 'Hz')}"
                f"\\ \\leq\\ f_{{c,\\mathrm{{ach}}}}"))
        else:
            eqs.append(eq(
                f"f_c = {tex_qty(xo.desired, 'Hz')}\\ {rel}\\ "
                f"f_{{c,\\mathrm{{ach}}}} = {tex_qty(xo.achievable, 'Hz')}"))
    eqs.append(eq(f"f_\\mathrm{{par}} \\geq n_\\mathrm{{sep}}\\, f_\\mathrm{{loop}} = "
                  f"{tex_num(sep)} \\times {tex_qty(loop_fc, 'Hz')} = {tex_qty(need, 'Hz')}"))
    # the phase margins the margins table judges: a case crossing 0 dB only outside the
    # loop's band shows none there (results.linear.phase_margin_judged)
    unjudged = [_case_number(xo, c.name) for c in xo.cases if not phase_margin_judged(c.criteria)]
    pms = [c.phase_margin_deg for c in xo.cases if phase_margin_judged(c.criteria)]
    pm_cases = ("all cases" if not unjudged else
                f"the judged cases; case{'s' if len(unjudged) > 1 else ''} "
                f"{', '.join(map(str, unjudged))} cross{'' if len(unjudged) > 1 else 'es'} 0 dB "
                f"only outside the loop's band, not judged")
    gms = [abs(c.gain_margin_db) for c in xo.cases]
    results = [
        {"quantity": "desired crossover fc", "value": xo.desired, "unit": "Hz"},
        # not limited below the search cap: the cap is a bound, as the verdict box says
        {"quantity": "achievable crossover",
         "value": (f"\u2265 {qty(xo.achievable, 'Hz')} (a bound: the search cap)"
                   if xo.limit_kind == "scan_limit" else xo.achievable), "unit": "Hz"},
        {"quantity": "limited by", "value": xo.limited_by, "unit": ""},
        {"quantity": f"smallest phase margin at fc ({pm_cases})",
         "value": min(pms) if pms else "none", "unit": "deg" if pms else ""},
        {"quantity": "smallest gain margin at fc (all cases)", "value": min(gms), "unit": "dB"},
        {"quantity": "loop delay in the analysis", "value": xo.delay, "unit": "s"},
        {"quantity": "loop crossover f_loop (the highest 0 dB crossing in the band"
                     + (f", case {_case_number(xo, xo.loop_crossover_case)})"
                        if xo.loop_crossover_case else ": none, the desired crossover)"),
         "value": loop_fc, "unit": "Hz"},
        {"quantity": "lowest allowed parasitic frequency", "value": need, "unit": "Hz"},
    ]
    if xo.limiting_mode is not None:
        results.append({"quantity": "parasitic mode that limits the crossover",
                        "value": f"{xo.limiting_mode} ({qty(xo.limiting_mode_frequency, 'Hz')})",
                        "unit": ""})
    if xo.notch is not None:
        n = xo.notch
        results.append({"quantity": f"achievable with a {n.notch.describe()}",
                        "value": n.achievable if n.achievable is not None else "none",
                        "unit": "Hz" if n.achievable is not None else ""})
        results.append({"quantity": "then limited by", "value": n.limited_by, "unit": ""})
    for m in xo.parasitic_modes:
        results.append({"quantity": f"parasitic mode \u2018{m.name}\u2019"
                                    f" ({'collocated' if m.collocated else 'non-collocated'})",
                        "value": m.frequency, "unit": "Hz"})
    steps.append({
        "number": 2, "title": "Desired and achievable crossover",
        "source": "paper \u00a72.2 and \u00a74 step 2; Figure 2",
        "equations": eqs, "results": results,
        "explanation": (
            "One PID must be stable, with the required margins "
            f"({qty(req.phase_margin, 'deg')} phase, {qty(req.gain_margin, 'dB')} gain), in every "
            "linear limit case the stage switches between near standstill (paper Figure 2). The "
            "achievable crossover is the highest at which all cases keep these margins and every "
            f"parasitic flexure mode stays {num(sep)} times above the loop's crossover (the "
            "highest frequency at which any case crosses 0 dB in the loop's band: with the "
            "cart stuck the joint's resonance can lift it well above the set crossover). A "
            "lightly damped mode that limits the margins is named, with the crossover a notch "
            "at it would allow (controller.filters gain-stabilises it). A limited "
            "achievable crossover makes an isolator useful; a high one may avoid hunting by "
            "control alone. The margins of each case are in the linear analysis below."),
    })

    # step 3
    eqs = []
    results = []
    if spec.isolator is not None or st.suggested:
        gamma = st.safety
        eqs.append(eq(
            f"k_\\max = \\frac{{F_s}}{{\\gamma\\, s}} = \\frac{{{tex_qty(st.static, 'N')}}}"
            f"{{{tex_num(gamma)} \\times {tex_qty(st.stroke, 'm')}}} = "
            f"{tex_qty(st.maximum, 'N/m')}"))
        ok = st.chosen <= st.maximum * (1 + 1e-12)
        rel = "<" if st.force_at_stroke < st.static else "\\geq"
        eqs.append(eq(
            f"F_k = k\\, s = {tex_qty(st.chosen, 'N/m')} \\times {tex_qty(st.stroke, 'm')} = "
            f"{tex_qty(st.force_at_stroke, 'N')}\\ {rel}\\ F_s = {tex_qty(st.static, 'N')}"))
        results += [
            {"quantity": "stroke s", "value": st.stroke, "unit": "m"},
            {"quantity": "safety factor \u03b3 (requirements.stiffness_safety)",
             "value": st.safety, "unit": "1"},
            {"quantity": "maximum drive stiffness k_max", "value": st.maximum, "unit": "N/m"},
            {"quantity": "chosen drive stiffness k", "value": st.chosen, "unit": "N/m"},
            {"quantity": "source of k", "value": st.source, "unit": ""},
            {"quantity": "flexure force at full stroke k s", "value": st.force_at_stroke,
             "unit": "N"},
            {"quantity": "k within k_max", "value": "yes" if ok else "no", "unit": ""},
        ]
    fx = result.flexure
    if fx is not None and fx.feasible:
        m, gd = fx.mechanics, fx.guide
        eqs.append(eq(
            f"k_e \\approx \\frac{{n E b t^3}}{{L^3}} = \\frac{{{gd.leaves} \\times "
            f"{tex_qty(gd.youngs_modulus, 'Pa')} \\times {tex_qty(gd.width, 'm')} \\times "
            f"({tex_qty(gd.thickness, 'm')})^3}}{{({tex_qty(gd.length, 'm')})^3}},\\quad "
            f"k = k_e + k_g = {tex_qty(m.stiffness.x, 'N/m')} "
            f"{'-' if m.gravity.geometric_stiffness < 0 else '+'} "
            f"{tex_qty(abs(m.gravity.geometric_stiffness), 'N/m')} = "
            f"{tex_qty(m.net_drive_stiffness, 'N/m')}"))
        rel = "\\leq" if m.stress <= gd.allowed_stress else ">"
        eqs.append(eq(
            f"\\sigma = \\frac{{3 E t s}}{{L^2}} + \\frac{{|N|}}{{b t}} = "
            f"{tex_qty(m.stress, 'Pa')}\\ {rel}\\ \\sigma_\\mathrm{{allow}} = "
            f"{tex_qty(gd.allowed_stress, 'Pa')}"))
        low = fx.lowest_mode
        results += [
            {"quantity": "leaf-spring guide (section The isolator's leaf-spring guide)",
             "value": (f"{gd.leaves} leaves L \u00d7 b \u00d7 t = {qty(gd.length, 'm')} \u00d7 "
                       f"{qty(gd.width, 'm')} \u00d7 {qty(gd.thickness, 'm')}, "
                       f"{gd.orientation.replace('_', ' ')}"
                       + (", as drawn" if fx.drawn else ", sized")), "unit": ""},
            {"quantity": "leaf thickness stock" if fx.thickness_step is not None else
             "leaf thickness", "value": fx.thickness, "unit": "m"},
            {"quantity": "net drive stiffness at \u00b1\u0394t", "value":
             list(fx.stiffness_range), "unit": "N/m"},
            {"quantity": "stress at full stroke", "value": m.stress, "unit": "Pa"},
            # factors to 3 digits, as the flexure checks, the conclusion and the guide quote them
            {"quantity": "stress margin allowed / actual", "value": num(m.stress_margin, 3),
             "unit": "1"},
            {"quantity": "buckling factor (load / weight)",
             "value": "no compression" if m.gravity.buckling_factor is None
             else num(m.gravity.buckling_factor, 3), "unit": "1"},
            {"quantity": f"lowest parasitic mode ({low.name})", "value": low.frequency,
             "unit": "Hz"},
            {"quantity": "required parasitic frequency (step 2: n_sep f_loop)",
             "value": need, "unit": "Hz"},
        ]
        if not fx.drawn and not math.isclose(fx.required_frequency, need, rel_tol=1e-9):
            # the sizing picks the guide before the loop with its modes is analysed: it asks
            # n_sep x the rigid limit cases' crossover, the check n_sep x the loop's
            results.append({"quantity": "parasitic frequency the guide was sized for (n_sep "
                                        "x the rigid limit cases' crossover)",
                            "value": fx.required_frequency, "unit": "Hz"})
    elif fx is not None:
        results.append({"quantity": "leaf-spring flexure", "value": f"none fits: {fx.reason}",
                        "unit": ""})
    sim = result.simulation
    land = getattr(sim, "landing", None) if sim is not None else None
    if land is not None and not math.isfinite(land.deflection):  # the run did not complete
        results.append({"quantity": "simulated deflection at rest d",
                        "value": "not determined: the isolated simulation of the spec's move "
                                 "did not complete (see the simulation section)", "unit": ""})
    elif land is not None:
        eqs.append(eq(
            f"F_\\mathrm{{rest}} = k \\min(|d|, s) = {tex_qty(land.stiffness, 'N/m')} \\times "
            f"{tex_qty(min(abs(land.deflection), land.stroke), 'm')} = {tex_qty(land.force, 'N')}"))
        results.append({"quantity": "simulated deflection at rest d", "value": land.deflection,
                        "unit": "m"})
        results.append({"quantity": "flexure force on the resting cart", "value": land.force,
                        "unit": "N"})
    if st.suggested:
        lead = ("The spec has no isolator; these are the rule's values for the paper's 0.3 mm "
                "stroke, the isolator the simulation tries beside the stage for comparison"
                + ("" if result.isolator_advice is None else
                   f" ({result.isolator_advice.reason})") + ". ")
    else:
        lead = ""
    steps.append({
        "number": 3, "title": "Maximum drive stiffness", "source": "paper \u00a74 step 3; "
                                                                    "Figure 4C",
        "equations": eqs, "results": results,
        "explanation": lead + (
            "At full stroke the flexure must push the cart with less than static friction, or it "
            "drags the cart along while the stage settles and the controller feels the friction "
            "again: k_max = Fs / (\u03b3 s). Lower stiffness mitigates hunting better (paper "
            "Figure 4C); the flexure's parasitic modes and support stiffness bound how low it can "
            "go. The simulated force on the resting cart refines the rule: the cart sees "
            "k min(|d|, s), not k s."),
    })

    # step 4
    m_text = ("m_1 + m_2" if spec.controller.tuning_mass == "total" else "m_1")
    eqs = [
        eq(f"m = {m_text} = {tex_qty(g.tuning_mass, 'kg')}"),
        eq("C(s) = k_s \\left(1 + \\frac{\\omega_i}{s}\\right)"
                  "\\frac{1 + s/\\omega_d}{1 + s/\\omega_t}"),
        eq(f"k_s = \\frac{{m\\, \\omega_c^2}}{{r}} = \\frac{{{tex_qty(g.tuning_mass, 'kg')}"
                  f" \\times ({tex_qty(g.wc, 'rad/s')})^2}}{{{tex_num(result.pid.derivative_ratio)}"
                  f"}} = {tex_qty(g.ks, 'N/m')}"),
        eq(f"\\omega_d = \\omega_c / r = {tex_qty(g.wd, 'rad/s')},\\quad \\omega_t = "
                  f"r\\, \\omega_c = {tex_qty(g.wt, 'rad/s')},\\quad \\omega_i = \\omega_c / r_i = "
                  f"{tex_qty(g.wi, 'rad/s')}"),
        eq(f"k_p = k_s (1 + \\omega_i/\\omega_d) = {tex_qty(g.kp, 'N/m')},\\quad "
                  f"k_i = k_s \\omega_i = {tex_qty(g.ki, 'N/(m*s)')},\\quad "
                  f"k_d = k_s / \\omega_d = {tex_qty(g.kd, 'N*s/m')}"),
    ]
    law = result.pid.controller
    hand = law.hand_off()
    if law.source == "rule":  # the same controller in the form controller.gains takes
        eqs += [
            eq("C(s) = \\frac{k_p + k_i/s + k_d s}{1 + s/\\omega_t} = k_p' + \\frac{k_i}{s} + "
               "\\frac{k_d' s}{1 + s/\\omega_t}"),
            eq(f"k_p' = k_p - k_i/\\omega_t = {tex_qty(hand['kp'], 'N/m')},\\quad "
               f"k_d' = k_d - k_p'/\\omega_t = {tex_qty(hand['kd'], 'N*s/m')},\\quad "
               f"f_t = \\omega_t / 2\\pi = {tex_qty(hand['roll_off'], 'Hz')}"),
        ]
    sampled = ("continuous" if hand["sample_rate"] is None
               else f"sampled at {qty(hand['sample_rate'], 'Hz')}")
    delay = delay_words(hand["delay"] or 0.0, spec.effects, sep=NBSP)
    simulated = simulated_only(spec.effects, sep=NBSP)
    results = [
        {"quantity": "tuning mass m", "value": g.tuning_mass, "unit": "kg"},
        {"quantity": "drive gain kp (controller.gains.kp)", "value": hand["kp"], "unit": "N/m"},
        {"quantity": "drive gain ki (controller.gains.ki)", "value": hand["ki"],
         "unit": "N/(m*s)"},
        {"quantity": "drive gain kd (controller.gains.kd)", "value": hand["kd"],
         "unit": "N*s/m"},
        {"quantity": "controller.roll_off (D term only)",
         "value": "none (an ideal D)" if hand["roll_off"] is None else hand["roll_off"],
         "unit": "Hz"},
    ]
    for i, f in enumerate(law.filters):
        results.append({"quantity": f"controller.filters[{i}]", "value": f.describe(),
                        "unit": ""})
    units = result.pid.drive_gains
    if units is not None:
        for key in ("kp", "ki", "kd"):
            results.append({"quantity": f"{key} in the drive's units", "value": getattr(units, key),
                            "unit": units.units[key]})
    dz = result.pid.discrete
    if dz is not None:
        results += [
            {"quantity": "per sample: integrator gain ki T/2", "value": dz.integrator_gain,
             "unit": "N/m"},
            {"quantity": "per sample: D recursion pole", "value": dz.derivative_pole,
             "unit": "1"},
            {"quantity": "per sample: D recursion gain", "value": dz.derivative_gain,
             "unit": "N/m"},
        ]
        for f in dz.filters:
            results.append({"quantity": f"biquad '{f.name}' b; a (Tustin, prewarped)",
                            "value": ", ".join(num(x, 6) for x in f.b) + "; "
                            + ", ".join(num(x, 6) for x in f.a), "unit": ""})
    steps.append({
        "number": 4, "title": "PID gains", "source": "paper \u00a72.2 and \u00a74 step 4",
        "equations": eqs,
        "results": results,
        "explanation": (
            "The gains follow from the moving mass and the crossover: the lead-lag part has its "
            "phase maximum at \u03c9c, and k_s puts |C(j\u03c9c)| = m \u03c9c\u00b2, so a free "
            "mass m crosses over at \u03c9c. The paper tunes on the maximum moving mass m1 + m2 "
            "(the limiter engaged), which it found best. The results are the loop as analysed, "
            "in the form a drive and the spec's controller.gains take: kp + ki/s + kd s / "
            "(1 + s/(2\u03c0 roll_off)), the roll-off filtering the D term only (the rule's "
            "kp, ki, kd above have the roll-off on the whole PID and are other numbers for the "
            f"same controller); D on the {hand['derivative_on']}, {sampled}, {delay} "
            "(controller.sample_rate and controller.delay: the hardware's, where given). "
            + (f"{simulated[0].upper()}{simulated[1:]}. " if simulated else "")
            + "fi-design SPEC.yaml --write-spec OUT.yaml writes them into a copy of the spec."),
    })
    return steps
