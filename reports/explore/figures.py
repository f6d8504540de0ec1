"""The explorer's Bokeh figures, one a view, and how a :class:`reports.explore.engine.Frame`
becomes their data: the polar lobe (linear, or three decades on a log radius), the hemisphere
and the theta_h x theta_d slice (log10 f_r in colour), the lit sphere (tone-mapped sRGB), the
directional albedo, and the masking terms and tangent curves of the microcylinder.

Each figure is named ``view-NAME`` (the page's ``data-testid``) and its data sources
``src-NAME...`` (the page counts their changes: ``data-version``).

Examples
--------
>>> tone_map(np.array([[[0.0, 0.0, 0.0], [10.0, 10.0, 10.0]]])).shape
(1, 2)
>>> polar(np.array([0.0]), np.array([2.0]), 2.0, log=False)
(array([0.]), array([1.]))
"""

from __future__ import annotations

import numpy as np
from bokeh.models import ColumnDataSource, HoverTool, LinearColorMapper
from bokeh.plotting import figure

__all__ = ["VIEWS", "SCALED", "make_figures", "update_figures", "tone_map", "polar",
           "DECADES"]

#: The views, in the page's order.
VIEWS = ("lobe", "hemisphere", "slice", "sphere", "albedo", "masking", "tangent")
#: The views drawn on the scale (linear or log): a change of scale redraws them.
SCALED = ("lobe", "hemisphere", "slice")
#: Decades of f_r the log radius and the log colour scales show below the peak.
DECADES = 3.0
#: The sphere's exposure: radiance (1/sr, unit irradiance) times this before tone mapping.
EXPOSURE = 4.0
_SIZE = 280


def tone_map(rgb: np.ndarray, exposure: float = EXPOSURE) -> np.ndarray:
    """Linear RGB radiance (n, m, 3) -> packed RGBA uint32 (n, m): exposure, Reinhard
    x / (1 + x), sRGB gamma 1/2.2, opaque."""
    x = np.clip(np.nan_to_num(rgb * exposure, nan=0.0, posinf=1e6), 0.0, None)
    c = np.clip(255.0 * (x / (1.0 + x)) ** (1.0 / 2.2), 0.0, 255.0).astype(np.uint32)
    return (255 << 24) | (c[..., 2] << 16) | (c[..., 1] << 8) | c[..., 0]


def _radius(f, peak, log):
    f = np.asarray(f, float)
    if peak <= 0 or not np.isfinite(peak):
        return np.zeros_like(f)
    if log:
        r = np.log10(np.clip(f, peak * 10.0 ** -DECADES, None) / peak) / DECADES + 1.0
    else:
        r = f / peak
    return np.clip(np.nan_to_num(r, nan=0.0), 0.0, 1.2)


def polar(theta_deg, f, peak, log):
    """(x, y) of a lobe on the unit half-disc: radius f / peak (linear) or the decade of f
    below the peak (log), angle theta_o from the normal."""
    r = _radius(f, peak, log)
    t = np.radians(np.asarray(theta_deg, float))
    return r * np.sin(t), r * np.cos(t)


def _fig(name, title, **kw):
    fig = figure(name=f"view-{name}", title=title, width=_SIZE, height=_SIZE,
                 css_classes=[f"view-{name}"], toolbar_location=None, **kw)
    return fig


def make_figures() -> tuple[dict, dict]:
    """The figures (name -> figure) and their data sources (name -> ColumnDataSource)."""
    src = {k: ColumnDataSource(data=d, name=f"src-{k}") for k, d in {
        "lobe": {"x": [], "y": [], "theta": [], "f": []}, "lobe_compare": {"x": [], "y": []},
        "lobe_band": {"x": [], "y": []}, "lobe_points": {"x": [], "y": []},
        "lobe_sigma": {"x0": [], "y0": [], "x1": [], "y1": []},
        "hemisphere": {"image": [np.zeros((2, 2))]}, "slice": {"image": [np.zeros((2, 2))]},
        "sphere": {"image": [np.zeros((2, 2), np.uint32)]},
        "albedo": {"t": [], "r": [], "g": [], "b": []},
        "masking": {"a": [], "M": [], "u": [], "pair": []},
        "tangent": {"xs": [], "ys": [], "c": []}}.items()}
    figs = {}
    f = figs["lobe"] = _fig("lobe", "lobe", x_range=(-1.1, 1.1), y_range=(-0.05, 1.15),
                            match_aspect=True)
    t = np.radians(np.linspace(-90, 90, 91))
    for r in (0.25, 0.5, 0.75, 1.0):
        f.line(r * np.sin(t), r * np.cos(t), color="#cccccc")
    f.patch("x", "y", source=src["lobe_band"], color="#1f77b4", alpha=0.3)
    lobe = f.line("x", "y", source=src["lobe"], color="#1f77b4", line_width=2)
    f.add_tools(HoverTool(renderers=[lobe], tooltips=[("θo (deg)", "@theta{0.0}"),
                                                      ("f_r (1/sr)", "@f{%.3g}")],
                          formatters={"@f": "printf"}))
    f.line("x", "y", source=src["lobe_compare"], color="#d62728", line_dash="dashed")
    f.segment("x0", "y0", "x1", "y1", source=src["lobe_sigma"], color="black")
    f.scatter("x", "y", source=src["lobe_points"], color="black", size=4)
    maps = {}
    for name, title, extent in (("hemisphere", "f_r over the hemisphere", (-1, -1, 2, 2)),
                                ("slice", "f_r: θh (x) by θd (y), deg", (0, 0, 90, 90))):
        maps[name] = LinearColorMapper(palette="Viridis256", low=-DECADES, high=0.0)
        x, y, w, h = extent
        g = figs[name] = _fig(name, title, x_range=(x, x + w), y_range=(y, y + h))
        img = g.image("image", x=x, y=y, dw=w, dh=h, source=src[name],
                      color_mapper=maps[name])
        g.add_tools(HoverTool(renderers=[img], formatters={"@image": "printf"}, tooltips=[
            ("x, y", "$x{0.00}, $y{0.00}"),
            ("f_r (1/sr; log10 of it on the log scale)", "@image{%.3g}")]))
    s = figs["sphere"] = _fig("sphere", "lit sphere", x_range=(-1, 1), y_range=(-1, 1))
    s.image_rgba("image", x=-1, y=-1, dw=2, dh=2, source=src["sphere"])
    a = figs["albedo"] = _fig("albedo", "albedo against θi (deg)",
                              y_range=(0, 1.05))
    for c, col in (("r", "#d62728"), ("g", "#2ca02c"), ("b", "#1f77b4")):
        a.line("t", c, source=src["albedo"], color=col, line_width=2, legend_label=c)
    a.add_tools(HoverTool(tooltips=[("θi (deg)", "@t{0}"), ("albedo r, g, b",
                                                            "@r{0.000}, @g{0.000}, @b{0.000}")],
                          mode="vline"))
    m = figs["masking"] = _fig("masking", "masking M, u, pair weight (deg)", y_range=(0, 1.05))
    for c, col in (("M", "#1f77b4"), ("u", "#ff7f0e"), ("pair", "#2ca02c")):
        m.line("a", c, source=src["masking"], color=col, legend_label=c)
    tg = figs["tangent"] = _fig("tangent", "tangent offset (deg) by arc length")
    tg.multi_line("xs", "ys", source=src["tangent"], color="c", line_width=2)
    for g in (a, m):
        g.legend.location = "bottom_left"
    src["_maps"] = maps
    return figs, src


def _put(source, data) -> None:
    """Set a source's data, unless both are empty (nothing to send)."""
    if any(len(v) for v in data.values()) or any(len(v) for v in source.data.values()):
        source.data = data


def _lobe(src, frame, log):
    peak = max(float(np.nanmax(frame.lobe_f)) if np.isfinite(frame.lobe_f).any() else 0.0,
               float(np.nanmax(frame.compare_f)) if frame.compare_f is not None else 0.0)
    th = frame.lobe_theta
    x, y = polar(th, frame.lobe_f, peak, log)
    src["lobe"].data = {"x": x, "y": y, "theta": th, "f": frame.lobe_f}
    cx, cy = polar(th, frame.compare_f, peak, log) if frame.compare_f is not None else ([], [])
    _put(src["lobe_compare"], {"x": cx, "y": cy})
    if frame.band is not None:
        hx, hy = polar(th, frame.band.hi, peak, log)
        lx, ly = polar(th, frame.band.lo, peak, log)
        _put(src["lobe_band"], {"x": np.r_[hx, lx[::-1]], "y": np.r_[hy, ly[::-1]]})
    else:
        _put(src["lobe_band"], {"x": [], "y": []})
    px, py, s0, s1 = [], [], [], []
    for _label, p in frame.points:
        x, y = polar(p.theta_o_deg, p.value, peak, log)
        px.append(x), py.append(y)
        s0.append(polar(p.theta_o_deg, p.value - p.sigma, peak, log))
        s1.append(polar(p.theta_o_deg, p.value + p.sigma, peak, log))
    cat = lambda parts: np.concatenate(parts) if parts else np.zeros(0)  # noqa: E731
    _put(src["lobe_points"], {"x": cat(px), "y": cat(py)})
    _put(src["lobe_sigma"], {"x0": cat([a[0] for a in s0]), "y0": cat([a[1] for a in s0]),
                              "x1": cat([a[0] for a in s1]), "y1": cat([a[1] for a in s1])})
    return peak


def _map(src, name, image, log):
    peak = float(np.nanmax(image)) if np.isfinite(image).any() else 0.0
    mapper = src["_maps"][name]
    if log:
        img = np.log10(np.clip(image, max(peak, 1e-30) * 10.0 ** -DECADES, None))
        lo, hi = np.log10(max(peak, 1e-30)) - DECADES, np.log10(max(peak, 1e-30))
    else:
        img, lo, hi = image, 0.0, max(peak, 1e-30)
    src[name].data = {"image": [np.nan_to_num(img, nan=lo)]}
    mapper.update(low=float(lo), high=float(hi))
    return peak


def update_figures(figs: dict, src: dict, frame, log: bool, views=VIEWS) -> None:
    """Put ``frame``'s numbers into the figures' sources of ``views`` (by default every
    view; those a move left unchanged need not be sent again); the titles say the peaks."""
    scale = "log" if log else "linear"          # log: DECADES below the peak
    if "lobe" in views:
        peak = _lobe(src, frame, log)
        figs["lobe"].title.text = f"lobe ({scale}; peak {peak:.3g} 1/sr)"
    for name in ("hemisphere", "slice"):
        if name in views:
            p = _map(src, name, getattr(frame, name), log)
            figs[name].title.text = f"{name} ({scale}; peak {p:.3g} 1/sr)"
    if "sphere" in views:
        src["sphere"].data = {"image": [tone_map(frame.sphere)]}
    if "albedo" in views:
        a = frame.albedo
        src["albedo"].data = {"t": frame.albedo_theta, "r": a[:, 0], "g": a[:, 1],
                              "b": a[:, 2]}
    if not _same(src["masking"].data.get("M"), frame.masking["M"]):
        _masking(src, frame)
    cols = ("#1f77b4", "#d62728")
    tangent = {"xs": [s for s, _ in frame.tangents], "ys": [o for _, o in frame.tangents],
               "c": list(cols[:len(frame.tangents)])}
    if not all(_same(a, b) for a, b in zip(src["tangent"].data["ys"], tangent["ys"])) \
            or len(src["tangent"].data["ys"]) != len(tangent["ys"]):
        src["tangent"].data = tangent


def _same(a, b) -> bool:
    return a is not None and np.shape(a) == np.shape(b) and np.array_equal(a, b)


def _masking(src, frame) -> None:
    """The masking terms (no slider changes them: sent once)."""
    m = frame.masking
    src["masking"].data = {"a": frame.masking_angle, "M": m["M"], "u": m["u"],
                           "pair": m["pair"]}
