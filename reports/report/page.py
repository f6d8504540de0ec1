"""Where a section writes: its fabric's folder of figures and data files."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import struct
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure
from matplotlib.text import Text

from gonio.csvcells import text_cells
from reports.plots.common import FONT, save_figure
from reports.plots.halfdisc import HalfDiscAxes
from reports.report.folder import write_file
from reports.report.markup import Markup, html, plain_json, url

__all__ = ["Page", "new_figure", "replace_3d", "figure_html", "smallest_font", "png_size",
           "display_width", "MIN_TEXT_PX", "MAX_DISPLAY_PX", "WIDE_PX"]

#: The smallest height (CSS px) a figure's text is shown at (its font size as displayed).
MIN_TEXT_PX = 13.0
#: The widest a figure is shown (CSS px): the page's column at a 1400 px window.
MAX_DISPLAY_PX = 1320
#: A figure shown wider than this spans the page instead of one cell of the grid.
WIDE_PX = 640


@dataclasses.dataclass
class Page:
    """One fabric's page, as its sections see it.

    Attributes
    ----------
    root : Path
        The (temporary) report folder.
    folder : str
        Sub-folder of ``root`` for this page's files.
    fabric : object
        The BRDF shown.
    q : dict
        Resolutions (a value of :data:`reports.report.QUALITIES`).
    preset : str or None
        The preset name when ``fabric`` is that preset with default options, else None.
    fit_results : path or None
        ``results.json`` of a fit of this fabric.
    """

    root: Path
    folder: str
    fabric: Any
    q: dict
    preset: str | None = None
    fit_results: Any = None

    def path(self, filename: str) -> Path:
        """The path of ``filename`` in the page's folder (created)."""
        d = self.root / self.folder
        d.mkdir(exist_ok=True)
        return d / filename

    def rel(self, filename: str) -> str:
        """``filename``'s link relative to the report folder."""
        return f"{self.folder}/{filename}"

    def figure(self, fig, filename: str, caption: str) -> Markup:
        """Save ``fig`` atomically beside the page, close it, return its <figure> HTML (a
        cell of the page's grid; the image links to itself at full size)."""
        try:
            font_pt = smallest_font(fig)
            path = save_figure(fig, self.path(filename), dpi=self.q["dpi"])
        finally:
            _close(fig)
        width, _ = png_size(path)
        font_px = font_pt * self.q["dpi"] / 72.0
        return figure_html(self.rel(filename), caption, width=display_width(width, font_px),
                           font_px=font_px)

    def json(self, filename: str, data) -> Markup:
        """Write ``data`` as strict JSON beside the page, return a link to it."""
        write_file(self.path(filename), json.dumps(plain_json(data), indent=1))
        return self.link(filename)

    def link(self, filename: str) -> Markup:
        """A link to ``filename`` in the page's folder, named by the file's name."""
        return html('<a href="{}">{}</a>', url(self.rel(filename)), filename)

    def csv(self, filename: str, header: list[str], rows) -> Markup:
        """Write ``rows`` as CSV (floats to 9 digits; text cells through
        :func:`gonio.csvcells.text_cell`) beside the page, return a link to it."""
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(text_cells(header))
        for row in rows:
            w.writerow(text_cells(f"{v:.9g}" if isinstance(v, (float, np.floating)) else v
                                  for v in row))
        write_file(self.path(filename), buf.getvalue())
        return self.link(filename)


def smallest_font(fig) -> float:
    """The smallest font size (points) of the visible, non-empty text of ``fig``."""
    sizes = [t.get_fontsize() for t in fig.findobj(Text)
             if t.get_visible() and t.get_text().strip()]
    return float(min(sizes)) if sizes else float(FONT["small"])


def png_size(path) -> tuple[int, int]:
    """(width, height) in pixels from a PNG file's header."""
    with open(path, "rb") as fh:
        head = fh.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path} is not a PNG file")
    return struct.unpack(">II", head[16:24])


def display_width(natural_px: int, font_px: float) -> int:
    """The width (CSS px) a figure is shown at: its smallest text at least
    :data:`MIN_TEXT_PX` high (a low-dpi preview, ``--quality fast``, scaled up: blurred
    but readable, and laid out as the default quality lays it out), and no less than 0.6
    of its natural size; at most :data:`MAX_DISPLAY_PX`, the width of a page's column at
    1400 px (a figure wider than that with text too small shows it below the limit, which
    the browser test catches).

    Examples
    --------
    >>> display_width(2200, 22.2)        # 11 in at 200 dpi, 8 pt text: full width
    1320
    >>> display_width(920, 22.2)         # one panel: 8 pt text shown at 13.3 px
    552
    >>> display_width(230, 5.56)         # the same panel at 50 dpi: shown as large
    538
    """
    scale = max(MIN_TEXT_PX / font_px, 0.6) if font_px > 0 else 0.6
    return int(min(round(natural_px * scale), MAX_DISPLAY_PX))


def figure_html(src: str, caption: str, *, width: int | None = None,
                font_px: float | None = None) -> Markup:
    """A ``<figure>`` of the grid: the image, a link to it at full size, its caption.

    ``width`` is the width (CSS px) to show the image at, a figure wider than one column
    spanning the page; ``font_px`` the height of its smallest text in the image's own pixels
    (for the check that text shows at least :data:`MIN_TEXT_PX` high).

    Examples
    --------
    >>> str(figure_html("a/b.png", "x")).split("<img")[0]
    '<figure><a href="a/b.png" title="x (click for full size)">'
    >>> 'class="wide"' in figure_html("a.png", "x", width=1200, font_px=22.2)
    True
    """
    if width is None:
        return html('<figure><a href="{src}" title="{text} (click for full size)">'
                    '<img src="{src}" alt="{text}" loading="lazy"></a>'
                    "<figcaption>{text}</figcaption></figure>", src=url(src), text=caption)
    return html('<figure{wide}><a href="{src}" title="{text} (click for full size)">'
                '<img src="{src}" alt="{text}" width="{width}" data-font-px="{font:.2f}" '
                'loading="lazy" style="width:{width}px"></a>'
                '<figcaption style="max-width:{cap}px">{text}</figcaption></figure>',
                wide=Markup(' class="wide"') if width > WIDE_PX else Markup(""),
                src=url(src), text=caption, width=int(width), font=float(font_px or 0.0),
                cap=max(int(width), 480))


def _close(fig):
    if plt.fignum_exists(getattr(fig, "number", -1)):
        plt.close(fig)


def new_figure(ncols=1, nrows=1, figsize=None, polar=False, **kw):
    """A constrained-layout Figure (not registered with pyplot) and its list of axes
    (``polar``: the lobes' half discs, :class:`reports.plots.halfdisc.HalfDiscAxes`)."""
    fig = Figure(figsize=figsize or (4.6 * ncols, 3.8 * nrows), layout="constrained")
    if polar:
        kw["axes_class"] = HalfDiscAxes
    axes = [fig.add_subplot(nrows, ncols, k + 1, **kw)
            for k in range(ncols * nrows)]
    return fig, axes


def replace_3d(fig, ax):
    """Replace ``ax`` in ``fig`` by a 3-D axes in the same place; return it."""
    spec = ax.get_subplotspec()
    ax.remove()
    return fig.add_subplot(spec, projection="3d")
