"""The nonlinear confirmation: the stage after every move, the spec's motion, one simulation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..display import column, number, quantity, scale
from .common import table

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console


#: Friction models as the literature names them.
_MODEL_NAMES = {"lugre": "LuGre", "switch": "switch"}


#: One character per move outcome in :func:`moves_strips`, with its style.
MOVE_GLYPHS = {"hunts": ("\u25cf", "bold red"), "settles": ("\u00b7", "green"),
               "rests": ("\u25aa", "green"), "stuck": ("\u25aa", "bold yellow"),
               "undetermined": ("?", "bold yellow")}


def moves_strips(stages: dict, suggested: bool = False) -> list:
    """The move family at a glance: one character per move, small to large, per plant.

    ``●`` ends in a cycle, ``·`` settles, ``▪`` rests off target (yellow: stuck),
    ``?`` undetermined; negative moves on a second strip.

    Parameters
    ----------
    stages : dict
        ``DesignResult.to_dict()["stage_hunting"]``.
    suggested : bool
        Whether the isolated plant is the suggested isolator.

    Returns
    -------
    list of rich.text.Text
    """
    from rich.text import Text

    names = {"isolated": "rule's isolator" if suggested else "with isolator",
             "non_isolated": "without isolator"}
    out = []
    for key in ("isolated", "non_isolated"):
        st = stages.get(key)
        if not st:
            continue
        moves = [m for m in st.get("moves", []) if m.get("label") == "family"]
        for sign, word in ((1.0, ""), (-1.0, " (negative)")):
            side = sorted((m for m in moves if m["distance"] * sign > 0),
                          key=lambda m: abs(m["distance"]))
            if not side:
                continue
            lo, hi = abs(side[0]["distance"]), abs(side[-1]["distance"])
            unit, f = scale("m", [lo, hi])
            line = Text(f"Moves {number(lo * f, 3)} to {number(hi * f, 3)} {unit}, "
                        f"{names[key]}{word}: ")
            for m in side:
                glyph, style = MOVE_GLYPHS.get(m["outcome"], ("x", "bold yellow"))
                line.append(glyph, style=style)
            out.append(line)
    if out:
        out.append(Text("  \u25cf ends in a hunting cycle, \u00b7 settles, \u25aa rests off "
                        "target, ? not judged", style="dim"))
    return out


def simulation_table(sim: dict, window: tuple[float, float] | None = None,
                      stages: dict | None = None) -> Any:
    """Table of the simulated verdicts from the confirmation's JSON form.

    One column per plant, one row per quantity, so it reads at any width;
    a row of lengths is in one unit, named in its title (``Final error x1 - r [mm]``).

    Parameters
    ----------
    sim : dict
        ``DesignResult.to_dict()["simulation"]``.
    window : tuple of float, optional
        The counting window [s], named in the cycles row.
    stages : dict, optional
        ``DesignResult.to_dict()["stage_hunting"]``: the stage-level rows.
    """
    from rich.text import Text

    label = "rule's isolator" if sim.get("suggested_isolator") else "with isolator"
    model = sim["isolated"].get("friction_model") or "lugre"
    other = sim.get("cross_check") or {}
    other_model = next((v.get("friction_model") for v in other.values() if v),
                       "switch" if model == "lugre" else "lugre")
    mins = sim.get("min_hunting_free_crossover") or {}
    t = table(f"Nonlinear confirmation ({_MODEL_NAMES.get(model, model)} simulation, paper "
               "section 2.3)")
    t.add_column("", no_wrap=True)
    plants = (("isolated", label), ("non_isolated", "without isolator"))
    for _, name in plants:
        t.add_column(Text(name), justify="right")
    counted = "in the window" if window is None else \
        f"in [{number(float(window[0]))} s, {number(float(window[1]))} s)"

    def verdict_text(verdict: str) -> Any:
        style = {"settled": "bold green", "settles": "bold green", "static_error": "bold green",
                 "hunting": "bold red", "hunts": "bold red"}.get(verdict, "bold yellow")
        return Text(verdict.replace("_", " "), style=style)

    stages = stages or {}

    def stage(key: str) -> dict:
        return stages.get(key) or {}

    def free_from(key: str) -> str:
        m = mins.get(key)
        b = stage(key).get("boundary") or {}
        if m is None:
            return {"bound": "above the search", "not_found": "not found"}.get(
                b.get("kind"), "-")
        return f"{number(m, 4)} Hz" + ("" if b.get("kind") == "fold" else " (bound)")

    def hunting_moves(key: str) -> str:
        st = stage(key)
        if not st:
            return "-"
        return f"{st.get('moves_hunting')} of {st.get('moves_tried')}"

    def entered(key: str) -> str:
        d = sorted(abs(x) for x in stage(key).get("entered_by") or [])
        if not d:
            return "-"
        unit, f = scale("m", d)
        return quantity(d[0], "m", 3) if len(d) == 1 else \
            f"{number(d[0] * f, 3)} to {number(d[-1] * f, 3)} {unit}"

    def cycle(key: str, name: str, unit: str | None = None) -> Any:
        c = stage(key).get("cycle")
        if not c or c.get(name) is None:
            return "-"
        value = c[name]
        if unit == "m":
            return quantity(value, "m", 3)
        if unit == "s":
            return f"{number(value, 3)} s"
        if isinstance(value, bool):
            return "yes" if value else "no"
        return number(value, 3)

    def period(v: dict) -> str:
        return "-" if v.get("period") is None else f"{number(v['period'], 3)} s"

    def settling(v: dict) -> str:
        st = v.get("settling_time")
        return "never" if st is None else f"{number(st, 3)} s"

    def lengths(title: str, value: Any) -> tuple[str, list[str]]:
        """A row of lengths in one unit, named in its title (display.column)."""
        values = [value(key) for key, _ in plants]
        shown, cells = column(values, "m", 3)
        return f"{title} [{shown}]", [c if v is not None else "-" for v, c in zip(values, cells)]

    rows = [
        ("Stage, after every move", lambda k, v: verdict_text(stage(k).get("outcome", ""))),
        ("Moves ending in a cycle", lambda k, v: hunting_moves(k)),
        ("Moves that enter it", lambda k, v: entered(k)),
        lengths("Cycle, peak to peak", lambda k: (stage(k).get("cycle") or {}).get("amplitude")),
        ("Cycle period", lambda k, v: cycle(k, "period", "s")),
        ("Floquet multiplier", lambda k, v: cycle(k, "multiplier")),
        ("Joint on its limiter", lambda k, v: cycle(k, "on_limiter")),
        ("No move hunts from", lambda k, v: free_from(k)),
        ("Spec's motion: outcome", lambda k, v: verdict_text(v.get("outcome") or v.get("verdict", ""))),
        (f"Hunting cycles {counted}", lambda k, v: str(v.get("hunting_cycles"))),
        lengths("Amplitude, peak to peak", lambda k: sim[k].get("amplitude")),
        ("Period", lambda k, v: period(v)),
        ("Settling time after the motion", lambda k, v: settling(v)),
        lengths("Final error x1 - r", lambda k: sim[k].get("final_error")),
    ]
    if other:
        rows.append((f"Cross-check, {_MODEL_NAMES.get(other_model, other_model)} model",
                     lambda k, v: verdict_text((other.get(k) or {}).get("outcome")
                                               or (other.get(k) or {}).get("verdict", ""))))
    for title, cell in rows:
        t.add_row(Text(title), *(cell if isinstance(cell, list) else
                                 [cell(key, sim[key]) for key, _ in plants]))
    return t


def print_simulation(console: "Console", result) -> None:
    """Print the metrics and solver statistics of a :class:`~fi_design.simulation.run.SimulationResult`.

    A replay of a measured record shows its agreement with the record
    instead of the hunting metric (which judges a settling stage, not a
    record in motion).

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.simulation.run.SimulationResult
        The simulation.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    m = result.metrics
    plant = "with isolator" if result.isolated else "without isolator"
    loop = "closed loop" if result.drive == "closed" else "open loop, measured force"
    what = "Simulation" if result.replay is None else f"Replay of {result.record} ({loop})"
    t = Table(title=f"{what} {plant} at {quantity(result.crossover, 'Hz', 4)} "
                    f"({result.friction_model}, {result.method} solver)",
              title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    t.add_column("Quantity")
    t.add_column("Value", justify="right")
    rows = []
    fit = result.replay
    if fit is not None:
        rows += [
            ("position, model - measured, rms [\u00b5m]", number(1e6 * fit.position_rms, 4)),
            ("position, model - measured, max [\u00b5m]", number(1e6 * fit.position_max, 4)),
            ("tracking error r - x1 rms, model [\u00b5m]", number(1e6 * fit.tracking_rms_model, 4)),
            ("tracking error r - x1 rms, measured [\u00b5m]",
             number(1e6 * fit.tracking_rms_measured, 4)),
            ("commanded force, model - measured, rms [N]", number(fit.force_rms, 4)),
        ]
        if result.window is not None:
            rows.append(("re-anchored windows [-]", str(int(result.window.max()) + 1)))
    else:
        rows += [
            ("verdict of the spec's own motion", m.verdict),
            ("hunting cycles in the window [-]", str(m.hunting_cycles)),
            ("amplitude (peak to peak)", quantity(m.amplitude, "m")),
            ("period [s]", number(m.period, 4)),
            ("settling time [s]", number(m.settling_time, 4)),
            ("final error", quantity(m.final_error, "m") if result.success else
             f"\u2013 (the run stopped at {quantity(result.t_reached, 's', 4)})"),
        ]
    rows += [
        ("integration", "ok" if result.success else result.message),
        ("steps / rejected / events [-]", f"{result.n_steps} / {result.n_rejected} / "
                                          f"{result.n_events}"),
        ("wall time [ms]", number(1e3 * result.wall_time, 3)),
    ]
    for k, v in rows:
        t.add_row(Text(k), Text(str(v)))
    console.print(t)
    for note in () if fit is None else fit.notes:
        console.print(Text("warning: ", style="bold yellow").append(Text(note)))
    if result.replay is None:
        console.print(Text(m.reason))
        console.print(Text(
            f"This is the spec's own motion only, judged by the paper's metric ({m.verdict}); "
            "hunting is a property of the stage, and one move can settle where others hunt: "
            "the design command (fi-design SPEC.yaml) judges every move of the family and "
            "signs off.", style="dim"))
