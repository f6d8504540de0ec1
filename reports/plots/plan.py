"""The figure of a measurement plan: the chosen pairs on the hemisphere, next to a uniform
design of as many pairs (:class:`analysis.planning.Plan`).

Each panel is a polar projection of the hemisphere seen from above (radius theta in degrees,
angle phi from the warp, +x): the source directions as filled discs, the detector directions
as open squares, a faint line joining the two of each pair. On the plan's panel every
detector is numbered in measurement order and every source position with the range of the
measurements taken from it (the plan sets the source once per group).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from reports.plots.common import FONT, PALETTE, finish

__all__ = ["draw_plan"]

_SOURCE, _DETECTOR = PALETTE[1], PALETTE[0]


def _polar(wi_or_angles):
    """(phi radians, theta degrees) of unit directions (n, 3)."""
    w = np.asarray(wi_or_angles, dtype=np.float64)
    return np.arctan2(w[:, 1], w[:, 0]), np.degrees(np.arccos(np.clip(w[:, 2], -1, 1)))


def _panel(ax, wi, wo, title, numbered: bool):
    pi_, ti = _polar(wi)
    po, to = _polar(wo)
    for a, b, c, d in zip(pi_, ti, po, to):
        ax.plot([a, c], [b, d], color="0.75", lw=0.4, zorder=1)
    ax.scatter(po, to, s=16, marker="s", facecolors="white", edgecolors=_DETECTOR, lw=0.8,
               zorder=2, label="detector")
    ax.scatter(pi_, ti, s=28, color=_SOURCE, zorder=3, label="source")
    if numbered:
        for k, (a, b) in enumerate(zip(po, to), start=1):
            ax.annotate(str(k), (a, b), xytext=(3, 2), textcoords="offset points",
                        fontsize=FONT["small"] - 2, color=_DETECTOR, zorder=4)
        key = np.round(np.stack([pi_, ti], -1), 9)
        _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
        for g, i0 in enumerate(first):
            idx = np.flatnonzero(inverse.ravel() == g) + 1
            text = str(idx[0]) if idx.size == 1 else f"{idx.min()}-{idx.max()}"
            ax.annotate(text, (pi_[i0], ti[i0]), xytext=(-4, -9), textcoords="offset points",
                        fontsize=FONT["small"] - 1, color=_SOURCE, weight="bold", zorder=5,
                        ha="right")
    ax.set_ylim(0, 90)
    ax.set_yticks([30, 60, 90])
    ax.set_yticklabels(["θ 30°", "60°", "90°"], fontsize=FONT["small"])
    ax.set_rlabel_position(157.5)
    for label in ax.get_yticklabels():          # readable over the pairs
        label.set_bbox({"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 1.0})
        label.set_zorder(6)
    ax.set_xticks(np.radians([0, 90, 180, 270]))
    ax.set_xticklabels(["φ 0° (warp)", "φ 90°", "180°", "270°"], fontsize=FONT["small"])
    ax.set_title(title, fontsize=FONT["title"])


def draw_plan(plan, *, fig=None, filename=None):
    """Draw a plan's pairs and a uniform design of as many (module notes).

    Parameters
    ----------
    plan : analysis.planning.Plan
    fig : matplotlib Figure, optional
        An empty figure to draw the two panels into; a new one by default.
    filename : path, optional
        Save there (atomically; the format from the suffix).

    Returns
    -------
    (fig, (ax_plan, ax_uniform))
    """
    fig = Figure(figsize=(12.0, 6.4), layout="constrained") if fig is None else fig
    ax1 = fig.add_subplot(1, 2, 1, projection="polar")
    ax2 = fig.add_subplot(1, 2, 2, projection="polar")
    n = plan.budget
    sd = np.exp(np.mean(np.log(plan.natural_sd / plan.uniform_natural_sd)))
    _panel(ax1, plan.wi, plan.wo, f"{plan.fabric}: plan of {n} pairs, numbered in "
           f"measurement order", numbered=True)
    _panel(ax2, plan.uniform_wi, plan.uniform_wo, f"uniform design of {n} pairs", False)
    ax2.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=FONT["small"])
    fig.suptitle(f"free: {', '.join(plan.free)}; expected sd of the plan / the uniform "
                 f"design: {sd:.2f} (geometric mean)", fontsize=FONT["label"])
    return finish(fig, (ax1, ax2), filename)
