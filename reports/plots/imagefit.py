"""The figures of ``microcyl fit-images``: each image against its fitted render, and the fit's
path (the loss and each parameter per step).

``images.png``: a row an image: the image, the render at the fitted parameters (both at one
exposure: the image's 99th percentile shown at 0.9, sRGB), and the residual normalized by the
noise model's sd (the green channel, from -4 to +4: blue where the render is darker, red where
brighter). ``steps.png``: the loss (``sum(r_a r_b) / 2``) at each step and, a panel each,
every free parameter's value per step with its final 95% interval shaded; a dashed line where
the Monte Carlo noise was estimated again (the loss's scale changes there).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import MaxNLocator

from analysis.imagefit.workflow import PLOT_FILES
from reports.plots.common import save_figure

__all__ = ["write_plots", "FILES"]

#: The figures and their files (the names fit-images claims in its folder before it draws).
FILES = dict(zip(("images", "steps"), PLOT_FILES))
#: The residual colour scale's ends, in noise sds.
RESIDUAL_RANGE = 4.0


def _shown(img, scale) -> np.ndarray:
    return np.clip(np.clip(img * scale, 0.0, 1.0) ** (1 / 2.2), 0.0, 1.0)


def images_figure(panels, filename=None):
    """``images.png`` (module notes) of ``panels``: ``(name, image, fitted, residual)``;
    saved to ``filename`` (the path returned), or the figure returned when None."""
    n = len(panels)
    fig, axes = plt.subplots(n, 3, figsize=(9.0, 1.9 * n + 0.4), squeeze=False)
    for row, (name, image, fitted, resid) in zip(axes, panels):
        scale = 0.9 / max(float(np.percentile(image, 99)), 1e-12)
        row[0].imshow(_shown(image, scale))
        row[1].imshow(_shown(fitted, scale))
        im = row[2].imshow(resid[..., 1], cmap="RdBu_r", vmin=-RESIDUAL_RANGE,
                           vmax=RESIDUAL_RANGE)
        row[0].set_ylabel(name, fontsize=8)
        for ax in row:
            ax.set_xticks([])
            ax.set_yticks([])
    for ax, title in zip(axes[0], ("image", "fitted render", "residual / sd (G)")):
        ax.set_title(title, fontsize=9)
    fig.colorbar(im, ax=axes[:, 2].tolist(), shrink=0.8)
    if filename is None:
        return fig
    out = save_figure(fig, filename)
    plt.close(fig)
    return out


def steps_figure(doc, filename):
    """``steps.png`` (module notes) of a ``results.json`` document."""
    hist = doc["fit"]["history"]
    names = list(doc["parameters"])
    fig, axes = plt.subplots(1 + len(names), 1, figsize=(5.5, 1.6 * (1 + len(names)) + 0.4),
                             sharex=True, squeeze=False)
    axes = axes[:, 0]
    steps = [h["iteration"] for h in hist]
    ok = [h["accepted"] for h in hist]
    axes[0].plot(steps, [h["loss"] for h in hist], "k.-")
    if not all(ok):
        axes[0].plot([s for s, a in zip(steps, ok) if not a],
                     [h["loss"] for h in hist if not h["accepted"]], "rx", label="step refused")
    axes[0].set_ylabel("loss")
    for h in hist[1:]:
        if h["start"]:
            for ax in axes:
                ax.axvline(h["iteration"], color="grey", ls="--", lw=0.8,
                           label="Monte Carlo noise estimated again" if ax is axes[0] else None)
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(fontsize=7, loc="best")
    for ax, name in zip(axes[1:], names):
        p = doc["parameters"][name]
        ax.axhspan(p["lo95"], p["hi95"], color="C0", alpha=0.25, label="95% interval")
        ax.plot(steps, [h["values"][name] for h in hist], "C0.-")
        ax.axhline(p["start"], color="grey", ls=":", label="start")
        ax.set_ylabel(f"{name} [{p['unit']}]", fontsize=8)
    axes[-1].set_xlabel("step")
    axes[-1].xaxis.set_major_locator(MaxNLocator(integer=True))     # steps are whole
    if len(axes) > 1:
        axes[1].legend(fontsize=7, loc="best")
    out = save_figure(fig, filename)
    plt.close(fig)
    return out


def write_plots(doc, panels, out_dir) -> dict:
    """Write :data:`FILES` into ``out_dir``; return ``{name: file name}``
    (the ``plots`` callable of :func:`analysis.imagefit.fit_images`)."""
    images_figure(panels, out_dir / FILES["images"])
    if doc["fit"]["history"]:
        steps_figure(doc, out_dir / FILES["steps"])
        return dict(FILES)
    return {"images": FILES["images"]}
