"""The isolator's leaf-spring guide drawn to scale: side and top views with dimensions.

:func:`guide_figure` draws a :class:`~fi_design.results.mechanism.GuideMechanics`:
the side view (drive direction x against the leaves' length z) with the
cart's clamp, the leaves, the stage and its centre of mass, the sensor and
the actuator, the weight's direction; the top view (x against the leaves'
width y) with the leaves' cross-sections and the stage's outline. Lengths in
mm; the leaves' thickness is drawn at least 0.6 % of the view so that it
shows, and labelled with its true value.
"""

from __future__ import annotations

from typing import Any

from ..display import number, quantity
from .figure import report_figure, styled

__all__ = ["guide_figure"]

#: Colours of the drawing's parts.
_LEAF, _STAGE, _CART, _GRAVITY = "#2b6cb0", "#d9e2ec", "#9aa5b1", "#c53030"


def _mm(x: float) -> float:
    return x * 1e3


def _mm_text(x: float) -> str:
    """A dimension [m] as the drawing's axes read it, in mm."""
    return quantity(x, "m", 3, shown=("mm", 1e3))


def _dim(ax, p0, p1, text: str, offset, *, vertical: bool = False) -> None:
    """A dimension line from p0 to p1 [mm], shifted by offset [mm], with its text."""
    (x0, y0), (x1, y1) = p0, p1
    dx, dy = offset
    ax.annotate("", xy=(x0 + dx, y0 + dy), xytext=(x1 + dx, y1 + dy),
                arrowprops=dict(arrowstyle="<->", lw=0.7, color="0.25", shrinkA=0, shrinkB=0))
    for x, y in (p0, p1):
        ax.plot([x, x + dx * 1.15], [y, y + dy * 1.15], lw=0.4, color="0.45")
    ax.text(0.5 * (x0 + x1) + dx * 1.35, 0.5 * (y0 + y1) + dy * 1.35, text, ha="center",
            va="center", fontsize=7.0, rotation=90 if vertical else 0,
            bbox=dict(fc="white", ec="none", pad=0.5))


@styled
def guide_figure(mech: Any, body_size: tuple[float, float, float] | None = None) -> Any:
    """The guide in side and top view, to scale, with its dimensions and the weight.

    Parameters
    ----------
    mech : fi_design.results.mechanism.GuideMechanics
        The guide and what it does.
    body_size : (float, float, float), optional
        The stage's box (x, y, z) [m]; without it the stage is drawn as a box
        around its centre of mass spanning the leaves.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.patches import Rectangle

    g = mech.guide
    L, b, t, d = _mm(g.length), _mm(g.width), _mm(g.thickness), _mm(g.spacing)
    h = _mm(g.com_height)
    sx, sy, sz = ((_mm(v) for v in body_size) if body_size is not None
                  else (d + 2 * b / 4, b * 1.5 if g.leaves == 2 else _mm(g.lateral_spacing) + b,
                        2 * h))
    fig = report_figure(3.1, left=0.3, right=0.15, top=0.3, bottom=0.35)
    side = fig.add_axes([0.05, 0.13, 0.48, 0.75])  # the x label's descent within the figure
    top = fig.add_axes([0.58, 0.13, 0.38, 0.75])
    hanging = g.orientation == "hanging"
    sgn = -1.0 if hanging else 1.0  # the drawing's z up, or down for a hanging stage
    span = max(L + sz, d + t, sx)
    tw = max(t, 0.006 * span)  # the leaves' thickness as drawn

    # side view: x across, the leaves' length z up (down when hanging)
    base = 0.12 * span
    side.add_patch(Rectangle((-0.5 * max(sx, d) - 0.1 * span, -sgn * base if not hanging
                              else 0.0), max(sx, d) + 0.2 * span, base, fc=_CART, ec="0.3",
                             lw=0.7, hatch="///"))
    side.text(0.0, -sgn * 0.5 * base, "cart", ha="center", va="center", fontsize=7.5,
              bbox=dict(fc="white", ec="none", pad=0.3))
    for x in (-0.5 * d, 0.5 * d):
        z0, z1 = sorted((0.0, sgn * L))
        side.add_patch(Rectangle((x - 0.5 * tw, z0), tw, z1 - z0, fc=_LEAF, ec=_LEAF))
    stage_z = sgn * L if not hanging else sgn * L - sz
    side.add_patch(Rectangle((-0.5 * sx, stage_z), sx, sz, fc=_STAGE, ec="0.3", lw=0.8))
    zc = sgn * (L + h)
    side.plot([0.0], [zc], marker="o", ms=5, mfc="white", mec="k", mew=1.0)
    # above its marker: to its left the label ran across the actuator's arrow and its word
    side.text(0.0, zc + 0.04 * span, "centre of mass", fontsize=7.0, va="bottom", ha="center")
    ys, zs = (_mm(v) for v in g.sensor_offset)
    ya, za = (_mm(v) for v in g.actuator_offset)
    side.plot([0.5 * sx], [zc + sgn * zs], marker="<", ms=6, color="k")
    side.text(0.5 * sx + 0.02 * span, zc + sgn * zs, "sensor", fontsize=7.0, va="center")
    side.annotate("", xy=(-0.5 * sx, zc + sgn * za), xytext=(-0.5 * sx - 0.12 * span,
                                                            zc + sgn * za),
                  arrowprops=dict(arrowstyle="-|>", lw=1.2, color="k"))
    side.text(-0.5 * sx - 0.12 * span, zc + sgn * za - 0.05 * span, "actuator", fontsize=7.0,
              ha="left")
    weight = f"m\u2081g = {number(g.weight, 3)} N"
    arrow = dict(arrowstyle="-|>", lw=1.4, color=_GRAVITY)
    if g.orientation in ("standing", "hanging"):
        side.annotate("", xy=(0.0, zc - 0.22 * span), xytext=(0.0, zc), arrowprops=arrow)
        side.text(0.03 * span, zc - 0.15 * span, weight, color=_GRAVITY, fontsize=7.5)
    elif g.orientation == "vertical_axis":
        side.annotate("", xy=(-0.3 * span, zc), xytext=(0.0, zc), arrowprops=arrow)
        side.text(-0.3 * span, zc - 0.1 * span, weight + " (x vertical)", color=_GRAVITY,
                  fontsize=7.5, va="top")
    else:
        side.plot([0.0], [zc - 0.15 * span], marker="X", ms=7, color=_GRAVITY)
        side.text(0.03 * span, zc - 0.15 * span, weight + ", into the page (along \u2212y)",
                  color=_GRAVITY, fontsize=7.5, va="center")
    _dim(side, (0.5 * d, 0.0), (0.5 * d, sgn * L), f"L = {_mm_text(g.length)}",
         (0.5 * sx - 0.5 * d + 0.16 * span, 0.0), vertical=True)
    _dim(side, (-0.5 * d, 0.0), (0.5 * d, 0.0), f"{_mm_text(g.spacing)}",
         (0.0, sgn * 0.45 * L))
    side.text(0.0, sgn * 0.2 * L, f"t = {_mm_text(g.thickness)}", ha="center", fontsize=7.0,
              va="center", bbox=dict(fc="white", ec="none", pad=0.3))
    side.set_aspect("equal")
    side.set_xlim(-0.5 * max(sx, d) - 0.25 * span, 0.5 * max(sx, d) + 0.3 * span)
    lo, hi = sorted((-sgn * base * 1.2, sgn * (L + sz + 0.1 * span)))
    side.set_ylim(lo - 0.05 * span, hi + 0.05 * span)
    side.set_xlabel("x, drive direction [mm]")
    side.set_ylabel("z, along the leaves [mm]")
    side.set_title(f"side view, {g.orientation.replace('_', ' ')}", fontsize=8.5)
    side.grid(False)

    # top view: x across, the leaves' width y up
    top.add_patch(Rectangle((-0.5 * sx, -0.5 * sy), sx, sy, fc="none", ec="0.4", lw=0.8,
                            ls="--"))
    for x, y in g.leaf_positions():
        top.add_patch(Rectangle((_mm(x) - 0.5 * tw, _mm(y) - 0.5 * b), tw, b, fc=_LEAF,
                                ec=_LEAF))
    _dim(top, (0.5 * d, -0.5 * b + _mm(g.leaf_positions()[-1][1])),
         (0.5 * d, 0.5 * b + _mm(g.leaf_positions()[-1][1])), f"b = {_mm_text(g.width)}",
         (0.5 * sx - 0.5 * d + 0.12 * span, 0.0), vertical=True)
    top.plot([0.0], [0.0], marker="o", ms=4, mfc="white", mec="k")
    top.set_aspect("equal")
    ext = 0.5 * max(sx, sy, d + t) + 0.25 * span
    top.set_xlim(-ext, ext)
    top.set_ylim(-ext, ext)
    top.set_xlabel("x, drive direction [mm]")
    top.set_ylabel("y, along the leaves' width [mm]")
    top.set_title(f"top view, {g.leaves} leaves", fontsize=8.5)
    top.grid(False)
    return fig
