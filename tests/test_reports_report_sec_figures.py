"""The figure sections evaluate each curve once, and what they write is what they draw.

The lobes section draws 9 distinct curves (3 incidences x 3 planes) in three figures and
writes them to lobes.csv; counted here by wrapping ``Fabric.eval``, it evaluates each of
them once (it used to evaluate 48: each figure's curves again for the shared radial limit,
and again for the CSV). Reference values come from the fabric at directions written out here.
"""

import csv

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import brdf  # noqa: E402
from reports.report import sec_figures  # noqa: E402
from reports.report.page import Page  # noqa: E402
from reports.report.settings import QUALITIES  # noqa: E402

N = 19      # samples per curve
W = np.array([0.2126, 0.7152, 0.0722])


def sph(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    t, p = np.broadcast_arrays(t, p)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


class Counter:
    """Wraps ``Fabric.eval``: every (wi, wo) pair evaluated, as rounded tuples."""

    def __init__(self, monkeypatch):
        self.pairs = []
        original = brdf.Fabric.eval

        def counted(fab, wi, wo, *args, **kwargs):
            wi_, wo_ = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
            self.pairs += [tuple(np.round(np.concatenate([a, b]), 9))
                           for a, b in zip(wi_.reshape(-1, 3), wo_.reshape(-1, 3))]
            return original(fab, wi, wo, *args, **kwargs)

        monkeypatch.setattr(brdf.Fabric, "eval", counted)


def _curve_pairs(thetas, planes=(0.0, 45.0, 90.0)):
    """The (wi, wo) pairs of the lobe curves at these incidences and planes, each once."""
    out = []
    s = np.linspace(-90.0, 90.0, N)
    for phi in planes:
        wo = np.where((s >= 0)[:, None], sph(np.abs(s), phi), sph(np.abs(s), phi + 180.0))
        for ti in thetas:
            wi = sph(ti, phi + 180.0)
            out += [tuple(np.round(np.concatenate([wi, o]), 9)) for o in wo]
    return out


@pytest.fixture
def drawn(tmp_path, monkeypatch):
    """A page whose figures are recorded (each line's gid, x and y) before they are saved."""
    figures = {}
    original = Page.figure

    def record(self, fig, filename, caption):
        figures[filename] = [[(line.get_gid(), line.get_xdata().copy(), line.get_ydata().copy(),
                               line.get_label()) for line in ax.get_lines() if line.get_gid()]
                             for ax in fig.axes]
        return original(self, fig, filename, caption)

    monkeypatch.setattr(Page, "figure", record)
    q = dict(QUALITIES["fast"], lobe=N)
    page = Page(tmp_path, "velvet", brdf.fabric("velvet"), q)
    return page, figures


def test_lobes_section_evaluates_each_curve_once(drawn, monkeypatch):
    page, figures = drawn
    count = Counter(monkeypatch)
    sec_figures.section_lobes(page)
    assert len(count.pairs) == 9 * N                       # 9 curves, once each (was 48)
    assert sorted(count.pairs) == sorted(_curve_pairs((0.0, 30.0, 60.0)))
    assert set(figures) == {"lobes_linear.png", "lobes_log.png", "lobes_rgb.png"}


def _read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return {name: np.array([float(r[k]) for r in rows[1:]]) for k, name in enumerate(rows[0])}


def test_lobes_csv_is_the_drawn_data_and_the_model(drawn):
    page, figures = drawn
    sec_figures.section_lobes(page)
    data = _read_csv(page.path("lobes.csv"))
    theta_o = data["theta_o_deg"]
    assert np.allclose(theta_o, np.linspace(-90, 90, N))
    fab = brdf.fabric("velvet")
    for phi in (0.0, 45.0, 90.0):                          # the model at directions built here
        for ti in (0.0, 30.0, 60.0):
            wo = np.where((theta_o >= 0)[:, None], sph(np.abs(theta_o), phi),
                          sph(np.abs(theta_o), phi + 180.0))
            f = fab.eval(np.broadcast_to(sph(ti, phi + 180.0), wo.shape), wo)
            for k, c in enumerate("rgb"):
                assert np.allclose(data[f"f_{c}_phi{phi:g}_ti{ti:g}"], f[:, k], rtol=1e-8,
                                   atol=1e-12)
            assert np.allclose(data[f"f_Y_phi{phi:g}_ti{ti:g}"], f @ W, rtol=2e-4, atol=1e-12)
    # per channel, linear: the line's y is f_r itself (30 and 60 degrees)
    for ax, phi in zip(figures["lobes_rgb.png"], (0.0, 45.0, 90.0)):
        lines = {gid: (x, y) for gid, x, y, _ in ax}
        assert len(lines) == 6
        for ti in (30, 60):
            for c in "rgb":
                x, y = lines[f"lobe theta_i={ti} {c}"]
                assert np.allclose(np.degrees(x), theta_o)
                assert np.allclose(y, data[f"f_{c}_phi{phi:g}_ti{ti}"], rtol=1e-8, atol=1e-12)
    # normalized: the luminance curve over its own peak, which the legend gives
    for ax, phi in zip(figures["lobes_linear.png"], (0.0, 45.0, 90.0)):
        for gid, _, y, label in ax:
            ti = gid.split("=")[1].split()[0]
            lum = data[f"f_Y_phi{phi:g}_ti{ti}"]
            assert np.allclose(y, lum / lum.max(), rtol=1e-7)
            assert f"peak {lum.max():.3g} 1/sr" in label
    # log: log10(f / floor) clipped at 0, one floor for all panels, four decades under the
    # largest luminance of the figure
    top = max(data[k].max() for k in data if k.startswith("f_Y"))
    floor = 10.0 ** np.floor(np.log10(top) - 4.0)
    for ax, phi in zip(figures["lobes_log.png"], (0.0, 45.0, 90.0)):
        for gid, _, y, _ in ax:
            ti = gid.split("=")[1].split()[0]
            lum = data[f"f_Y_phi{phi:g}_ti{ti}"]
            assert np.allclose(y, np.log10(np.maximum(lum, floor) / floor), rtol=1e-7,
                               atol=1e-7)


def test_masking_section_evaluates_each_curve_once(drawn, monkeypatch):
    page, figures = drawn
    count = Counter(monkeypatch)
    sec_figures.section_masking(page)
    # 2 incidences x 3 planes x masking on and off; on and off share their directions
    assert sorted(count.pairs) == sorted(2 * _curve_pairs((60.0, 80.0)))
    assert {gid for ax in figures["masking_lobes.png"] for gid, *_ in ax} == \
        {"masking on", "masking off"}


def test_hemisphere_section_evaluates_each_light_once(drawn, monkeypatch):
    """Three lights over the disc (the first drawn twice: luminance and colour) and the 3-D
    lobe's grid: each evaluated once."""
    page, figures = drawn
    count = Counter(monkeypatch)
    sec_figures.section_hemisphere(page)
    n, (nt, npf) = page.q["hemi"], page.q["lobe3d"]
    # the n x n image's pixel centres inside the unit disc, counted in integers: only those
    # are shaded (the corners lie below the horizon)
    d = sum((2 * i + 1 - n) ** 2 + (2 * j + 1 - n) ** 2 <= n * n
            for i in range(n) for j in range(n))
    assert 0.7 * n * n < d < 0.8 * n * n                  # about pi/4 of the square
    assert len(count.pairs) == 3 * d + nt * npf            # was 5 n^2 + nt np
    lights = {p[:3] for p in count.pairs}
    assert len(lights) == 3
    assert sorted(sum(p[:3] == wi for p in count.pairs) for wi in lights) == \
        [d, d, d + nt * npf]                                # 45° warp: disc and 3-D lobe
    assert set(figures) == {"hemisphere.png", "lobe3d.png"}
