r"""The LOO-PIT histogram of a fit: is each value's leave-one-out predictive distribution right?

For a model whose predictive distribution is right, the LOO-PIT values
(:mod:`analysis.fit.loo`) are uniform on [0, 1]: every bin of the histogram holds n / bins
values up to binomial scatter. The figure draws the density of the PIT values, the uniform
density 1, and the central 99% band of one bin's density under uniformity (binomial
quantiles), with the Kolmogorov-Smirnov p-value in the title. A U shape says the predictive
distributions are too narrow (noise underestimated, or misfit); a hump, too wide; a slope,
a bias.
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from reports.plots.common import FONT, PALETTE, finish, new_axes

__all__ = ["pit_histogram"]


def pit_histogram(pit, bins: int = 20, ks_pvalue: float | None = None, ax=None,
                  filename=None):
    """Histogram of LOO-PIT values against the uniform distribution.

    Parameters
    ----------
    pit : array_like, shape (n,)
        PIT values in [0, 1] (NaN dropped).
    bins : int
        Equal bins over [0, 1] (>= 2).
    ks_pvalue : float, optional
        The Kolmogorov-Smirnov p-value to print in the title.
    ax : matplotlib Axes, optional
    filename : path, optional
        Saved there (atomically) when given.

    Returns
    -------
    (fig, ax)

    Raises
    ------
    ValueError
        ``bins`` below 2, or no finite PIT value.

    Examples
    --------
    >>> fig, ax = pit_histogram(np.random.default_rng(0).uniform(size=500), ks_pvalue=0.5)
    >>> bars = ax.containers[0].patches
    >>> len(bars), round(float(sum(b.get_height() * b.get_width() for b in bars)), 6)
    (20, 1.0)
    """
    if int(bins) < 2:
        raise ValueError(f"bins must be >= 2; got {bins}")
    p = np.asarray(pit, dtype=np.float64).ravel()
    p = p[np.isfinite(p)]
    if p.size == 0:
        raise ValueError("pit holds no finite value")
    bins = int(bins)
    fig, ax = new_axes(ax, figsize=(4.6, 3.4))
    n = p.size
    lo, hi = (stats.binom.ppf(q, n, 1.0 / bins) * bins / n for q in (0.005, 0.995))
    ax.axhspan(lo, hi, color="0.85", lw=0, label="99% band under uniformity")
    heights, _, _ = ax.hist(np.clip(p, 0.0, 1.0), bins=bins, range=(0.0, 1.0), density=True,
                            color=PALETTE[0], alpha=0.8, edgecolor="white", label="LOO-PIT")
    ax.axhline(1.0, color="k", lw=1.0, ls="--", label="uniform")
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.0, 1.3 * max(float(np.max(heights)), hi, 1.0))     # room for the legend
    ax.set_xlabel("LOO-PIT (leave-one-out predictive CDF at the value)",
                  fontsize=FONT["label"])
    ax.set_ylabel("density", fontsize=FONT["label"])
    ax.tick_params(labelsize=FONT["small"])
    title = f"LOO-PIT of {n} values"
    if ks_pvalue is not None:
        title += f"; uniformity (KS) p = {ks_pvalue:.2g}"
    ax.set_title(title, fontsize=FONT["title"])
    ax.legend(fontsize=FONT["small"], loc="upper center", ncol=3, framealpha=0.9,
              handlelength=1.5, columnspacing=1.0)
    return finish(fig, ax, filename)
