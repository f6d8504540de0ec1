"""Tests of reports.fitplots: the corner plot a reviewer reads (titles apart, whole tick
values, a PNG small enough for a page)."""

from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from reports.fitplots import corner_plot  # noqa: E402

NAMES = ["eta1", "kd1", "kd2", "gamma_s1", "gamma_v1", "gamma_s2", "gamma_v2", "area1",
         "log_noise", "scale"]
UNITS = ["1", "1", "1", "deg", "deg", "deg", "deg", "1", "1", "1"]


def _result(n=4000):
    rng = np.random.default_rng(1)
    centre = np.array([1.46, 0.1, 0.7, 12.0, 24.0, 2.5, 5.0, 0.95, -3.6, 1.0])
    x = rng.multivariate_normal(np.zeros(10), np.eye(10) * 1e-4 + 5e-5, n) + centre
    x[:, 3] = 12.12 + (x[:, 3] - 12.0) * 0.01      # 12.12 +- 1e-4: matplotlib would offset it
    return SimpleNamespace(samples=lambda: x, names=NAMES, units=UNITS)


def test_corner_titles_apart_no_offset_and_small_png(tmp_path):
    out = tmp_path / "corner.png"
    fig, axes = corner_plot(_result(), filename=out)
    try:
        fig.canvas.draw()
        r = fig.canvas.get_renderer()
        titles = [ax.title.get_window_extent(r) for ax in axes if ax.get_title()]
        assert len(titles) == 10
        for i, a in enumerate(titles):
            for b in titles[i + 1:]:
                assert not a.overlaps(b)
        # no title runs into a panel other than its own column's
        boxes = [ax.get_window_extent(r) for ax in axes]
        for ax in axes:
            if ax.get_title():
                t = ax.title.get_window_extent(r)
                assert not any(t.overlaps(b) for b, other in zip(boxes, axes)
                               if other is not ax and other.get_visible() and other.has_data())
        offsets = [axis.get_offset_text().get_text() for ax in axes
                   for axis in (ax.xaxis, ax.yaxis)]
        assert offsets == [""] * len(offsets)
        # the offset-prone parameter's ticks read as whole values
        labels = [t.get_text() for t in axes[-7].get_xticklabels() if t.get_text()]
        assert labels and all(lab.replace("−", "-").startswith("12.1") for lab in labels)
    finally:
        plt.close(fig)
    assert out.stat().st_size <= 400 * 1024
    from PIL import Image
    with Image.open(out) as im:          # at 200 dpi: about 1.5 in a parameter
        assert im.size[0] > 200 * 1.4 * 10


def test_a_band_thinner_than_its_line_is_noted_and_a_wide_one_is_not():
    from reports.fitplots import _note_thin_band
    th = np.radians(np.linspace(-89, 89, 61))
    for width, thin in ((1e-4, True), (0.3, False)):
        fig = plt.figure(figsize=(4.2, 3.6))
        try:
            ax = fig.add_subplot(projection="polar")
            ax.set_thetamin(-90)
            ax.set_thetamax(90)
            med = 1.0 + 0.2 * np.cos(th)
            band = ax.fill_between(th, med - width / 2, med + width / 2, label="90% band")
            ax.plot(th, med)
            assert _note_thin_band(ax, band, np.full(th.shape, width)) is thin
            assert ("thinner than the line" in band.get_label()) is thin
        finally:
            plt.close(fig)
