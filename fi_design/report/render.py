"""Rendering: one jinja environment, HTML from a context, PDF from the HTML (WeasyPrint).

The templates live in the repository's top-level ``templates/`` folder; the
wheel carries them as ``fi_design/templates`` (:func:`template_dir` finds
either). Every section template extends ``section.html.jinja`` and uses only
``extends``, ``block``, ``for`` and ``if``; numbers are formatted by the
filters of :mod:`fi_design.report.filters`. Files are written atomically
(:mod:`fi_design.output`).
"""

from __future__ import annotations

import contextlib
import functools
import gc
import logging
import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Callable

from ..errors import OutputError
from .context import build_context
from .filters import FILTERS

__all__ = ["FORMATS", "template_dir", "environment", "render_html", "output_format",
           "write_document", "render_report", "report_figures", "render_document"]

log = logging.getLogger(__name__)

#: Output formats by file extension.
FORMATS = {".html": "html", ".pdf": "pdf"}


def template_dir() -> Path:
    """The folder holding the report templates.

    An installed wheel carries them as ``fi_design/templates``; a source tree
    (an editable install) keeps them in the repository's top-level
    ``templates/`` folder, next to the package.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    FileNotFoundError
        Neither place holds ``report.html.jinja`` (a broken installation).
    """
    package = Path(__file__).resolve().parents[1]
    for candidate in (package / "templates", package.parent / "templates"):
        if (candidate / "report.html.jinja").is_file():
            return candidate
    raise FileNotFoundError(f"fi_design: report templates not found in {package / 'templates'} "
                            f"or {package.parent / 'templates'}; reinstall the package")


@functools.lru_cache(maxsize=1)
def environment() -> Any:
    """The one jinja environment of the reports: autoescape, ``StrictUndefined``, filters.

    Returns
    -------
    jinja2.Environment
        Loads from :func:`template_dir`; the filters ``num``, ``qty`` and
        ``unit`` (:data:`fi_design.report.filters.FILTERS`).
    """
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(template_dir())),
        autoescape=jinja2.select_autoescape(default=True, default_for_string=True),
        undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True,
        keep_trailing_newline=True)
    env.filters.update(FILTERS)
    return env


def render_html(context: dict) -> str:
    """Render a report context (from :func:`~fi_design.report.context.build_context`) to HTML.

    Parameters
    ----------
    context : dict
        ``meta``, ``sections`` (each with ``id``, ``number``, ``title`` and
        ``template``) and the data each section's template reads under its
        ``id``.

    Returns
    -------
    str
        One self-contained HTML document (inline CSS and SVG, no script).
    """
    from markupsafe import Markup

    env = environment()
    body = [Markup(env.get_template(section["template"]).render(
        section=section, data=context.get(section["id"]), meta=context["meta"],
        context=context)) for section in context["sections"]]
    css = Markup((template_dir() / "report.css").read_text(encoding="utf-8"))
    return env.get_template("report.html.jinja").render(
        meta=context["meta"], sections=context["sections"], body=body, css=css)


def output_format(path: str | os.PathLike) -> str:
    """The format of a report file, from its extension.

    Parameters
    ----------
    path : str or os.PathLike
        The report's file name.

    Returns
    -------
    str
        ``"html"`` or ``"pdf"``.

    Raises
    ------
    fi_design.errors.OutputError
        Any other extension.
    """
    ext = Path(path).suffix.lower()
    if ext not in FORMATS:
        raise OutputError(f"{path}: a report must end with .html or .pdf")
    return FORMATS[ext]


def write_document(html: str, path: str | os.PathLike, *, figures: Any = None) -> Path:
    """Write a rendered report as HTML, or as a PDF (A4, WeasyPrint) made from it, atomically.

    Parameters
    ----------
    html : str
        The document (:func:`render_html`).
    path : str or os.PathLike
        ``.html`` or ``.pdf``; an existing file is replaced.
    figures : object, optional
        A PDF's figures placed by name (``<img src="figure:NAME">``, see
        :func:`fi_design.plots.deferred_figures`): ``figures.png(name)`` gives
        the PNG bytes when the layout reaches the figure; where
        ``figures.stand_in(name)`` gives PNG bytes (an image of the figure's
        size only, drawn elsewhere meanwhile), the layout takes those and the
        PDF the figure's own rows, asked for when the PDF is written.

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    fi_design.errors.OutputError
        Wrong extension, or the file cannot be written.
    """
    from ..output import atomic_path, write_atomic

    out = Path(path)
    if output_format(out) == "html":
        return write_atomic(out, html)
    # WeasyPrint logs every CSS property it does not know at WARNING; the report's
    # screen-only rules are expected to be skipped.
    logging.getLogger("weasyprint").setLevel(logging.ERROR)
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    _import_weasyprint()
    from weasyprint import HTML
    from weasyprint.urls import FatalURLFetchingError

    def laid_out(stand_ins: bool) -> tuple[Any, Any]:
        fetcher = _self_contained(figures, stand_ins=stand_ins)
        try:
            return HTML(string=html, base_url=None, url_fetcher=fetcher).render(), fetcher
        except FatalURLFetchingError:
            if fetcher.failed is not None:  # a figure's own error, not WeasyPrint's wrapping
                raise fetcher.failed from None
            raise

    with _collector_paused():
        document, fetcher = laid_out(True)
        with atomic_path(out) as tmp:
            with _png_as_is(getattr(figures, "png", None)) as replaced:
                document.write_pdf(str(tmp))
            if fetcher.stood_in - replaced:  # a stand-in went into the file as it was laid out
                log.warning("the PDF's figures were not put in place of their stand-ins "
                            "(%s): the report is laid out again with the figures",
                            ", ".join(sorted(fetcher.stood_in - replaced)))
                laid_out(False)[0].write_pdf(str(tmp))
    return out


@contextlib.contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector paused for the block (reference counting goes on).

    WeasyPrint builds some 10^5 objects for a report of 26 pages (styles, boxes, lines),
    and the collector traversed them, and the process's own, again and again as they
    grew: about a fifth of the PDF's time (the paper setup's, written in a process
    holding a design: 0.6 s of CPU of about 3 s). What is left in reference cycles is
    collected after the block, when the collector next runs (peak memory +8 MB).
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


@contextlib.contextmanager
def _png_as_is(figure: Callable[[str], bytes] | None = None) -> Iterator[set[str]]:
    """While WeasyPrint writes a PDF, an opaque 8-bit RGB PNG goes into it as it is.

    WeasyPrint decodes every PNG and encodes it again to take the compressed pixel rows
    (the IDAT chunks) that a PDF image stream holds as they are (``FlateDecode`` with
    the PNG predictors): 0.25 s of the paper report's 0.65 s of output for its 26
    images. A PNG that is already 8-bit RGB, not interlaced (what
    :func:`fi_design.plots.rgb_png` writes) has those rows: they are taken from the
    file. Any other image (a palette, an alpha channel, 16 bits, interlacing) is
    encoded again as before. A figure's stand-in (:func:`_stand_in`) is replaced by the
    figure, ``figure(name)`` (PNG bytes), which must be an RGB image of its size. The
    method taken over is WeasyPrint's own (60 and later, :func:`_rows_replaceable`); a
    WeasyPrint without it writes the PDF its own way, and no stand-in is laid out.
    Yields the set of the figures put in place of their stand-ins (filled as the PDF is
    written), which :func:`write_document` checks against the stand-ins laid out.
    """
    import io

    from PIL import Image
    from weasyprint.images import RasterImage

    replaced: set[str] = set()
    if not _rows_replaceable():  # another WeasyPrint: its own encoding, untouched
        yield replaced
        return
    encode = RasterImage.__dict__["_get_png_data"]

    def rows(pillow_image: Any) -> bytes:
        name = getattr(pillow_image, "info", {}).get(_STAND_IN_KEY)
        if name is not None and figure is not None:
            with Image.open(io.BytesIO(figure(name))) as real:
                if real.size != pillow_image.size or real.mode != "RGB":
                    raise RuntimeError(f"figure {name!r}: drawn {real.mode} {real.size}, "
                                       f"laid out as RGB {pillow_image.size}")
                data = _rgb_png_rows(real)
                replaced.add(name)
                return encode.__func__(real) if data is None else data
        data = _rgb_png_rows(pillow_image)
        return encode.__func__(pillow_image) if data is None else data

    RasterImage._get_png_data = staticmethod(rows)
    try:
        yield replaced
    finally:
        RasterImage._get_png_data = encode


def _rows_replaceable() -> bool:
    """Whether WeasyPrint's PNG encoder is the static method :func:`_png_as_is` takes over
    (WeasyPrint 60 and later): only then are figures' stand-ins laid out."""
    from weasyprint.images import RasterImage

    return isinstance(RasterImage.__dict__.get("_get_png_data"), staticmethod)


def _rgb_png_rows(pillow_image: Any) -> bytes | None:
    """The compressed pixel rows (the IDAT chunks, joined) of a PNG opened by Pillow, if
    it is 8-bit RGB without interlacing and its bytes are at hand; else None."""
    import io
    import struct
    import zlib

    fp = getattr(pillow_image, "fp", None)
    if (getattr(pillow_image, "format", None) != "PNG" or pillow_image.mode != "RGB"
            or not isinstance(fp, io.BytesIO)):
        return None
    data = fp.getvalue()
    if data[:8] != b"\x89PNG\r\n\x1a\n" or data[12:16] != b"IHDR":
        return None
    width, height, depth, colour, method, filtering, interlace = struct.unpack(
        "!IIBBBBB", data[16:29])
    if ((width, height) != pillow_image.size or depth != 8 or colour != 2
            or (method, filtering, interlace) != (0, 0, 0)):
        return None
    chunks, at = [], 8
    while at + 12 <= len(data):
        length, kind = struct.unpack("!I4s", data[at:at + 8])
        end = at + 8 + length
        if end + 4 > len(data) or data[end:end + 4] != struct.pack(
                "!I", zlib.crc32(data[at + 4:end])):
            return None  # truncated or damaged: left to Pillow's decoder
        body = data[at + 8:end]
        if kind == b"IDAT":
            chunks.append(body)
        elif kind == b"IEND":
            break
        at += 12 + length
    return b"".join(chunks) if chunks else None


#: The tEXt key of a figure's stand-in PNG; its value is the figure's name.
_STAND_IN_KEY = "fi-design-figure"


def _stand_in(name: str, width: int, height: int) -> bytes:
    """A white 8-bit RGB PNG of ``width`` x ``height`` pixels that names the figure it
    stands in for (a tEXt chunk): what WeasyPrint lays out while the figure is drawn
    elsewhere; :func:`_png_as_is` puts the figure's own rows into the PDF."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack("!I", len(body)) + kind + body
                + struct.pack("!I", zlib.crc32(kind + body)))

    row = b"\0" + b"\xff" * (3 * width)
    return (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack("!IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"tEXt", _STAND_IN_KEY.encode("latin-1") + b"\0"
                    + name.encode("latin-1", "replace"))
            + chunk(b"IDAT", zlib.compress(row * height, 1)) + chunk(b"IEND", b""))


def _import_weasyprint() -> None:
    """Import WeasyPrint, on Linux without ctypes' search for its libraries.

    WeasyPrint opens GLib, Pango, HarfBuzz and fontconfig by several names in turn
    through cffi, which asks :func:`ctypes.util.find_library` for every name that is
    not a file it can open; on Linux each such call runs ``ldconfig -p``, then gcc and
    ld when the name is unknown: some 200 processes, 0.3 s of the import's 0.7 s. Every
    list of names also holds the library's soname (``libpango-1.0.so.0``), which the
    dynamic loader finds by itself, as find_library would have: while WeasyPrint is
    imported, find_library answers None, and if that import fails it is made again the
    usual way.
    """
    import importlib
    import sys

    if "weasyprint" in sys.modules or not sys.platform.startswith("linux"):
        importlib.import_module("weasyprint")
        return
    import ctypes.util
    import io

    search = ctypes.util.find_library
    ctypes.util.find_library = lambda name: None
    try:  # WeasyPrint prints its installation advice when a library is missing
        with contextlib.redirect_stdout(io.StringIO()):
            importlib.import_module("weasyprint")
        return
    except Exception:  # a library only ctypes' search finds: the usual import below
        pass
    finally:
        ctypes.util.find_library = search
    importlib.import_module("weasyprint")


def _self_contained(figures: Any = None, *, stand_ins: bool = True) -> Any:
    """WeasyPrint's URL fetcher limited to ``data:`` URLs and the figures placed by name
    (``figure:NAME``, from ``figures``; their stand-ins where ``figures`` has them, the
    writing can replace them and ``stand_ins``; the fetcher's ``stood_in`` names them): the
    report is self-contained by design and makes no external request (any other URL is
    refused)."""
    from weasyprint.urls import URLFetcher, URLFetcherResponse

    from ..plots import FIGURE_SCHEME

    prefix = FIGURE_SCHEME + ":"
    # a stand-in only where the PDF's writing puts the figure in its place (_png_as_is)
    stand_in = getattr(figures, "stand_in", None) if stand_ins and _rows_replaceable() else None

    class Fetcher(URLFetcher):
        failed: Exception | None = None  # what drawing a figure raised
        stood_in: set[str] = set()  # the figures laid out as stand-ins

        def fetch(self, url: str, headers: Any = None) -> Any:
            if figures is not None and url.startswith(prefix):
                name = url[len(prefix):]
                try:
                    png = stand_in(name) if stand_in is not None else None
                    if png is None:
                        png = figures.png(name)
                    else:
                        self.stood_in = self.stood_in | {name}
                except Exception as exc:
                    self.failed = exc
                    raise
                return URLFetcherResponse(url, png, {"Content-Type": "image/png"})
            return super().fetch(url, headers)

    return Fetcher(allowed_protocols={"data"}, fail_on_errors=True)


def _checked_output(out: Path, force: bool, write: Callable[[], Path]) -> Path:
    """``write()`` a report at ``out`` that the current run has not checked (a library call):
    :func:`~fi_design.output.check_output` first (an existing file refused without
    ``force``, a directory or a missing folder at once), in a context of its own, so that
    the claim is this call's and the next call to the same path checks again. A path the
    run checked (the command line, with its ``--force``) is written as its claim allows."""
    import contextvars

    from ..output import check_output, claimed

    if claimed(out):
        return write()

    def checked() -> Path:
        check_output(out, force=force, extensions=tuple(FORMATS), force_flag="force=True")
        return write()

    return contextvars.copy_context().run(checked)


def render_report(result: Any, path: str | os.PathLike, *, date: Any = None,
                  command: str | None = None, design_map: Any = None,
                  progress: Callable[[str], None] | None = None,
                  executor: Any = None, force: bool = False) -> Path:
    """Write the report of a result as HTML or PDF (chosen by the extension).

    Presentation only: every number comes from ``result`` (and
    ``design_map``); nothing is simulated here.

    Parameters
    ----------
    result : DesignResult, SweepResult, StudyResult, RobustnessResult, RecommendResult,
             ReconcileResult, IdentificationResult or object
        What to report (:func:`~fi_design.report.context.build_context`). An
        object with ``report_sections()`` and ``report_title`` is rendered as
        a generic document.
    path : str or os.PathLike
        Output file, ``.html`` or ``.pdf``, written atomically. Any other
        extension, an existing file without ``force``, a directory or a missing
        folder raises before any work.
    date : str or datetime.date, optional
        Report date; default today (or ``SOURCE_DATE_EPOCH``).
    command : str, optional
        The command line, shown in the title block.
    design_map : fi_design.studies.DesignMap, optional
        Design reports: a crossover x stroke hunting map around the design
        point (:func:`fi_design.studies.design_map`), shown in its own section.
    progress : callable, optional
        ``progress(text)`` with a short message as the work proceeds.
    executor : concurrent.futures-style executor, optional
        A PDF's figures are drawn there (``submit``, one task a figure in the
        order the report places them; the result and ``design_map`` are sent
        with each) while this process lays the report out; the layout waits
        for a figure only when it reaches it. None draws them here as the
        layout reaches them. An HTML report's figures are drawn there from the
        first and here from the last at once (the same SVG).
    force : bool, optional
        Replace an existing file. Default False: an existing file is refused
        (``OutputError``), as the command line refuses it without ``--force``.

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    fi_design.errors.OutputError
        The extension is not .html or .pdf, the file exists and ``force`` is
        False, or the file cannot be written.
    fi_design.errors.ReportError
        ``result`` is of a kind there is no report for (a ``TypeError`` too).
    """
    out = Path(path)
    fmt = output_format(out)
    return _checked_output(out, force, lambda: _write_report(
        result, out, fmt, date=date, command=command, design_map=design_map,
        progress=progress, executor=executor))


def _write_report(result: Any, out: Path, fmt: str, *, date: Any, command: str | None,
                  design_map: Any, progress: Callable[[str], None] | None,
                  executor: Any) -> Path:
    """Write the report of :func:`render_report` at ``out`` (checked: its claim is this
    run's) in ``fmt`` (``"html"`` or ``"pdf"``); the parameters are render_report's."""
    if progress is not None:
        progress("drawing the report's figures ...")
    options = {} if design_map is None else {"design_map": design_map}
    from ..plots import deferred_figures

    if fmt == "html":
        if executor is None:
            html = render_html(build_context(result, date=date, command=command, **options))
        else:  # the figures drawn there and here at once, each put in its place
            with deferred_figures(None) as figures:
                context = build_context(result, date=date, command=command, **options)
            html = _svg_placed(render_html(context), figures, executor, result, options)
        if progress is not None:
            progress("writing the HTML ...")
        return write_document(html, out)

    with deferred_figures() as figures:
        context = build_context(result, date=date, command=command, **options)
    drawn = None
    if executor is not None and figures.makers:  # drawn there while the HTML is made here
        # one task a figure, in the order the layout needs them: the layout waits for the
        # figure it reaches, not for the last one
        key = _report_key(context)
        sizes = executor.submit(report_figure_sizes, result, options, key=key)
        # the result goes with every task (any worker of any pool can draw any figure); a
        # worker that made the report's figures for an earlier task keeps them by the key
        drawn = {name: executor.submit(report_figures, result, options, names=(name,), key=key)
                 for name in figures.makers}
    html = render_html(context)
    if progress is not None:
        progress("writing the PDF ...")
    return write_document(html, out, figures=_Figures(figures, drawn,
                                                      None if drawn is None else sizes))


def _report_key(placed: Any) -> str:
    """A name for one report's figure tasks (:func:`report_figures`' ``key``), unique across
    this process's reports and its workers' earlier ones."""
    return f"{os.getpid()}-{id(placed)}-{time.monotonic_ns()}"


def _svg_placed(html: str, figures: Any, executor: Any, result: Any, options: dict) -> str:
    """An HTML report's page with its deferred SVG figures in place (their
    :func:`~fi_design.plots.figure_mark`), drawn by the executor from the first and by this
    process from the last: this process takes each figure whose task it can still cancel,
    the executor the rest (a figure its worker fails is drawn here)."""
    from ..plots import figure_mark

    names = list(figures.makers)
    key = _report_key(figures)
    tasks = {name: executor.submit(report_figures, result, options, names=(name,), key=key,
                                   svg=True) for name in names}
    svg: dict[str, str] = {}
    for name in reversed(names):
        cancel = getattr(tasks[name], "cancel", None)
        if cancel is None or cancel() is not True:  # started there: so are those before it
            break
        svg[name] = figures.svg(name)
    for name in names:
        if name not in svg:
            try:
                svg[name] = tasks[name].result()[name]
            except Exception:  # the worker failed or is gone: the figure is drawn here
                log.info("the report's figure %r could not be drawn in a worker; drawing it "
                         "here", name, exc_info=True)
                svg[name] = figures.svg(name)
    for name in names:
        html = html.replace(figure_mark(name), svg[name], 1)
    return html


def report_figures(result: Any, options: dict, names: Any = None,
                   key: str | None = None, svg: bool = False) -> dict[str, Any]:
    """The figures of a PDF report, drawn: name -> PNG bytes (what an executor runs for
    :func:`render_report`, one figure a task); with ``svg``, an HTML report's: name -> the
    inline SVG (:meth:`fi_design.plots.DeferredFigures.svg`).

    Parameters
    ----------
    result : object
        What the report is of (:func:`render_report`); its figures are made once per
        ``key`` in this process.
    options : dict
        ``design_map`` when the report has one.
    names : sequence of str, optional
        Only these figures (default: every one).
    key : str, optional
        Names one report: the figures placed for it are kept in this process for the
        next call with the same key (the tasks of one report in one worker), so the
        report's context is built once.
    svg : bool, optional
        Inline SVG for an HTML report instead of PNG bytes.

    Returns
    -------
    dict
        The figures in the order the report places them.

    Raises
    ------
    KeyError
        A name the report does not place.
    """
    from ..plots import figure_svg, rgb_png

    figures, made = _placed(result, options, key)
    wanted = list(figures.makers) if names is None else list(names)
    with _collector_paused():  # a forked worker's collector would traverse the parent's heap
        if svg:
            return {name: figure_svg(made.pop(name), name) if name in made
                    else figures.svg(name) for name in wanted}
        return {name: rgb_png(made.pop(name), figures.dpi) if name in made
                else figures.png(name) for name in wanted}


def report_figure_sizes(result: Any, options: dict, key: str | None = None
                        ) -> dict[str, tuple[int, int]]:
    """The size of each figure of a PDF report as :func:`report_figures` draws it [pixels]:
    name -> (width, height); the figures are made (not drawn) and kept for
    :func:`report_figures` with the same ``key``.

    Parameters
    ----------
    result : object
        What the report is of (:func:`render_report`).
    options : dict
        ``design_map`` when the report has one.
    key : str, optional
        Names the report (:func:`report_figures`).

    Returns
    -------
    dict
        The figures' sizes in the order the report places them.
    """
    from ..plots import png_size

    figures, made = _placed(result, options, key)
    with _collector_paused():
        for name, make in figures.makers.items():
            made.setdefault(name, make())
        return {name: png_size(made[name], figures.dpi) for name in figures.makers}


def _placed(result: Any, options: dict, key: str | None) -> tuple[Any, dict]:
    """The figures placed for a report (DeferredFigures) and those made so far (name ->
    Figure), kept in this process for the report named ``key``."""
    global _PLACED

    from ..plots import deferred_figures

    if key is not None and _PLACED is not None and _PLACED[0] == key:
        return _PLACED[1], _PLACED[2]
    from .equations import equations_left_out

    with deferred_figures() as figures, equations_left_out():  # the figures' makers only
        build_context(result, **options)
    made: dict = {}
    _PLACED = None if key is None else (key, figures, made)
    return figures, made


#: What a worker keeps of the last report it draws for: (key, DeferredFigures, made).
_PLACED: tuple[str, Any, dict] | None = None


class _Figures:
    """A PDF's figures by name: from ``drawn`` (name -> a future of :func:`report_figures`
    for that figure, run elsewhere) when it has them, else drawn here from ``placed`` (the
    makers). With ``sizes`` (a future of :func:`report_figure_sizes`), the layout takes a
    stand-in of each figure's size (:meth:`stand_in`) and the figure itself is asked for
    when the PDF is written."""

    def __init__(self, placed: Any, drawn: Any, sizes: Any = None) -> None:
        self._placed = placed
        self._drawn = dict(drawn or {})
        self._sizes = sizes

    def stand_in(self, name: str) -> bytes | None:
        """A PNG of the figure's size that names it (:func:`_stand_in`), or None (no sizes:
        the figure itself is laid out)."""
        if self._sizes is None:
            return None
        try:
            size = self._sizes.result().get(name)
        except Exception:  # the worker failed or is gone: the figures are laid out as drawn
            log.info("the report's figure sizes could not be had from a worker",
                     exc_info=True)
            self._sizes = None
            return None
        return None if size is None else _stand_in(name, *size)

    def png(self, name: str) -> bytes:
        future = self._drawn.pop(name, None)
        if future is not None:
            try:
                return future.result()[name]
            except Exception:  # the worker failed or is gone: the figure is drawn here
                log.info("the report's figure %r could not be drawn in a worker; drawing it "
                         "here", name, exc_info=True)
        return self._placed.png(name)


def render_document(path: str | os.PathLike, *, title: str, spec: Any, sections: Any,
                    date: Any = None, command: str | None = None, kind: str = "report",
                    conclusion: str = "", force: bool = False) -> Path:
    """Write a generic report (HTML or PDF) from :class:`~fi_design.report.blocks.Section` values.

    The other commands' reports use this: the same title block, page layout,
    running header and appendix as the design report, with their own
    sections.

    Parameters
    ----------
    path : str or os.PathLike
        ``.html`` or ``.pdf``, written atomically; an existing file is refused
        without ``force``.
    title : str
        Report title.
    spec : fi_design.spec.Spec
        The spec the work started from.
    sections : sequence of Section
        The content.
    date : str or datetime.date, optional
        Report date (default today).
    command : str, optional
        The command line.
    kind : str, optional
        Short kind of report.
    conclusion : str, optional
        A summary paragraph shown first.
    force : bool, optional
        Replace an existing file (default False: refused with ``OutputError``).

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    fi_design.errors.OutputError
        Wrong extension, the file exists and ``force`` is False, or the file
        cannot be written.
    """
    from .context import document_context

    out = Path(path)
    output_format(out)

    def write() -> Path:
        ctx = document_context(title, spec, sections, date=date, command=command, kind=kind,
                               conclusion=conclusion)
        return write_document(render_html(ctx), out)

    return _checked_output(out, force, write)
