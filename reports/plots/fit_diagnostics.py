r"""Plots of a Bayesian fit: corner, traces, posterior-predictive lobes, residual maps, and the
adequacy figure (residuals against angle, an optional PIT histogram, the verdict and the
warnings) (the fit's quality figures themselves are computed in :mod:`analysis.fit.quality`
and :mod:`analysis.fit.adequacy`).

Every function takes ``ax=`` (or ``fig=`` for the corner plot), returns ``(fig, ax)``, saves only
when given ``filename`` and never calls ``show()``.
"""

from __future__ import annotations

import contextlib
import io
import logging
import textwrap
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import ScalarFormatter
from PIL import Image

from analysis.fit import LogPosterior
from analysis.fit.adequacy import normal_scores, point_scores, regions
from analysis.fit.loo import import_arviz
from analysis.views.posterior import compute_posterior_lobes, posterior_draws
from gonio import atomic_write
from reports.plots.common import DPI
from reports.plots.common import legend_outside
from reports.plots.halfdisc import HalfDiscAxes
from reports.plots.lobes import setup_polar
from reports.plots.pit import pit_histogram

__all__ = ["corner_plot", "trace_plot", "lobe_plot", "residual_map", "posterior_draws",
           "adequacy_plot", "write_fit_plots"]


def _plt():
    """pyplot, on the Agg backend when it can be set (fits run without a display)."""
    matplotlib.use("Agg", force=False)
    return plt


def _save(fig, filename):
    """Save whole or not at all (gonio.atomic_write), in the format of the file's suffix; a
    PNG at :data:`reports.plots.common.DPI` with a palette of at most 256 colours (the plots'
    few colours and their anti-aliasing; a third of the size of full RGB)."""
    if filename is None:
        return
    fmt = Path(filename).suffix[1:].lower() or "png"
    if fmt != "png":
        with atomic_write(filename, "wb") as fh:
            fig.savefig(fh, format=fmt, dpi=DPI, bbox_inches="tight")
        return
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
    buf.seek(0)
    with Image.open(buf) as im:
        small = im.convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT)
    with atomic_write(filename, "wb") as fh:
        small.save(fh, format="png", optimize=True)


def _corner():
    """The ``corner`` module, imported on use and after arviz (:func:`import_arviz`): corner
    imports arviz for its InferenceData input, and through import_arviz that import skips
    the Bokeh modules arviz would load for two docstrings."""
    import_arviz()
    import corner        # on use: a verb that draws no corner plot does not pay for arviz
    return corner


def corner_plot(result, truths=None, fig=None, filename=None):
    """Corner plot of the free parameters (``corner`` package), natural units.

    Each diagonal panel is titled in three lines, the parameter and its median with the
    distances to the 2.5% and 97.5% quantiles, so that no title runs into its neighbour; tick
    labels show whole values (no offset such as "+1.2e1"); samples are drawn as contours and
    density, not as points (a PNG of ten parameters at 200 dpi stays under 400 KB).

    Parameters
    ----------
    result : analysis.fit.results.FitResult
    truths : mapping name -> value, optional
        Drawn as lines (e.g. the simulation's parameters).
    """
    samples = result.samples()
    if samples.shape[0] > 40000:
        samples = samples[np.random.default_rng(0).choice(samples.shape[0], 40000, False)]
    labels = [f"{n} [{u}]" if u not in ("1", "") else n for n, u in zip(result.names,
                                                                        result.units)]
    tr = None if truths is None else [truths.get(n, None) for n in result.names]
    d = samples.shape[1]
    if fig is None:
        fig = _plt().figure(figsize=(1.5 * d + 0.8, 1.5 * d + 0.8))
    with _corner_log() as said:
        fig = _corner().corner(samples, labels=labels, truths=tr,
                               quantiles=[0.025, 0.5, 0.975], show_titles=False, fig=fig,
                               max_n_ticks=3, plot_datapoints=False, plot_density=False,
                               fill_contours=True, label_kwargs={"fontsize": 8},
                               labelpad=0.08)
    if said:           # corner's own words on the root logger, once, as microcyl says things
        logging.getLogger("microcyl").info(
            f"corner plot: {len(said)} panel(s) drawn without contours (corner: "
            f"{said[0].rstrip('.').lower()}: the draws of a pair of parameters hardly spread)")
    _corner_titles(fig, samples, labels)
    return _finish_corner(fig, filename)


@contextlib.contextmanager
def _corner_log():
    """The messages corner logs on the root logger while it draws (its "Too few points to
    create valid contours" would reach the terminal as ``WARNING:root:...``), kept in a list
    instead of printed."""
    said: list[str] = []

    class _Keep(logging.Handler):
        def emit(self, record):
            said.append(record.getMessage())

    root = logging.getLogger()
    keep, propagate = _Keep(), root.handlers[:]
    root.handlers[:] = [keep]
    try:
        yield said
    finally:
        root.handlers[:] = propagate


def _corner_titles(fig, samples, labels):
    """Three-line titles over the diagonal: the label, the median, and the distances to the
    2.5% and 97.5% quantiles (narrow enough to stay over their own panel)."""
    d = samples.shape[1]
    axes = np.asarray(fig.axes).reshape(d, d)
    lo, med, hi = np.percentile(samples, [2.5, 50, 97.5], axis=0)
    for k in range(d):
        axes[k, k].set_title(f"{labels[k]}\n{med[k]:.4g}\n+{hi[k] - med[k]:.2g} / "
                             f"−{med[k] - lo[k]:.2g}", fontsize=8)


def _finish_corner(fig, filename):
    """Whole tick values (no offset text), 8 pt ticks; save; return (fig, axes)."""
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if isinstance(axis.get_major_formatter(), ScalarFormatter):
                axis.set_major_formatter(ScalarFormatter(useOffset=False))
        ax.tick_params(labelsize=8)
    _save(fig, filename)
    return fig, fig.axes


def trace_plot(result, ax=None, filename=None, max_walkers: int = 8):
    """Trace of every free parameter, a few walkers of each ensemble (post burn-in)."""
    plt = _plt()
    d = len(result.names)
    if ax is None:
        fig, ax = plt.subplots(d, 1, figsize=(8, 1.4 * d + 0.6), sharex=True, squeeze=False)
        ax = ax[:, 0]
    else:
        ax = np.atleast_1d(ax)
        fig = ax[0].figure
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    steps = np.arange(result.burn, result.burn + result.chains.shape[1])
    for i, name in enumerate(result.names):
        for k in range(result.chains.shape[0]):
            ax[i].plot(steps, result.chains[k, :, :max_walkers, i], color=colours[k % 10],
                       lw=0.5, alpha=0.5)
        ax[i].set_ylabel(name, fontsize=8)
    ax[-1].set_xlabel("step (after burn-in)")
    ax[0].set_title(f"traces ({result.chains.shape[0]} ensembles, colour = ensemble)")
    _save(fig, filename)
    return fig, ax


def _predict_at(result, model_factory, wi, wo, theta):
    lp = LogPosterior(result.spec, None, model_factory(wi, wo))
    return lp.predict(theta)


def lobe_plot(result, table, model_factory, theta_i_deg=None, phi_i_deg=None, ax=None,
              filename=None, n_draws: int = 48, plane_tol_deg: float = 8.0,
              theta_tol_deg: float = 4.0):
    """Posterior-predictive bands of f_r cos(theta_o) in the plane of incidence, over the data.

    For up to three incidence angles, the 5-95% band and median of f_r cos(theta_o) (luminance-
    free mean of R, G, B) of ``n_draws`` posterior draws is drawn against the signed outgoing
    angle (negative on the incidence side), on polar axes (normal up); table points within
    ``theta_tol_deg`` of the incidence angle and ``plane_tol_deg`` of the plane are overlaid.

    Parameters
    ----------
    model_factory : callable
        ``model_factory(wi, wo) -> model`` for new directions (e.g. ``FabricModel`` of the
        fitted fabric).
    theta_i_deg : sequence of float, optional
        Incidence angles; default: up to three of the table's most common ones.
    """
    plt = _plt()
    lobes = compute_posterior_lobes(result, table, model_factory, theta_i_deg, phi_i_deg,
                                    n_draws=n_draws, plane_tol_deg=plane_tol_deg,
                                    theta_tol_deg=theta_tol_deg)
    if ax is None:
        fig, ax = plt.subplots(1, len(lobes), subplot_kw={"axes_class": HalfDiscAxes},
                               figsize=(4.2 * len(lobes), 3.0), squeeze=False,
                               layout="constrained")
        ax = ax[0]
    else:
        ax = np.atleast_1d(ax)
        fig = ax[0].figure
    for a, lobe in zip(ax, lobes):
        th = np.radians(lobe.signed_deg)
        band = a.fill_between(th, lobe.lo, lobe.hi, alpha=0.35, color="C0", label="90% band")
        a.plot(th, lobe.median, color="C0", lw=1, label="median")
        if lobe.data.size:
            a.plot(np.radians(lobe.data_signed_deg), lobe.data, "k.", ms=3, label="data")
        top = max(np.nanmax(lobe.hi), np.nanmax(lobe.data, initial=0.0))
        setup_polar(a, "linear", 1.0, top, "f_r cos θo (1/sr)")   # as the other lobe plots
        _note_thin_band(a, band, np.asarray(lobe.hi) - np.asarray(lobe.lo))
        a.set_title(f"theta_i = {lobe.theta_i_deg:g} deg: f_r cos(theta_o) (1/sr), mean RGB\n"
                    f"(+ forward, - backward in the plane phi_i = {lobe.phi_i_deg:g} deg)",
                    fontsize=8)
    legend_outside(ax[0], "below", ncol=3)
    _save(fig, filename)
    return fig, ax


def _note_thin_band(ax, band, width, line_pt: float = 1.0):
    """Say so in the band's legend label when the band is nowhere wider than the median's
    line (``line_pt`` points) on this polar axes: it would be drawn but not seen."""
    fig = ax.figure
    rmax = ax.get_rmax()
    ax.apply_aspect()                            # the box of the disc's shape and size
    centre, rim = ax.transData.transform([(0.0, 0.0), (0.0, rmax)])
    radius_pt = float(np.hypot(*(rim - centre))) * 72.0 / fig.dpi
    w = float(np.nanmax(width)) if np.size(width) else 0.0
    if rmax > 0 and radius_pt > 0 and w < line_pt / radius_pt * rmax:
        band.set_label(f"90% band (thinner than the line: at most {w:.2g} 1/sr)")
        return True
    return False


def residual_map(result, table, prediction, ax=None, filename=None):
    """Normalized residuals (data - prediction in the likelihood's space, over its sigma)
    mapped on the half-vector disk (h_x, h_y), mean over channels.

    Parameters
    ----------
    prediction : ndarray (n, 3)
        Model f_r at the table's pairs (e.g. the posterior median's).
    """
    plt = _plt()
    lik = result.logpost.lik
    y_model = lik.transform(prediction[None])[0]
    r = lik.y - y_model
    s2 = lik.sigma_y2 if lik.sigma_y2 is not None else 0.0
    if "log_noise" in result.names:
        s2 = s2 + np.exp(2 * result.summary["log_noise"]["median"])
    z = r / np.sqrt(s2)
    n = len(table)
    zsum = np.bincount(lik.pt, weights=z, minlength=n)
    cnt = np.bincount(lik.pt, minlength=n)
    keep = cnt > 0
    zmean = zsum[keep] / cnt[keep]
    h = table.wi + table.wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    if ax is None:
        fig, ax = plt.subplots(figsize=(5, 4.4))
    else:
        fig = ax.figure
    lim = max(3.0, float(np.nanpercentile(np.abs(zmean), 98)))
    sc = ax.scatter(h[keep, 0], h[keep, 1], c=zmean, cmap="RdBu_r", vmin=-lim, vmax=lim, s=6)
    fig.colorbar(sc, ax=ax, label="normalized residual (in units of sigma)")
    ax.add_patch(plt.Circle((0, 0), 1, fill=False, lw=0.5))
    ax.set_aspect("equal")
    ax.set_xlabel("h_x (warp; unit half vector, unitless)")
    ax.set_ylabel("h_y (weft; unitless)")
    ax.set_title(f"residuals: rms {np.sqrt(np.mean(z * z)):.2f} over {z.size} values",
                 fontsize=9)
    _save(fig, filename)
    return fig, ax


def _verdict_text(result, width: int = 110) -> str:
    """The adequacy verdict and each warning, wrapped, for a figure's text block."""
    a = result.adequacy or {}
    head = {True: "ADEQUATE", False: "NOT ADEQUATE", None: "adequacy not checked"}
    lines = textwrap.wrap(f"{head[a.get('adequate')]}: {a.get('reason', 'not checked')}", width)
    for w in result.warnings:
        lines += textwrap.wrap(f"warning ({w['kind']}): {w['message']}", width,
                               subsequent_indent="    ")
    if not result.warnings:
        lines.append("no warnings")
    return "\n".join(lines)


def adequacy_plot(result, table, pit=None, filename=None):
    """Standardized residuals against angle, an optional PIT histogram, and the fit's verdict
    and warnings as text.

    The residual of each point is its normal score averaged over channels times
    sqrt(channels) (:func:`analysis.fit.adequacy.point_scores`; N(0, 1) under the model) at
    the posterior median, against theta_i, theta_o and phi_o - phi_i (degrees), forward and
    back scatter in two colours; the band is +-2.

    Parameters
    ----------
    result : analysis.fit.FitResult
        With its posterior, ``adequacy`` and ``warnings``.
    table : gonio.Table
        The fitted table.
    pit : array_like, optional
        LOO-PIT values in [0, 1] (one per value); drawn as a histogram beside the residuals
        when given (uniform when the model is calibrated).

    Returns
    -------
    (fig, axes)
    """
    plt = _plt()
    lik = result.logpost.lik
    scores = normal_scores(result, result.median_internal()[None])[0]
    points, zp = point_scores(lik, np.where(np.isfinite(scores), scores, 0.0))
    ang = np.degrees(table.angles)[points]
    fwd, back = regions(table.wi[points], table.wo[points])["forward_back"][2:]
    dphi = np.degrees(np.angle(np.exp(1j * np.radians(ang[:, 3] - ang[:, 1]))))
    n = 3 + (pit is not None)
    words = _verdict_text(result, width=int(30 * n))
    text_h = 0.14 * (words.count("\n") + 1) + 0.2
    fig = plt.figure(figsize=(3.4 * n, 3.4 + text_h))
    grid = fig.add_gridspec(2, n, height_ratios=(3.0, text_h))
    axes = [fig.add_subplot(grid[0, k]) for k in range(n)]
    for a, x, label in zip(axes, (ang[:, 0], ang[:, 2], dphi),
                           ("θi (deg)", "θo (deg)", "φo - φi (deg)")):
        other = ~(fwd | back)
        for sel, col, name in ((fwd, "C3", "forward"), (back, "C0", "back"),
                               (other, "0.5", "near the normal")):
            if np.any(sel):
                a.plot(x[sel], zp[sel], ".", ms=3, color=col, label=name)
        a.axhspan(-2, 2, color="0.9", zorder=0)
        a.axhline(0, color="k", lw=0.5)
        a.set_xlabel(label, fontsize=8)
        a.tick_params(labelsize=7)
    axes[0].set_ylabel("standardized residual", fontsize=8)
    axes[0].legend(fontsize=6, loc="upper left")
    if pit is not None:
        p = np.asarray(pit, dtype=np.float64)
        axes[3].hist(p[np.isfinite(p)], bins=20, range=(0, 1), color="C2", alpha=0.7)
        axes[3].axhline(np.isfinite(p).sum() / 20, color="k", lw=0.8, ls="--")
        axes[3].set_xlabel("LOO-PIT", fontsize=8)
        axes[3].tick_params(labelsize=7)
    text = fig.add_subplot(grid[1, :])
    text.axis("off")
    text.text(0, 1, words, va="top", ha="left",
              fontsize=7, family="monospace", transform=text.transAxes)
    fig.suptitle("residuals at the posterior median, per point (N(0, 1) if the model fits)",
                 fontsize=9)
    _save(fig, filename)
    return fig, axes


def write_fit_plots(result, table, model_factory, out_dir, truths=None) -> dict:
    """Write corner.png, traces.png, lobes.png, residuals.png, adequacy.png (and pit.png, the
    LOO-PIT histogram, when the result has its PSIS-LOO) into ``out_dir``.

    The signature :func:`analysis.fit.fit_fabric` expects of its ``plots``; returns
    ``{name: path}``.
    """
    plt = _plt()
    out = Path(out_dir)
    files = {}
    pred = _predict_at(result, model_factory, table.wi, table.wo, result.median_internal()[None])[0]
    for name, call in (
            ("corner.png", lambda f: corner_plot(result, truths=truths, filename=f)),
            ("traces.png", lambda f: trace_plot(result, filename=f)),
            ("lobes.png", lambda f: lobe_plot(result, table, model_factory, filename=f)),
            ("residuals.png", lambda f: residual_map(result, table, pred, filename=f)),
            ("adequacy.png", lambda f: adequacy_plot(result, table, filename=f))):
        fig, _ = call(out / name)
        plt.close(fig)
        files[name[:-4]] = str(out / name)
    if getattr(result, "loo", None) is not None:
        pvalue = result.quality.get("loo_pit", {}).get("ks_pvalue")
        fig, _ = pit_histogram(result.loo.pit, ks_pvalue=pvalue, filename=out / "pit.png")
        plt.close(fig)
        files["pit"] = str(out / "pit.png")
    return files
