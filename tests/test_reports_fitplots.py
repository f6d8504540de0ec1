"""Tests of reports.plots.fit_diagnostics: the adequacy figure (residuals against angle, the optional PIT
histogram, the verdict and warnings as text), the corner plot a reviewer reads (titles
apart, whole tick values, a PNG small enough for a page) and the lobe plot's note of a band
thinner than its line (from real fits, one thin and one wide)."""

from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import brdf  # noqa: E402
from analysis.fit import FabricModel, fit  # noqa: E402
from analysis.params import ParamSpec, defaults_from_fabric  # noqa: E402
from reports.plots.fit_diagnostics import adequacy_plot, corner_plot  # noqa: E402
from _fitmodels import fabric_table  # noqa: E402


def test_adequacy_figure_shows_residuals_pit_and_warnings(tmp_path):
    silk = brdf.fabric("silk_crepe_de_chine")
    t1, t2 = silk.threads
    fab = silk.replace(threads=(t1, t2.replace(area=0.0)))    # kd2 has no effect
    table, _ = fabric_table("silk", n=120, seed=3, fab=fab)
    spec = ParamSpec("gamma_s1,kd2", defaults=defaults_from_fabric(fab))
    r = fit(table, spec, FabricModel(fab, table.wi, table.wo), max_steps=100, progress=False,
            threads=1)
    assert any(w["kind"] == "not_informed" for w in r.warnings)
    pit = np.random.default_rng(0).uniform(size=r.counts["used"])
    fig, axes = adequacy_plot(r, table, pit=pit, filename=tmp_path / "a.png")
    assert len(axes) == 4 and (tmp_path / "a.png").stat().st_size > 1000
    # every point of the table is drawn once in the first panel, against its theta_i
    xs = np.concatenate([line.get_xdata() for line in axes[0].lines if line.get_marker() == "."])
    assert np.allclose(np.sort(xs), np.sort(np.degrees(table.angles[:, 0])))
    assert sum(p.get_height() for p in axes[3].patches) == pit.size
    text = "\n".join(t.get_text() for a in fig.axes for t in a.texts)
    assert "warning (not_informed): kd2" in text.replace("\n    ", " ")
    fig, axes = adequacy_plot(r, table)
    assert len(axes) == 3


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
    from reports.plots.fit_diagnostics import _note_thin_band
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


def _band_width_pt(ax):
    """The widest radial extent of the polar axes' filled band as drawn, in points: from the
    band's polygon (theta, r) and the axes' own transform (independent of the note's rule)."""
    band = ax.collections[0]
    verts = band.get_paths()[0].vertices
    theta = np.round(verts[:, 0], 9)
    widths = [np.ptp(verts[theta == t, 1]) for t in np.unique(theta)]
    fig = ax.figure
    fig.canvas.draw()
    origin, top = ax.transData.transform([[0.0, 0.0], [0.0, ax.get_rmax()]])
    pt_per_unit = np.hypot(*(top - origin)) * 72.0 / fig.dpi / ax.get_rmax()
    return max(widths) * pt_per_unit


def test_the_lobe_plot_notes_a_band_thinner_than_its_line_from_a_real_fit():
    """Two real fits of a simulated silk: 300 pairs at 0.2 % noise with gamma_s1 free (a
    posterior so narrow that its 90% band, drawn, is under a point wide, under the 1-point
    median line) and 40 pairs at 30 % noise with four parameters free (a band several points
    wide). The lobe plot's legend says "thinner than the line" for the first alone."""
    from reports.plots.fit_diagnostics import lobe_plot
    cases = (("gamma_s1", 300, 0.002, 60, True),
             ("kd1,gamma_v1,gamma_s1,gamma_v2", 40, 0.3, 150, False))
    for free, n, rel, steps, thin in cases:
        table, fab = fabric_table("silk_crepe_de_chine", n=n, rel=rel, seed=3)
        spec = ParamSpec(free, defaults=defaults_from_fabric(fab))
        r = fit(table, spec, FabricModel(fab, table.wi, table.wo), max_steps=steps,
                progress=False, threads=1)
        fig, ax = lobe_plot(r, table, lambda wi, wo: FabricModel(fab, wi, wo),
                            theta_i_deg=[30])
        try:
            labels = [t.get_text() for t in ax[0].get_legend().get_texts()]
            width = _band_width_pt(ax[0])
            if thin:
                assert width < 1.0, width
                assert labels[0].startswith("90% band (thinner than the line: at most")
            else:
                assert width > 3.0, width
                assert labels[0] == "90% band"
        finally:
            plt.close(fig)


def test_corner_says_once_which_panels_lack_contours_not_on_the_root_logger(tmp_path, caplog):
    """corner logs "Too few points to create valid contours" on the root logger (the terminal
    showed ``WARNING:root:...``); the plot says it once through microcyl's logger."""
    import logging
    from types import SimpleNamespace

    from reports.plots.fit_diagnostics import corner_plot
    rng = np.random.default_rng(0)
    x = rng.normal(size=(4000, 3))
    x[:, 1] = rng.integers(0, 2, 4000) * 1e-3
    x[:, 2] = np.where(rng.random(4000) < 0.999, 0.5, 0.6)      # hardly spread
    result = SimpleNamespace(samples=lambda: x, names=["a", "b", "c"], units=["1"] * 3)
    said = []

    class Keep(logging.Handler):
        def emit(self, record):
            said.append(record.getMessage())

    log = logging.getLogger("microcyl")      # the CLI may have set it not to propagate
    keep, level = Keep(), log.level
    log.addHandler(keep)
    log.setLevel(logging.INFO)
    try:
        with caplog.at_level(logging.INFO):
            corner_plot(result, filename=tmp_path / "corner.png")
    finally:
        log.removeHandler(keep)
        log.setLevel(level)
    assert not [r for r in caplog.records if r.name == "root"]
    assert len(said) == 1 and "without contours" in said[0], said
    assert (tmp_path / "corner.png").stat().st_size > 1000
