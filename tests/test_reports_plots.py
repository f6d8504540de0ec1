"""Tests of the plot modules: every plot returns a figure holding the expected data.

Reference values are computed here from the BRDF directly, with direction formulas written out
independently of reports.plots.common.
"""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import brdf  # noqa: E402
from analysis import AlbedoResult  # noqa: E402
from gonio import Table  # noqa: E402
from reports import plots  # noqa: E402
from reports_standin import Lambert, Phongish  # noqa: E402

W = np.array([0.2126, 0.7152, 0.0722])


def sph(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    t, p = np.broadcast_arrays(t, p)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def ev(fab, wi, wo):
    wi, wo = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
    return fab.eval(wi.reshape(-1, 3), wo.reshape(-1, 3)).reshape(wi.shape)


@pytest.fixture(scope="module")
def velvet():
    return brdf.fabric("velvet")


@pytest.fixture(scope="module")
def silk():
    return brdf.fabric("silk_crepe_de_chine")


def lines_by_gid(ax):
    return {l.get_gid(): l for l in ax.get_lines() if l.get_gid()}


@pytest.mark.parametrize("phi", [0.0, 45.0, 90.0])
def test_polar_lobe_values_equal_eval(velvet, phi):
    fig, ax = plots.plot_polar_lobe(velvet, [20.0, 50.0], phi, resolution=37)
    lines = lines_by_gid(ax)
    for ti in (20.0, 50.0):
        line = lines[f"lobe theta_i={ti:g} luminance"]
        x = np.degrees(line.get_xdata())
        assert np.allclose(x, np.linspace(-90, 90, 37))
        # light on the far side of the plane: azimuth phi + 180
        wi = sph(ti, phi + 180.0)
        wo = np.where((x >= 0)[:, None], sph(np.abs(x), phi), sph(np.abs(x), phi + 180.0))
        expected = ev(velvet, wi, wo) @ W
        # interior points: at the horizon itself (z ~ 6e-17) the model is sensitive to
        # round-off in the other components
        assert np.allclose(line.get_ydata()[1:-1], expected[1:-1], rtol=1e-10, atol=1e-14)
    assert ax.name == "polar"


def test_polar_lobe_rgb_and_log(silk):
    fig, ax = plots.plot_polar_lobe(silk, 30.0, 0.0, quantity="rgb", resolution=19)
    lines = lines_by_gid(ax)
    x = np.linspace(-90, 90, 19)
    wo = np.where((x >= 0)[:, None], sph(np.abs(x), 0.0), sph(np.abs(x), 180.0))
    f = ev(silk, sph(30.0, 180.0), wo)
    for k, c in enumerate("rgb"):
        line = lines[f"lobe theta_i=30 {c}"]
        assert np.allclose(line.get_ydata()[1:-1], f[1:-1, k])
        assert line.get_color() == ("tab:red", "tab:green", "tab:blue")[k]
    fig, ax = plots.plot_polar_lobe(silk, 30.0, 0.0, scale="log", decades=3, resolution=19)
    y = lines_by_gid(ax)["lobe theta_i=30 luminance"].get_ydata()
    lum = f @ W
    floor = 10.0 ** np.floor(np.log10(lum.max()) - 3)
    assert np.allclose(y[1:-1], np.log10(np.maximum(lum, floor) / floor)[1:-1])


def test_lobe_planes_and_comparison(velvet, silk):
    fig, axes = plots.plot_lobe_planes(velvet, (30.0,), (0.0, 90.0), resolution=11)
    assert len(axes) == 2 and all(a.name == "polar" for a in axes)
    fig, ax = plots.plot_lobe_comparison({"velvet": velvet, "silk": silk}, 40.0, 90.0,
                                         scale="linear", resolution=13)
    lines = lines_by_gid(ax)
    x = np.linspace(-90, 90, 13)
    wo = np.where((x >= 0)[:, None], sph(np.abs(x), 90.0), sph(np.abs(x), 270.0))
    assert np.allclose(lines["lobe silk"].get_ydata()[1:-1],
                       (ev(silk, sph(40.0, 270.0), wo) @ W)[1:-1])



def _tick_texts(ax):
    return [t.get_text() for t in ax.get_yticklabels()]


def test_log_lobe_panels_share_their_decades(velvet, silk):
    """Every panel of a log figure: one floor (the power of 10 four decades below the
    figure's peak, found here from eval), so the same radius is the same f_r in each, and
    the same radial limit and tick labels."""
    from reports.plots.views import lobes_view
    thetas, planes, n = (0.0, 30.0, 60.0), (0.0, 45.0, 90.0), 37
    fig, axes = plots.plot_lobe_planes(velvet, thetas, planes, scale="log", resolution=n)
    x = np.linspace(-90, 90, n)
    lum = {}
    for phi in planes:
        wo = np.where((x >= 0)[:, None], sph(np.abs(x), phi), sph(np.abs(x), phi + 180.0))
        for ti in thetas:
            lum[phi, ti] = ev(velvet, sph(ti, phi + 180.0), wo) @ W
    peaks = {phi: max(lum[phi, ti].max() for ti in thetas) for phi in planes}
    assert max(peaks.values()) > 2 * min(peaks.values())   # the panels' own scales differ
    floor = 10.0 ** np.floor(np.log10(max(peaks.values())) - 4)
    for ax, phi in zip(axes, planes):
        lines = lines_by_gid(ax)
        for ti in thetas:
            y = lines[f"lobe theta_i={ti:g} luminance"].get_ydata()
            ref = np.log10(np.maximum(lum[phi, ti], floor) / floor)
            assert np.allclose(y[1:-1], ref[1:-1], atol=1e-9)
        assert ax.get_ylim() == axes[0].get_ylim()
        assert list(ax.get_yticks()) == list(axes[0].get_yticks())
        assert _tick_texts(ax) == _tick_texts(axes[0])
    assert axes[0].get_ylim()[1] >= np.log10(max(peaks.values()) / floor)
    # several fabrics: a grid of comparisons, one set of decades for all of it
    fig = lobes_view({"velvet": velvet, "silk": silk}, theta_i=(30.0, 60.0), planes=(0.0, 90.0),
                     resolution=n)
    polar = [ax for ax in fig.axes if ax.name == "polar"]
    assert len(polar) == 4
    assert len({ax.get_ylim() for ax in polar}) == 1
    assert len({tuple(_tick_texts(ax)) for ax in polar}) == 1


def test_saves_only_when_given_a_filename(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    lam = Lambert()
    plots.plot_polar_lobe(lam, resolution=5)
    plots.plot_hemisphere(lam, resolution=8)
    assert list(tmp_path.iterdir()) == []
    target = tmp_path / "sub" / "lobe.png"
    target.parent.mkdir()
    fig, ax = plots.plot_polar_lobe(lam, resolution=5, filename=target)
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in target.parent.iterdir()] == ["lobe.png"]  # no temp file left
    plots.plot_slice_theta_h(lam, resolution=5, filename=tmp_path / "s.svg")
    assert (tmp_path / "s.svg").read_text().lstrip().startswith("<?xml")


def test_given_axes_are_used(velvet):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    f2, a2 = plots.plot_slice_theta_o(velvet, ax=ax, resolution=5)
    assert f2 is fig and a2 is ax
    with pytest.raises(ValueError, match="projection"):
        plots.plot_polar_lobe(velvet, ax=ax)
    plt.close(fig)


def test_half_diff_conversion_properties():
    th, td, pd, ph = np.radians([25.0, 40.0, 70.0, 30.0])
    wi, wo = plots.half_diff_to_io(th, td, pd, ph)
    h = (wi + wo) / np.linalg.norm(wi + wo)
    assert np.allclose(h, sph(25.0, 30.0))
    assert np.degrees(np.arccos(wi @ h)) == pytest.approx(40.0)
    assert np.linalg.norm(wi) == pytest.approx(1.0) and np.linalg.norm(wo) == pytest.approx(1.0)
    # theta_h = 0: h = n, wi at (theta_d, phi_d), wo its mirror about n
    wi, wo = plots.half_diff_to_io(0.0, td, pd, 0.0)
    assert np.allclose(wi, sph(40.0, 70.0))
    assert np.allclose(wo, sph(40.0, 250.0))


def test_cartesian_slices_equal_eval(silk):
    x = np.linspace(0, 89.5, 7)
    fig, ax = plots.plot_slice_theta_o(silk, 30.0, 180.0, 45.0, resolution=7)
    f = ev(silk, sph(30.0, 180.0), sph(x, 45.0))
    for k, c in enumerate("rgb"):
        assert np.allclose(lines_by_gid(ax)[f"theta_o {c}"].get_ydata(), f[:, k])
    # theta_d slice at theta_h = 0: wi = (theta_d, phi_d), wo = (theta_d, phi_d + 180)
    fig, ax = plots.plot_slice_theta_d(silk, 0.0, 60.0, resolution=7, quantity="luminance")
    x = lines_by_gid(ax)["theta_d luminance"].get_xdata()
    assert x[-1] == pytest.approx(89.5)
    inside = x < 90
    expected = ev(silk, sph(x, 60.0), sph(x, 240.0)) @ W
    assert np.allclose(lines_by_gid(ax)["theta_d luminance"].get_ydata()[inside],
                       expected[inside])
    fig, ax = plots.plot_slice_theta_h(silk, 10.0, 90.0, 0.0, resolution=7, quantity="g")
    wi, wo = plots.half_diff_to_io(np.radians(np.linspace(0, 89.5, 7)), np.radians(10.0),
                                   np.radians(90.0))
    assert np.allclose(lines_by_gid(ax)["theta_h g"].get_ydata(), ev(silk, wi, wo)[:, 1])


def test_slice_image_equals_eval(velvet):
    fig, ax = plots.plot_slice_image(velvet, 90.0, resolution=6)
    img = np.asarray(ax.images[0].get_array())
    assert img.shape == (6, 6)
    centres = (np.arange(6) + 0.5) * 15.0
    r, c = 4, 1   # theta_d = 67.5, theta_h = 22.5
    wi, wo = plots.half_diff_to_io(np.radians(centres[c]), np.radians(centres[r]),
                                   np.radians(90.0))
    assert img[r, c] == pytest.approx(float(ev(velvet, wi, wo) @ W))



def _bar_gap(fig, ax):
    """(gap between the image's right edge and its colour bar's left edge, image width),
    in pixels of the drawn figure; the bar is the axes holding a colour bar of the image."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    im = ax.images[0]
    bar = im.colorbar.ax
    img_box = ax.get_window_extent()
    return bar.get_window_extent().x0 - img_box.x1, img_box.width


def test_the_colour_bar_sits_beside_its_image(velvet):
    """No wide gap between an image and its colour bar: at most a tenth of the image's
    width, alone and in the slices view's grid (whose image keeps its aspect)."""
    from reports.plots.views import slices_view
    fig, ax = plots.plot_slice_image(velvet, 90.0, resolution=8)
    gap, width = _bar_gap(fig, ax)
    assert 0 <= gap <= 0.1 * width, (gap, width)
    fig = slices_view({"velvet": velvet}, resolution=9)
    ax = next(a for a in fig.axes if a.images)
    gap, width = _bar_gap(fig, ax)
    assert 0 <= gap <= 0.1 * width, (gap, width)


def test_hemisphere_is_equal_area_and_equals_eval(silk):
    n = 40
    fig, ax = plots.plot_hemisphere(silk, 45.0, 30.0, resolution=n)
    img = ax.images[0].get_array()
    assert img.shape == (n, n)
    c = (np.arange(n) + 0.5) / n * 2 - 1
    y, x = np.meshgrid(c, c, indexing="ij")
    rho = np.hypot(x, y)
    assert np.array_equal(np.ma.getmaskarray(img), rho > 1)
    theta = np.degrees(2 * np.arcsin(np.clip(rho, 0, 1) / np.sqrt(2)))
    phi = np.degrees(np.arctan2(y, x))
    expected = ev(silk, sph(45.0, 30.0), sph(theta, phi)) @ W
    inside = rho <= 1
    assert np.allclose(img[inside], expected[inside])
    # equal area: the cap theta < 60 degrees has half the hemisphere's solid angle
    assert np.mean(theta[inside] < 60.0) == pytest.approx(0.5, abs=0.03)
    assert "1/sr" in fig.axes[-1].get_ylabel()   # the colour bar
    fig, ax = plots.plot_hemisphere(silk, 45.0, 30.0, quantity="srgb", resolution=8)
    assert ax.images[0].get_array().shape == (8, 8, 4)


def test_lobe_3d(velvet):
    fig, ax = plots.plot_lobe_3d(velvet, 40.0, 0.0, resolution=(7, 9))
    assert ax.name == "3d"
    t, p = np.meshgrid(np.linspace(0, 90, 7), np.linspace(0, 360, 9), indexing="ij")
    r = ev(velvet, sph(40.0, 0.0), sph(t, p)) @ W * np.cos(np.radians(t))
    zmax = float(np.max(r * np.cos(np.radians(t))))
    surf = ax.collections[0]
    assert len(surf.get_facecolors()) == 6 * 8
    assert ax.zz_dataLim.intervalx[1] >= zmax * (1 - 1e-9)


def test_masking_views(velvet):
    fig, ax = plots.plot_masking_lobes(velvet, 70.0, 0.0, resolution=13)
    lines = lines_by_gid(ax)
    x = np.linspace(-90, 90, 13)
    wo = np.where((x >= 0)[:, None], sph(np.abs(x), 0.0), sph(np.abs(x), 180.0))
    off = brdf.fabric("velvet", masking=False)
    inner = slice(1, -1)  # away from the horizon (see test_polar_lobe_values_equal_eval)
    assert np.allclose(lines["masking off"].get_ydata()[inner],
                       (ev(off, sph(70.0, 180.0), wo) @ W)[inner])
    assert np.allclose(lines["masking on"].get_ydata()[inner],
                       (ev(velvet, sph(70.0, 180.0), wo) @ W)[inner])
    assert not np.allclose(lines["masking on"].get_ydata(), lines["masking off"].get_ydata())
    fig, ax = plots.plot_masking_terms((30.0,), resolution=13)
    lines = lines_by_gid(ax)
    x = np.linspace(-180, 180, 13)
    assert np.allclose(lines["M"].get_ydata(), np.maximum(np.cos(np.radians(x)), 0))
    assert np.allclose(lines["u"].get_ydata(), np.exp(-x ** 2 / (2 * 20.0 ** 2)))
    # pair weight at phi_o = 0 against phi_i = 30: delta = -30 degrees
    ud = np.exp(-30.0 ** 2 / (2 * 20.0 ** 2))
    mi, mo = np.cos(np.radians(30.0)), 1.0
    expected = (1 - ud) * mi * mo + ud * min(mi, mo)
    assert lines["pair phi_i=30"].get_ydata()[6] == pytest.approx(expected)
    with pytest.raises(ValueError, match="replace"):
        plots.plot_masking_lobes(Lambert())


def test_albedo_from_arrays_and_results():
    theta = np.array([0.0, 30.0, 60.0])
    val = np.array([[0.5, 0.6, 0.7], [0.4, 0.5, 0.6], [0.3, 0.2, 1.1]])
    err = np.full((3, 3), 0.01)

    result = AlbedoResult(value=val, error=err, direction=np.zeros((3, 3)), swap=False,
                          method="threads", evals=0, level=np.zeros(3, int))
    fig, ax = plots.plot_albedo(theta, result)
    lines = lines_by_gid(ax)
    for k, c in enumerate("rgb"):
        assert np.allclose(lines[f"albedo albedo {c}"].get_ydata(), val[:, k])
    fig, ax = plots.plot_albedo(theta, val, err, quantity="luminance", label="x")
    assert np.allclose(lines_by_gid(ax)["albedo x luminance"].get_ydata(), val @ W)
    fig, ax = plots.plot_albedo(theta, val[:, 0])
    assert np.allclose(lines_by_gid(ax)["albedo albedo grey"].get_ydata(), val[:, 0])
    with pytest.raises(ValueError, match="albedo must have shape"):
        plots.plot_albedo(theta, val[:2])
    with pytest.raises(ValueError, match="error"):
        plots.plot_albedo(theta, val, err[:, :2])


def test_reciprocity_map():
    b = Phongish()
    theta, err = plots.reciprocity_map(b, 180.0, 0.0, resolution=5)
    assert np.allclose(theta, [9, 27, 45, 63, 81])
    i, o = 1, 3
    wi, wo = sph(theta[i], 180.0), sph(theta[o], 0.0)
    a, c = ev(b, wi, wo) @ W, ev(b, wo, wi) @ W
    assert err[i, o] == pytest.approx(abs(a - c) / max(a, c))
    assert err.max() > 0.01
    theta, err0 = plots.reciprocity_map(Lambert(), resolution=4)
    assert np.all(err0 == 0)
    fig, ax = plots.plot_reciprocity_map(b, resolution=5)
    assert np.allclose(ax.images[0].get_array(), err)
    fig, ax = plots.plot_reciprocity_map(theta_deg=theta, error=err0)
    with pytest.raises(ValueError, match="square"):
        plots.plot_reciprocity_map(error=np.zeros((2, 3)))


def test_fit_overlay(silk):
    x = np.linspace(-80, 80, 17)
    rows_wi, rows_wo = [], []
    for ti in (20.0, 50.0):
        for s in x:
            rows_wi.append(sph(ti, 180.0))
            rows_wo.append(sph(abs(s), 0.0 if s >= 0 else 180.0))
    rows_wi.append(sph(30.0, 60.0))          # off the plane: left out
    rows_wo.append(sph(30.0, 100.0))
    wi, wo = np.array(rows_wi), np.array(rows_wo)
    vals = ev(silk, wi, wo) * 1.1
    vals[3] = np.nan                                # invalid: left out
    table = Table(wi.copy(), wo.copy(), vals, sigma=0.05 * np.nan_to_num(vals) + 1e-4)
    fig, ax = plots.plot_fit_overlay(table, silk, 0.0, resolution=9)
    lines = lines_by_gid(ax)
    data = lines["data theta_i=20 r"]
    keep = np.ones(17, bool)
    keep[3] = False
    assert np.allclose(data.get_xdata(), x[keep])
    assert np.allclose(data.get_ydata(), vals[:17, 0][keep])
    xm = np.linspace(-90, 90, 9)
    wom = np.where((xm >= 0)[:, None], sph(np.abs(xm), 0.0), sph(np.abs(xm), 180.0))
    assert np.allclose(lines["model theta_i=50 b"].get_ydata()[1:-1],
                       ev(silk, sph(50.0, 180.0), wom)[1:-1, 2])
    assert "data theta_i=30 r" not in lines
    with pytest.raises(ValueError, match="no valid points"):
        plots.plot_fit_overlay(table, silk, 37.0)


@pytest.mark.parametrize("call, match", [
    (lambda b: plots.plot_polar_lobe(b, 95.0), "theta_i_deg"),
    (lambda b: plots.plot_polar_lobe(b, quantity="hsv"), "quantity"),
    (lambda b: plots.plot_polar_lobe(b, scale="sqrt"), "scale"),
    (lambda b: plots.plot_hemisphere(b, quantity="rgb"), "quantity"),
    (lambda b: plots.plot_slice_theta_h(b, resolution=1), "resolution"),
    (lambda b: plots.plot_lobe_3d(b, resolution=(1, 1)), "resolution"),
])
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call(Lambert())


def test_reciprocity_map_and_statistics_share_one_definition():
    """The report's map and its pair statistics measure the same error: on the map's own grid
    the largest map value is reciprocity()'s max, and a hand-computed cell agrees."""
    import brdf
    from analysis.reciprocity import reciprocity
    from reports.plots.reciprocity import reciprocity_map
    fab = brdf.fabric("velvet")
    theta, err = reciprocity_map(fab, resolution=9)
    t = np.radians(theta)
    TI, TO = np.meshgrid(t, t, indexing="ij")
    ang = lambda th, ph: np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph),
                                   np.cos(th)], -1)
    wi, wo = ang(TI, np.pi), ang(TO, 0.0 * TO)
    stats = reciprocity(fab, (wi.reshape(-1, 3), wo.reshape(-1, 3)))
    assert np.nanmax(err) == pytest.approx(stats.max, rel=1e-12)
    y = lambda f: f @ np.array([0.2126, 0.7152, 0.0722])
    a, b = y(fab.eval(wi[2, 5], wo[2, 5])), y(fab.eval(wo[2, 5], wi[2, 5]))
    assert err[2, 5] == pytest.approx(abs(a - b) / max(a, b), rel=1e-12)


def test_polar_lobe_takes_a_preset_name_and_names_anything_else():
    fig, ax = plots.plot_polar_lobe("velvet", 30.0, 0.0, resolution=7)
    ref, _ = plots.plot_polar_lobe(brdf.fabric("velvet"), 30.0, 0.0, resolution=7)
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(),
                                  ref.axes[0].get_lines()[0].get_ydata())
    with pytest.raises(ValueError, match="brdf must be a preset.*'velour'"):
        plots.plot_polar_lobe("velour")
    with pytest.raises(TypeError, match="brdf must be a preset name or a BRDF.*int"):
        plots.plot_polar_lobe(3)


def test_lobe_figures_evaluate_each_curve_once():
    """plot lobes of two fabrics and plot_lobe_planes: each curve evaluated once (the shared
    radial limit read from the same curves), and the drawn line is the curve."""
    from reports.plots import views as plot_views

    class Counted(Lambert):
        pairs = 0

        def eval(self, wi, wo):
            type(self).pairs += wi.shape[0]
            return super().eval(wi, wo)

    plot_views.lobes_view({"a": Counted(), "b": Counted()}, resolution=7)
    assert Counted.pairs == 2 * 9 * 7                  # 2 fabrics x 3 incidences x 3 planes
    Counted.pairs = 0
    fig, axes = plots.plot_lobe_planes(Counted(), (30.0,), (0.0, 90.0), scale="linear",
                                       resolution=7)
    assert Counted.pairs == 2 * 7
    y = Lambert().eval(np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, 1.0]]))[0] @ W
    assert np.allclose(axes[1].get_lines()[0].get_ydata()[1:-1], y)


def test_hemisphere_x_label_clears_its_colour_bar():
    """In the report's row of three hemispheres (11 in wide) each disc's x label stays
    clear of every colour bar (on one line it ran under its own)."""
    import brdf as _brdf
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from analysis.views import compute_hemisphere
    from reports.plots.hemisphere import draw_hemisphere
    from reports.report.page import new_figure
    fab = _brdf.fabric("velvet")
    fig, axes = new_figure(3, 1, figsize=(11.0, 3.6))
    for ax, (ti, phi) in zip(axes, ((45.0, 0.0), (45.0, 90.0), (60.0, 45.0))):
        draw_hemisphere(compute_hemisphere(fab, ti, phi, 15), ax=ax)
    FigureCanvasAgg(fig).draw()
    r = fig.canvas.get_renderer()
    bars = [a for a in fig.axes if a not in list(axes)]
    assert len(bars) == 3
    for ax in axes:
        label = ax.xaxis.label.get_window_extent(r)
        assert not any(label.overlaps(b.get_window_extent(r)) for b in bars)


def test_a_half_disc_legend_sits_under_the_disc():
    """The lobes' legend below a half-disc polar plot: within 60 pt of the disc's flat edge,
    not under the empty lower half of the axes' box."""
    import brdf as _brdf
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from reports.plots.lobes import plot_lobe_comparison
    fabs = {n: _brdf.fabric(n) for n in ("velvet", "polyester_satin_charmeuse")}
    fig, ax = plot_lobe_comparison(fabs, 30, 0, resolution=19)
    FigureCanvasAgg(fig).draw()
    r = fig.canvas.get_renderer()
    edge_y = ax.transData.transform((0.0, 0.0))[1]          # the disc's centre, display px
    top = ax.get_legend().get_window_extent(r).y1
    assert 0 < (edge_y - top) * 72.0 / fig.dpi < 60.0


def _pt(fig, pixels):
    return pixels * 72.0 / fig.dpi


def _polar_layout(fig):
    """Per polar axes, in points: the gap from the top of the disc and its angle labels to
    the title, and the lowest point of its labels; and per figure legend its top."""
    fig.draw_without_rendering()
    gaps, bottoms = [], []
    for ax in (a for a in fig.axes if a.name == "polar"):
        top = max([ax.transData.transform((0.0, ax.get_rmax()))[1]]
                  + [t.get_window_extent().y1 for t in ax.get_xticklabels() if t.get_text()])
        gaps.append(_pt(fig, ax.title.get_window_extent().y0 - top))
        texts = [t for t in [*ax.texts, *ax.get_xticklabels(), *ax.get_yticklabels()]
                 if t.get_text()]
        bottoms.append(min(t.get_window_extent().y0 for t in texts))
    legend_gaps = [_pt(fig, min(bottoms) - leg.get_window_extent().y1) for leg in fig.legends]
    return gaps, legend_gaps


def _lobe_figures(velvet, silk):
    from reports.plots.views import lobes_view, masking_view
    yield "polar lobe", plots.plot_polar_lobe(velvet, (30.0, 60.0), resolution=19)[0]
    yield "comparison", plots.plot_lobe_comparison({"v": velvet, "s": silk}, 30.0,
                                                   resolution=19)[0]
    yield "planes", plots.plot_lobe_planes(velvet, (30.0,), scale="log", resolution=19)[0]
    yield "masking", plots.plot_masking_lobes(velvet, 60.0, resolution=19)[0]
    yield "plot lobes, two fabrics", lobes_view({"v": velvet, "s": silk}, theta_i=(30.0, 60.0),
                                                resolution=19)
    yield "plot masking, two rows", masking_view({"v": velvet, "s": silk}, resolution=19)


def test_lobe_figures_keep_title_and_legend_next_to_the_half_disc(velvet, silk):
    """Issue 40: the half disc sat in the middle of a square box, a quarter of it empty above
    (23 to 47 pt between the title and the disc) and below (a figure legend 19 to 21 pt away
    from the labels). Now the title is a title's pad away, the legend a few points."""
    for name, fig in _lobe_figures(velvet, silk):
        gaps, legend_gaps = _polar_layout(fig)
        assert gaps and all(0.0 < g < 8.0 for g in gaps), (name, gaps)
        assert all(0.0 < g < 10.0 for g in legend_gaps), (name, legend_gaps)


def test_the_half_disc_is_round_and_fills_its_box(velvet):
    fig, ax = plots.plot_polar_lobe(velvet, (30.0,), resolution=19)
    fig.draw_without_rendering()
    box = ax.get_window_extent()
    rmax = ax.get_rmax()
    (cx, cy), (lx, ly), (tx, ty), (rx, ry) = ax.transData.transform(
        [(0.0, 0.0), (-np.pi / 2, rmax), (0.0, rmax), (np.pi / 2, rmax)])
    radius = cx - lx
    assert np.allclose([rx - cx, ty - cy], radius, rtol=1e-6)       # round, not squashed
    assert np.allclose([lx, rx, cy, ty], [box.x0, box.x1, box.y0, box.y1], atol=0.5)
    # the clip path is the disc: a point just inside the rim at 60 degrees is kept
    inside = ax.transData.transform((np.radians(60.0), 0.99 * rmax))
    assert ax.patch.get_path().transformed(ax.patch.get_transform()).contains_point(inside)
