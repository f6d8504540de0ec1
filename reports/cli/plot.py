"""The ``plot`` verb: one figure of one view of presets, or of a measured table against models.

``microcyl plot VIEW SOURCE... -o FILE``: the views are those of the report (lobes, slices,
hemisphere, masking, albedo, reciprocity) and ``table`` (a measured table against presets and
a fit: every incidence in the plane, a panel each, and a line saying what was left out; a
table of scattered pairs, such as a ``microcyl plan`` design, gets a view of every point
instead). Several presets overlay (or sit in one row each where a view is an image). The figure
is drawn by the plot functions of :mod:`reports.plots`; the format comes from the suffix of
FILE (PNG at ``--dpi``, PDF and SVG as vector graphics).
"""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

import numpy as np

import brdf
import gonio
from analysis import sources
from analysis.fit.medians import median_fabric
from analysis.fit.results import read_results
from gonio.jsonplain import meta_text
from analysis.views import compute_table_scatter, is_scattered, table_coverage
from analysis.views.table import write_table_data
from reports.cli import lazy
from reports.cli import options as cliutil

__all__ = ["register", "run_plot", "VIEWS", "fitted_fabric", "fitted_model", "parse_planes",
           "fit_note"]

#: The views of ``microcyl plot``.
VIEWS = ("lobes", "slices", "hemisphere", "masking", "albedo", "reciprocity", "table")
#: Default incidences per view, degrees (``table``: every incidence in the plane).
_THETA_I = {"lobes": (0.0, 30.0, 60.0), "slices": (30.0,), "hemisphere": (45.0,),
            "masking": (60.0,), "albedo": (), "reciprocity": (), "table": ()}
_FORMATS = (".png", ".pdf", ".svg")
_PLANES = {"warp": 0.0, "weft": 90.0, "diagonal": 45.0}


def register(sub):
    """Add ``plot`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "plot", help="draw one view of presets or a measured table (PNG, PDF, SVG)",
        description="Draw one figure: VIEW of the presets SOURCE... (several overlay), or for "
                    "'table' a measured table (SOURCE) against presets (further SOURCEs, "
                    "--preset) and a fit (--fit DIR). The format comes from the suffix of FILE.")
    p.add_argument("view", choices=VIEWS, metavar="VIEW", help=", ".join(VIEWS))
    p.add_argument("sources", nargs="*", metavar="FABRIC|TABLE",
                   help="fabrics: " + sources.accepted() + "; for 'table' a table file "
                        "first")
    p.add_argument("--fabric", action="append", default=None, metavar="FABRIC",
                   help="a FABRIC given as an option (repeatable): drawn as SOURCEs are")
    p.add_argument("-o", "--output", required=True, metavar="FILE",
                   help="output file: .png, .pdf or .svg")
    p.add_argument("--dpi", type=int, default=200, help="PNG resolution (default 200)")
    p.add_argument("--size", type=_size, default=None, metavar="W,H",
                   help="figure size in inches (default: from the panels)")
    p.add_argument("--channel", choices=("luminance", "r", "g", "b", "rgb"), default=None,
                   help="what of f_r is drawn (default luminance; rgb for one fabric's slices)")
    p.add_argument("--theta-i", type=_angles, default=None, metavar="DEG[,DEG...]",
                   help="incidence angles in degrees, e.g. 30,60 (table: those of the "
                        "table's incidences to draw; default all)")
    p.add_argument("--plane", type=parse_planes, default=None, metavar="warp|weft|45|DEG",
                   help="planes of incidence: warp, weft, diagonal or azimuths in degrees, "
                        "comma-separated (default warp,45,weft for lobes, else warp)")
    p.add_argument("--scale", choices=("log", "linear", "normalized"), default="log",
                   help="lobes' radial scale; normalized: linear, each curve / its peak")
    p.add_argument("--resolution", type=int, default=None, metavar="N",
                   help="samples per curve or image side (default: the view's)")
    p.add_argument("--fit", default=None, metavar="DIR",
                   help="table: a fit's folder (or its results.json) drawn as a model")
    p.add_argument("--preset", action="append", default=None, metavar="NAME",
                   help="table: a preset drawn as a model (repeatable); also the fitted preset "
                        "when the fit does not say")
    p.add_argument("--data", default=None, metavar="FILE.csv",
                   help="table: also write what was drawn at the measured points, one row "
                        "per point and curve: curve,theta_i,phi_i,theta_o,phi_o,f_r (curve "
                        "'measured' or a model's label; angles in degrees, f_r in 1/sr; each "
                        "model at every measured point's own angles)")
    cliutil.add_fabric_options(p)
    p.set_defaults(func=run_plot)


def _size(text: str) -> tuple[float, float]:
    try:
        w, h = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected W,H in inches, got {text!r}") from None
    if not (0.5 <= w <= 50 and 0.5 <= h <= 50):
        raise argparse.ArgumentTypeError(f"W and H must be in [0.5, 50] inches, got {text!r}")
    return w, h


def _angles(text: str) -> tuple[float, ...]:
    try:
        vals = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected degrees such as 30,60, got {text!r}") \
            from None
    if not all(math.isfinite(v) and 0.0 <= v < 90.0 for v in vals):
        raise argparse.ArgumentTypeError(f"angles must be in [0, 90) degrees, got {text!r}")
    return vals


def parse_planes(text: str) -> tuple[float, ...]:
    """Planes of incidence: ``warp``, ``weft``, ``diagonal`` or azimuths in degrees.

    Examples
    --------
    >>> parse_planes("warp,45,weft")
    (0.0, 45.0, 90.0)
    """
    out = []
    for item in text.split(","):
        item = item.strip().lower()
        try:
            out.append(_PLANES[item] if item in _PLANES else float(item))
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected warp, weft, diagonal or degrees, got {item!r}") from None
        if not (math.isfinite(out[-1]) and -360.0 <= out[-1] <= 360.0):
            raise argparse.ArgumentTypeError(f"plane must be in [-360, 360] degrees, "
                                             f"got {item!r}")
    return tuple(out)


def _fabric_texts(args) -> list[str]:
    """The FABRICs named: SOURCEs (after the table of 'table'), then each --fabric."""
    names = list(args.sources[1:] if args.view == "table" else args.sources)
    return names + list(args.fabric or ())


def _check(args) -> None:
    """Every option checked before any work."""
    suffix = Path(args.output).suffix.lower()
    if suffix not in _FORMATS:
        raise ValueError(f"-o must end in .png, .pdf or .svg; got {args.output!r}")
    if not 10 <= args.dpi <= 1200:
        raise ValueError(f"--dpi must be in [10, 1200]; got {args.dpi}")
    if args.resolution is not None and not 3 <= args.resolution <= 2000:
        raise ValueError(f"--resolution must be in [3, 2000]; got {args.resolution}")
    names = _fabric_texts(args)
    for name in args.preset or ():
        brdf.check_preset(name)
    if len(set(names)) != len(names):
        raise ValueError(f"a fabric is given twice: {', '.join(names)}")
    if args.view == "table" and not args.sources:
        raise ValueError("table: give the table file first (plot table TABLE [FABRIC...])")
    if args.view != "table" and not names:
        raise ValueError(f"{args.view}: give at least one FABRIC (positional or --fabric)")
    if args.view == "table" and not os.path.lexists(args.sources[0]):  # a FIFO: gonio.read
        raise ValueError(f"table: no such file {args.sources[0]!r}")
    if args.view != "table" and (args.fit or args.preset):
        raise ValueError("--fit and --preset apply to the 'table' view only")
    if args.view == "table" and not (names or args.preset or args.fit):
        raise ValueError("table: give a fabric (SOURCE, --fabric or --preset) or --fit DIR "
                         "to compare the table with")
    if args.data is not None and args.view != "table":
        raise ValueError("--data applies to the 'table' view only")
    if args.data is not None and Path(args.data).suffix.lower() != ".csv":
        raise ValueError(f"--data must end in .csv; got {args.data!r}")
    if args.data is not None and not Path(args.data).resolve().parent.is_dir():
        raise ValueError(f"--data: no such folder {str(Path(args.data).resolve().parent)!r}")
    if args.view == "table" and args.channel == "rgb":
        raise ValueError("--channel for 'table' must be luminance, r, g or b; got 'rgb'")
    out = Path(args.output).resolve().parent
    if not out.is_dir():
        raise ValueError(f"-o: no such folder {str(out)!r}")


def _check_incidences(table, args) -> None:
    plane_incidences = lazy.plots().fit.plane_incidences
    phi = (args.plane or (0.0,))[0]
    have = plane_incidences(table, phi)
    for t in args.theta_i or ():
        if not np.any(np.abs(have - t) <= 0.5):
            raise ValueError(f"--theta-i must be among the table's incidences in the plane "
                             f"{phi:g} degrees ({', '.join(f'{h:g}' for h in have)}); "
                             f"got {t:g}")


def fitted_fabric(fit, preset=None) -> tuple[brdf.Fabric, str]:
    """The fabric of a fit's posterior medians and its preset
    (:func:`analysis.fit.median_fabric`); ``fit`` is a fit's folder or its ``results.json``,
    ``preset`` names the preset where ``fit_config.json`` does not."""
    src = sources.resolve(fit, what="--fit", preset=preset)
    return src.brdf, src.preset


def _medians(fit, preset):
    """:func:`analysis.fit.median_fabric` of ``fit`` (a fit's folder or its results.json),
    its errors naming --fit."""
    path = Path(fit)
    try:
        return median_fabric(path if path.is_dir() else path.parent, preset=preset)
    except ValueError as exc:
        raise ValueError(f"--fit {str(fit)!r}: {exc}") from None


def fitted_model(fit, preset=None):
    """The model of a fit at its posterior medians, to draw against its table, and its label:
    the median fabric (tangent offsets scaled by the fit's ``tangent_scale``) times the fit's
    overall ``scale`` (:attr:`analysis.fit.MedianFabric.model`); the label names the preset
    (a baseline model's fit: the model) and a scale other than 1."""
    m = _medians(fit, preset)
    scale = "" if m.scale == 1.0 else f", × {m.scale:.3g}"
    return m.model, f"fit ({m.preset if m.is_fabric else m.model_name}{scale})"


def _models(args) -> dict:
    """Label -> BRDF of the FABRICs named (and, for 'table', each --preset), with the
    variant flags given; resolved before any drawing."""
    texts = list(dict.fromkeys(_fabric_texts(args) + list(args.preset or ())))
    return {s.label: s.brdf for s in sources.resolve_all(
        texts, options=cliutil.fabric_options(args))}


def fit_note(fit, label: str) -> str | None:
    """A line for the figure when the fit drawn (``--fit``: its folder or results.json) is
    not adequate or did not converge, from its results.json; None when neither."""
    path = Path(fit)
    doc = read_results(path if path.is_file() else path / "results.json")
    kinds = sorted({str(w.get("kind")) for w in doc.get("warnings") or []
                    if isinstance(w, dict)})
    said = []
    if doc.get("adequate") is False:
        said.append("NOT ADEQUATE (the model does not describe the table to within its noise)")
    if doc.get("converged") is False:
        said.append("NOT converged")
    if not said:
        return None
    warned = (f"; {len(kinds)} kinds of warning: {', '.join(map(meta_text, kinds))}" if kinds
              else "")
    return f"{label}: " + ", ".join(said) + warned


def _table_figure(args, models, plot_views, opts):
    """The figure of ``plot table`` (a plane's panels, or every point of a scattered table),
    its ``--data`` CSV, and the line of what was left out (None when nothing was)."""
    notes = []
    if args.fit:
        model, label = fitted_model(args.fit, (args.preset or [None])[0])
        models[label] = model
        notes.append(fit_note(args.fit, label))
    table = gonio.read(args.sources[0])
    phi = (args.plane or (0.0,))[0]
    source = Path(args.sources[0]).name
    if is_scattered(table, phi):
        if args.theta_i:
            raise ValueError("--theta-i: the table's pairs are scattered (no incidence in the "
                             f"plane {phi:g} degrees holds a lobe of 3 points); its view shows "
                             "every point")
        view = compute_table_scatter(table, models, quantity=args.channel or "luminance")
        note = plot_views.coverage_note(table_coverage(table, view.rows))
        fig = plot_views.table_scatter_view(table, models, channel=args.channel,
                                            scale=args.scale, source=source, view=view,
                                            notes=[note, *notes])
        rows = view.data_rows()
    else:
        _check_incidences(table, args)
        panels = plot_views.table_view_panels(table, models, channel=args.channel,
                                              theta_i=args.theta_i, planes=args.plane,
                                              resolution=args.resolution)
        drawn = np.concatenate([p.points["rows"] for p in panels])
        note = plot_views.coverage_note(table_coverage(table, drawn, phi))
        fig = plot_views.table_view(table, models, source=source, panels=panels,
                                    notes=[note, *notes], **opts)
        rows = plot_views.table_view_data(table, models, panels=panels)
    if args.data is not None:      # the numbers the figure drew at the measured points
        write_table_data(args.data, rows)
    return fig, "; ".join(n for n in (note, *notes) if n) or None


def run_plot(args):
    _check(args)
    models = _models(args)
    others = [label for label, b in models.items() if not isinstance(b, brdf.Fabric)]
    if args.view == "masking" and others:
        raise ValueError(f"masking: {', '.join(others)} is no microcylinder fabric (a fit of "
                         f"a baseline model): the view switches the microcylinder's masking")
    plot_views, save_figure = lazy.plots().views, lazy.plots().common.save_figure

    opts = dict(channel=args.channel, theta_i=args.theta_i, planes=args.plane,
                scale=args.scale, resolution=args.resolution)
    if args.view == "table":
        fig, note = _table_figure(args, models, plot_views, opts)
        if note:
            print(note)
    else:
        fig = plot_views.VIEW_FUNCTIONS[args.view](models, **opts)
    if args.size is not None:
        fig.set_size_inches(*args.size)
    path = save_figure(fig, args.output, dpi=args.dpi)
    print(f"wrote {path} ({args.view}, {len(fig.axes)} axes)")
    if args.data is not None:
        print(f"wrote {args.data} (the points drawn)")
    return 0

