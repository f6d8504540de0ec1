"""Where a section writes: its fabric's folder of figures and data files."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from reports._plotting import save_figure
from reports.report.folder import write_file
from reports.report.markup import Markup, html, plain_json, url

__all__ = ["Page", "new_figure", "replace_3d", "figure_html"]


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
            save_figure(fig, self.path(filename), dpi=self.q["dpi"])
        finally:
            _close(fig)
        return figure_html(self.rel(filename), caption)

    def json(self, filename: str, data) -> Markup:
        """Write ``data`` as strict JSON beside the page, return a link to it."""
        write_file(self.path(filename), json.dumps(plain_json(data), indent=1))
        return self.link(filename)

    def link(self, filename: str) -> Markup:
        """A link to ``filename`` in the page's folder, named by the file's name."""
        return html('<a href="{}">{}</a>', url(self.rel(filename)), filename)

    def csv(self, filename: str, header: list[str], rows) -> Markup:
        """Write ``rows`` as CSV (floats to 9 digits) beside the page, return a link to it."""
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(header)
        for row in rows:
            w.writerow([f"{v:.9g}" if isinstance(v, (float, np.floating)) else v for v in row])
        write_file(self.path(filename), buf.getvalue())
        return self.link(filename)


def figure_html(src: str, caption: str) -> Markup:
    """A ``<figure>`` of the grid: the image, a link to it at full size, its caption.

    Examples
    --------
    >>> str(figure_html("a/b.png", "x")).split("<img")[0]
    '<figure><a href="a/b.png" title="x (click for full size)">'
    """
    return html('<figure><a href="{src}" title="{text} (click for full size)">'
                '<img src="{src}" alt="{text}" loading="lazy"></a>'
                "<figcaption>{text}</figcaption></figure>", src=url(src), text=caption)


def _close(fig):
    if plt.fignum_exists(getattr(fig, "number", -1)):
        plt.close(fig)


def new_figure(ncols=1, nrows=1, figsize=None, polar=False, **kw):
    """A constrained-layout Figure (not registered with pyplot) and its list of axes."""
    fig = Figure(figsize=figsize or (4.6 * ncols, 3.8 * nrows), layout="constrained")
    axes = [fig.add_subplot(nrows, ncols, k + 1, projection="polar" if polar else None, **kw)
            for k in range(ncols * nrows)]
    return fig, axes


def replace_3d(fig, ax):
    """Replace ``ax`` in ``fig`` by a 3-D axes in the same place; return it."""
    spec = ax.get_subplotspec()
    ax.remove()
    return fig.add_subplot(spec, projection="3d")
