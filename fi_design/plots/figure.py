"""Report figures and their rendering: the page style, fixed margins, SVG and PNG bytes.

What every result family's figures share: :data:`REPORT_RC` and
:func:`report_figure` (the A4 text width, fixed margins), :func:`styled`,
plain tick labels on log axes, the thinning of long traces
(:func:`decimate`), cell edges of a map, and the two renderings
(:func:`figure_svg` for inlining in HTML, :func:`figure_bytes` for files),
both reproducible, and :func:`figure_markup`, which places a figure as inline
SVG or, inside :func:`raster_figures` (a PDF), as a PNG image, and
:func:`figure_from`, which within :func:`deferred_figures` places it by name,
to be drawn when the PDF's layout reaches it.
matplotlib is imported inside the functions.
"""

from __future__ import annotations

import base64
import contextlib
import contextvars
import io
import math
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from ..display import fixed, plain
from ..display import tick_label as plain_tick  # the log axes' tick labels (FuncFormatter)
from ..errors import ArgumentError


#: Width of a full-width report figure [in]: the A4 text width (170 mm), so 1 pt is 1 pt.
REPORT_WIDTH = 6.7


#: matplotlib settings of the report figures: fonts readable on paper, light grid.
REPORT_RC = {
    "font.size": 8.5, "axes.titlesize": 9.0, "axes.labelsize": 8.5, "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0, "legend.fontsize": 7.5, "axes.grid": True, "grid.color": "0.88",
    "grid.linewidth": 0.6, "axes.linewidth": 0.7, "lines.linewidth": 1.3,
    "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False,
    "figure.dpi": 100,
}


def report_figure(height: float, width: float = REPORT_WIDTH, *, left: float = 0.62,
                   right: float = 0.12, top: float = 0.12, bottom: float = 0.45,
                   hspace: float = 0.35) -> Any:
    """A report figure with fixed margins [in].

    Fixed margins rather than a layout engine: the report's figures have known
    contents, and a layout engine draws every figure twice (it doubled the
    report's figure time).
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height))
    fig.subplots_adjust(left=left / width, right=1.0 - right / width, top=1.0 - top / height,
                        bottom=bottom / height, hspace=hspace)
    return fig


def styled(draw):
    """Run a figure function under :data:`REPORT_RC` (fonts are fixed when artists are made)."""
    import functools

    @functools.wraps(draw)
    def wrapper(*args, **kwargs):
        import matplotlib

        with matplotlib.rc_context(REPORT_RC):
            return draw(*args, **kwargs)

    return wrapper


def log_x(ax: Any, numticks: int = 12) -> None:
    """Logarithmic x axis with plain decade labels and no minor ticks (they are slow to draw)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

    ax.set_xscale("log")
    ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0,), numticks=numticks))
    ax.xaxis.set_major_formatter(FuncFormatter(plain_tick))
    ax.xaxis.set_minor_locator(NullLocator())


def nice_ticks(lo: float, hi: float) -> list[float]:
    """1-2-5 ticks between ``lo`` and ``hi`` (for log axes).

    Parameters
    ----------
    lo, hi : float
        The axis range (above zero).

    Returns
    -------
    list of float
    """
    out = []
    for exp in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1):
        for m in (1.0, 2.0, 5.0):
            v = m * 10.0 ** exp
            if lo * 0.999 <= v <= hi * 1.001:
                out.append(float(plain(v, 6)))
    return out


def cell_edges(values: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around centres (geometric midpoints on a log axis)."""
    v = np.asarray(values, dtype=float)
    if len(v) == 1:
        return np.array([v[0] * 0.9, v[0] * 1.1]) if log else np.array([v[0] - 0.5, v[0] + 0.5])
    if log:
        lv = np.log(v)
        mid = (lv[1:] + lv[:-1]) / 2
        return np.exp(np.concatenate([[2 * lv[0] - mid[0]], mid, [2 * lv[-1] - mid[-1]]]))
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def decimate(t: np.ndarray, y: np.ndarray, buckets: int = 700) -> tuple[np.ndarray, np.ndarray]:
    """Thin a trace for plotting, keeping each bucket's minimum and maximum.

    Parameters
    ----------
    t, y : numpy.ndarray, shape (n,)
        Sample times and values.
    buckets : int, optional
        Number of buckets; at most two samples survive per bucket.

    Returns
    -------
    t, y : numpy.ndarray
        The kept samples, in time order (the input when it is short already).
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    n = len(t)
    if n <= 2 * buckets:
        return t, y
    edges = np.linspace(0, n, buckets + 1).astype(int)
    starts = edges[:-1][np.diff(edges) > 0]
    lengths = np.diff(np.append(starts, n))
    bucket = np.repeat(np.arange(len(starts)), lengths)
    # a bucket with a finite value keeps the first of its smallest and of its largest values
    # (NaN ignored); one without keeps its first sample, a NaN, so the line breaks there
    has = np.logical_or.reduceat(np.isfinite(y), starts)
    keep = [np.array([0, n - 1]), starts[~has]]
    for extreme in (np.fmin, np.fmax):
        value = extreme.reduceat(y, starts)
        at = np.flatnonzero((y == value[bucket]) & has[bucket])[::-1]
        first = np.full(len(starts), -1)
        first[bucket[at]] = at  # the last write, from the reversed order, is the first index
        keep.append(first[has])
    idx = np.unique(np.concatenate(keep))
    return t[idx], y[idx]


def figure_svg(fig: Any, prefix: str, text_as_paths: bool = False) -> str:
    """A figure as SVG text for inlining in HTML: no XML prolog, unique ids, scalable.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    prefix : str
        Prepended to every ``id`` (and the references to it), so several
        figures can share one HTML page; letters, digits and ``-`` only.
    text_as_paths : bool, optional
        Draw text as glyph outlines (equations: exact, with any font);
        default False.

    Returns
    -------
    str
        An ``<svg>`` element with a ``viewBox`` (CSS sizes it), reproducible
        (fixed id salt, no date). By default text stays text
        (``svg.fonttype: none``): searchable, and about twice as fast for
        WeasyPrint to draw as glyph outlines; viewers draw it with their own
        sans-serif font.
    """
    import re

    import matplotlib

    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "fi_design",
                                "svg.fonttype": "path" if text_as_paths else "none"}):
        fig.savefig(buf, format="svg", metadata={"Date": None})
    text = buf.getvalue().decode("utf-8")
    text = text[text.index("<svg"):]
    text = re.sub(r'\bid="([^"]+)"', lambda m: f'id="{prefix}-{m.group(1)}"', text)
    text = re.sub(r'href="#([^"]+)"', lambda m: f'href="#{prefix}-{m.group(1)}"', text)
    text = re.sub(r"url\(#([^)]+)\)", lambda m: f"url(#{prefix}-{m.group(1)})", text)
    text = re.sub(r"<metadata>.*?</metadata>\s*", "", text, flags=re.DOTALL)
    return text.strip()


#: Resolution of the figures a PDF report carries as images [dots per inch].
RASTER_DPI = 200

_RASTER: contextvars.ContextVar[float | None] = contextvars.ContextVar("fi_design_raster",
                                                                       default=None)


@contextlib.contextmanager
def raster_figures(dpi: float = RASTER_DPI) -> Iterator[None]:
    """Within this block, :func:`figure_markup` places figures as PNG images of ``dpi``.

    A PDF report is laid out by WeasyPrint, which parses, styles and draws every
    element of an inline SVG in Python: the report's figures and equations as
    images take a fraction of that time. The HTML report keeps its scalable SVG.

    Parameters
    ----------
    dpi : float, optional
        Resolution [dots per inch] (default :data:`RASTER_DPI`).
    """
    token = _RASTER.set(float(dpi))
    try:
        yield
    finally:
        _RASTER.reset(token)


def raster_dpi() -> float | None:
    """The resolution of :func:`raster_figures` in force [dots per inch], or None (SVG)."""
    return _RASTER.get()


#: Scheme of the address a deferred figure's ``<img>`` points at (``figure:NAME``).
FIGURE_SCHEME = "figure"


#: What :func:`figure_from` places for an SVG figure drawn later (``deferred_figures(None)``):
#: an HTML comment that :func:`figure_mark` names and the figure's markup replaces.
FIGURE_MARK = "<!--fi_design figure:{name}-->"


def figure_mark(name: str) -> str:
    """Where the deferred SVG figure ``name`` goes in an HTML page (:data:`FIGURE_MARK`)."""
    return FIGURE_MARK.format(name=name)


class DeferredFigures:
    """The figures of a report placed by name and drawn when asked for (:func:`deferred_figures`).

    Attributes
    ----------
    dpi : float or None
        Resolution of the images [dots per inch]; None: the figures are inline
        SVG, placed by :func:`figure_mark`.
    makers : dict
        Name -> a callable returning the :class:`matplotlib.figure.Figure`, in the
        order the figures were placed.
    """

    def __init__(self, dpi: float | None) -> None:
        self.dpi = None if dpi is None else float(dpi)
        self.makers: dict[str, Callable[[], Any]] = {}

    def png(self, name: str) -> bytes:
        """The figure ``name`` drawn now (:func:`rgb_png`)."""
        return rgb_png(self.makers[name](), self.dpi)

    def svg(self, name: str) -> str:
        """The figure ``name`` drawn now as the inline SVG :func:`figure_from` would have
        placed without deferring it (:func:`figure_svg`, its ids prefixed by the name)."""
        return figure_svg(self.makers[name](), name)

    def all_png(self) -> dict[str, bytes]:
        """Every figure placed, drawn now: name -> PNG bytes."""
        return {name: self.png(name) for name in self.makers}


_DEFERRED: contextvars.ContextVar[DeferredFigures | None] = contextvars.ContextVar(
    "fi_design_deferred", default=None)


@contextlib.contextmanager
def deferred_figures(dpi: float | None = RASTER_DPI) -> Iterator[DeferredFigures]:
    """Within this block, :func:`figure_from` places a figure as ``<img src="figure:NAME">``
    and keeps its maker, to be drawn later or elsewhere; figures are PNG images of ``dpi``
    (:func:`raster_figures` holds too). With ``dpi`` None the figures stay inline SVG,
    each placed as its :func:`figure_mark` for the markup to replace.

    A PDF report's layout needs a figure only when WeasyPrint reaches it: drawn by
    another process meanwhile (:func:`fi_design.report.render_report` with an executor),
    the figures cost the layout no time; an HTML report's are drawn by several
    processes at once.

    Parameters
    ----------
    dpi : float or None, optional
        Resolution [dots per inch] (default :data:`RASTER_DPI`); None: SVG.

    Yields
    ------
    DeferredFigures
        The figures placed within the block.
    """
    figures = DeferredFigures(dpi)
    token = _DEFERRED.set(figures)
    try:
        with raster_figures(dpi) if dpi is not None else contextlib.nullcontext():
            yield figures
    finally:
        _DEFERRED.reset(token)


def figure_from(make: Callable[[], Any], name: str) -> str:
    """A figure for a report page from its maker: :func:`figure_markup` of ``make()``, or
    within :func:`deferred_figures` an ``<img>`` pointing at ``figure:NAME`` (not drawn).

    Parameters
    ----------
    make : callable
        Returns the :class:`matplotlib.figure.Figure`.
    name : str
        The figure's name, unique within the report (letters, digits, ``-``, ``_``).

    Returns
    -------
    str
        An ``<svg>`` or ``<img>`` element (deferred SVG: its :func:`figure_mark`).
    """
    figures = _DEFERRED.get()
    if figures is None:
        return figure_markup(make(), name)
    if name in figures.makers:
        raise ArgumentError(f"two report figures are named {name!r}")
    figures.makers[name] = make
    if figures.dpi is None:
        return figure_mark(name)
    return f'<img src="{FIGURE_SCHEME}:{name}" alt="">'


def png_img(png: bytes, width_pt: float | None = None, alt: str = "") -> str:
    """An ``<img>`` element carrying ``png`` as a data URL, ``width_pt`` wide [pt] if given."""
    from markupsafe import escape

    style = "" if width_pt is None else f' style="width:{fixed(width_pt, 2)}pt"'
    data = base64.b64encode(png).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{escape(alt)}"{style}>'


def figure_markup(fig: Any, prefix: str) -> str:
    """A figure for a report page: inline SVG (:func:`figure_svg`), or a PNG image inside
    :func:`raster_figures`.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    prefix : str
        Prefix of the SVG's ids (see :func:`figure_svg`).

    Returns
    -------
    str
        An ``<svg>`` or ``<img>`` element; CSS sizes either to the text width.
    """
    dpi = raster_dpi()
    if dpi is None:
        return figure_svg(fig, prefix)
    return png_img(rgb_png(fig, dpi))


def rgb_png(fig: Any, dpi: float) -> bytes:
    """A figure drawn at ``dpi`` as an opaque 8-bit RGB PNG (zlib's default compression).

    For a PDF: an opaque RGB PNG goes into the file as it is (its compressed
    rows, see :func:`fi_design.report.render.write_document`), where WeasyPrint
    would decode any other image and compress it again (an RGBA image twice,
    colour and alpha apart); compressed as WeasyPrint would, the PDF keeps its size.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (its face colour is the background).
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    bytes
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba())
    buf = io.BytesIO()
    Image.fromarray(rgba[..., :3]).save(buf, format="png")
    return buf.getvalue()


def png_size(fig: Any, dpi: float) -> tuple[int, int]:
    """The size of :func:`rgb_png`'s image of a figure at ``dpi`` [pixels], without drawing it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    tuple of int
        (width, height).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig.set_dpi(dpi)
    width, height = FigureCanvasAgg(fig).get_width_height(physical=True)
    return int(width), int(height)


def figure_bytes(fig: Any, fmt: str = "svg") -> bytes:
    """Render a figure to SVG or PNG bytes, reproducibly (no date, fixed SVG ids).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    fmt : {"svg", "png"}
        Output format.

    Returns
    -------
    bytes
    """
    import matplotlib

    fmt = fmt.lower().lstrip(".")
    if fmt not in ("svg", "png"):
        raise ArgumentError(f"unsupported figure format {fmt!r}; use svg or png")
    buf = io.BytesIO()
    meta = {"Date": None} if fmt == "svg" else {"Software": None}
    with matplotlib.rc_context({"svg.hashsalt": "fi_design", "svg.fonttype": "path"}):
        fig.savefig(buf, format=fmt, dpi=150 if fmt == "png" else None, metadata=meta)
    return buf.getvalue()
