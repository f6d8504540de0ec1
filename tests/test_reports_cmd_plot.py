"""Tests of ``microcyl plot`` (reports.cli.plot) and its figures (reports.plots.views).

End to end: one subprocess per view, as a user runs it, the format chosen by the suffix.
Layout: every view's figure, drawn, has no two texts overlapping and none outside the figure
(window extents of the drawn text artists, computed here from matplotlib's own artists).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from PIL import Image  # noqa: E402

import brdf  # noqa: E402
from gonio import Table  # noqa: E402
from reports import plots  # noqa: E402
from reports.plots import views as plot_views
from reports.cli import main  # noqa: E402
from reports.cli.plot import fitted_fabric  # noqa: E402
from reports.report import overview, sec_figures  # noqa: E402
from reports.report.page import Page  # noqa: E402
from reports.report.sec_energy import EnergyData  # noqa: E402
from reports.report.sections import FabricReport, SectionRun  # noqa: E402
from reports.report.settings import QUALITIES, Section  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
MAGIC = {".png": b"\x89PNG\r\n\x1a\n", ".pdf": b"%PDF", ".svg": b"<?xml"}


def microcyl(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], cwd=cwd or REPO,
                          env=dict(os.environ, PYTHONPATH=str(REPO)), capture_output=True,
                          text=True, timeout=300)


def fake_fit(folder: Path, preset="linen_plain") -> Path:
    """A fit's folder as ``microcyl fit`` leaves it: kd1, gamma_s1, area1 fitted, kd2 and
    area2 tied (its
    configuration holds the spec's description, as the fit writes it)."""
    from analysis.params import ParamSpec, defaults_from_fabric
    folder.mkdir()
    spec = ParamSpec(["kd1", "gamma_s1", "area1"], defaults=defaults_from_fabric(brdf.fabric(preset)),
                     ties=["kd2=kd1", "area2=1-area1"])
    doc = {"schema": "microcyl-fit", "schema_version": 2, "converged": True, "reason": "",
           "parameters": {"kd1": {"median": 0.05}, "gamma_s1": {"median": 20.0},
                          "area1": {"median": 0.4}},
           "fit": {"ties": {"kd2": ["kd1", "equal"], "area2": ["area1", "complement"]}},
           "quality": {}, "plots": {}}
    (folder / "results.json").write_text(json.dumps(doc))
    (folder / "fit_config.json").write_text(json.dumps(
        {"config": {"spec": spec.describe(), "extra": {"fabric": preset, "options": {}}}}))
    return folder


def test_fitted_fabric_takes_medians_and_ties(tmp_path):
    fab, name = fitted_fabric(fake_fit(tmp_path / "fit"))
    base = brdf.fabric("linen_plain")
    t1, t2 = fab.threads
    assert name == "linen_plain"
    assert t1.kd == 0.05 and t2.kd == 0.05 and t1.gamma_s == 20.0
    assert t2.gamma_s == base.threads[1].gamma_s          # not fitted, not tied
    assert t1.area == 0.4 and t2.area == pytest.approx(0.6)       # area2 = 1 - area1
    assert not np.allclose(fab.eval(np.array([0, 0, 1.0]), np.array([0.5, 0, 0.866])),
                           base.eval(np.array([0, 0, 1.0]), np.array([0.5, 0, 0.866])))


# One case a view: arguments after the view, output suffix, what the figure must hold.
CASES = {
    "lobes": (["velvet", "--theta-i", "30,60", "--plane", "warp,45", "--dpi", "120"], ".png"),
    "slices": (["velvet", "linen_plain", "--channel", "g", "--plane", "weft"], ".svg"),
    "hemisphere": (["silk_shot", "--theta-i", "60", "--plane", "45", "--size", "5,4"], ".pdf"),
    "masking": (["velvet", "--theta-i", "70", "--plane", "warp,weft", "--scale", "linear"],
                ".png"),
    "albedo": (["polyester_satin_charmeuse", "polyester_satin_charmeuse_back", "--channel",
                "b", "--plane", "30"], ".png"),
    "reciprocity": (["velvet", "--plane", "warp"], ".pdf"),
}


@pytest.mark.parametrize("view", sorted(CASES))
def test_plot_view_end_to_end(tmp_path, view):
    args, suffix = CASES[view]
    out = tmp_path / f"figure{suffix}"
    p = microcyl("plot", view, *args, "--resolution", 9 if view != "albedo" else 4, "-o", out)
    assert p.returncode == 0, p.stderr
    assert out.read_bytes()[:len(MAGIC[suffix])] == MAGIC[suffix]
    assert f"wrote {out}" in p.stdout and view in p.stdout
    assert [f.name for f in tmp_path.iterdir()] == [out.name]     # no temporary file left
    if suffix == ".png":
        dpi = Image.open(out).info["dpi"]
        assert dpi[0] == pytest.approx(120 if "--dpi" in args else 200, abs=1)
    if suffix == ".pdf":
        assert b"/Type /Page" in out.read_bytes()
    if suffix == ".svg":                     # curves as vector paths
        assert out.read_text().count("<path") > 10


def test_plot_table_against_preset_and_fit(tmp_path, shared_data):
    out = tmp_path / "table.png"
    bsdf = shared_data / "rgl" / "acrylic_felt_purple_rgb.bsdf"
    fit = fake_fit(tmp_path / "fit")
    p = microcyl("plot", "table", bsdf, "velvet", "--fit", fit, "--theta-i", "0,40",
                 "--channel", "r", "--resolution", 19, "-o", out)
    assert p.returncode == 0, p.stderr
    assert out.read_bytes()[:8] == MAGIC[".png"] and Image.open(out).info["dpi"][0] == \
        pytest.approx(200, abs=1)
    assert "wrote" in p.stdout and "table, 2 axes" in p.stdout


@pytest.mark.parametrize("argv, message", [
    (["lobes", "velvet", "-o", "x.jpg"], "-o must end in .png, .pdf or .svg"),
    (["lobes", "denim", "-o", "x.png"], "FABRIC 'denim': not a preset"),
    (["lobes", "velvet", "--plane", "up", "-o", "x.png"], "--plane: expected warp, weft"),
    (["lobes", "velvet", "--theta-i", "95", "-o", "x.png"], "--theta-i: angles must be in"),
    (["table", "velvet", "-o", "x.png"], "table: no such file 'velvet'"),
    (["lobes", "velvet", "--fit", "fit", "-o", "x.png"], "--fit and --preset apply to"),
    (["lobes", "velvet", "--dpi", "0", "-o", "x.png"], "--dpi must be in"),
])
def test_plot_errors_are_one_line(tmp_path, monkeypatch, capsys, argv, message):
    monkeypatch.chdir(tmp_path)
    try:
        status = main(["plot", *argv])
    except SystemExit as exc:                 # usage errors: argparse's exit status 2
        status = exc.code
    err = capsys.readouterr().err
    assert status != 0 and message in err
    assert len(err.strip().splitlines()) == 1 and list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------------------------
# Layout: no text overlaps another or leaves the figure.

def _drawn_texts(fig):
    """The text artists a draw of ``fig`` shows: figure texts and legends, and per axes its
    titles, axis labels, annotations, legend and the tick labels of the ticks in view."""
    texts = list(fig.texts) + [t for leg in fig.legends for t in leg.get_texts()]
    for ax in fig.axes:
        texts += [getattr(ax, n) for n in ("title", "_left_title", "_right_title")]
        axes = [ax.xaxis, ax.yaxis] + ([ax.zaxis] if hasattr(ax, "zaxis") else [])
        for axis in axes:
            texts.append(axis.label)
            for tick in axis._update_ticks():
                texts += [tick.label1, tick.label2]
        texts += list(ax.texts)
        if ax.get_legend() is not None:
            texts += ax.get_legend().get_texts()
    unique = {id(t): t for t in texts}                     # an artist listed twice is one
    return [t for t in unique.values() if t.get_visible() and t.get_text().strip()]


def assert_no_overlap(fig):
    FigureCanvasAgg(fig)
    fig.canvas.draw()               # the layout settles, and with it the ticks in view
    texts = _drawn_texts(fig)
    fig.canvas.draw()               # every label where a draw puts it (3-D tick labels)
    renderer = fig.canvas.get_renderer()
    boxes = [(t.get_text(), t.get_window_extent(renderer).expanded(1.0, 1.0)) for t in texts]
    frame = fig.bbox
    for text, b in boxes:
        assert frame.x0 - 1 <= b.x0 and b.x1 <= frame.x1 + 1 and frame.y0 - 1 <= b.y0 \
            and b.y1 <= frame.y1 + 1, f"{text!r} extends outside the figure: {b} vs {frame}"
    for i, (ta, a) in enumerate(boxes):
        for tb, b in boxes[i + 1:]:
            ox = min(a.x1, b.x1) - max(a.x0, b.x0)
            oy = min(a.y1, b.y1) - max(a.y0, b.y0)
            assert ox <= 1.0 or oy <= 1.0, f"{ta!r} overlaps {tb!r}: {a} and {b}"
    assert len(boxes) > 5                                # the check saw the figure's text


SMALL = dict(resolution=13)
THREE = {n: brdf.fabric(n) for n in ("polyester_satin_charmeuse",
                                     "polyester_satin_charmeuse_back", "velvet")}
TWO = {n: THREE[n] for n in ("polyester_satin_charmeuse", "polyester_satin_charmeuse_back")}
VELVET = {"velvet": THREE["velvet"]}


@pytest.mark.parametrize("view, fabrics, opts", [
    ("lobes", VELVET, dict(scale="log")),
    ("lobes", VELVET, dict(scale="normalized")),
    ("lobes", THREE, dict(theta_i=(30.0, 60.0), planes=(0.0, 90.0))),
    ("slices", VELVET, {}),
    ("slices", THREE, dict(channel="luminance")),
    ("hemisphere", TWO, dict(theta_i=(45.0, 75.0))),
    ("masking", TWO, dict(planes=(0.0, 45.0, 90.0))),
    ("albedo", TWO, dict(planes=(0.0, 90.0), resolution=3)),
    ("reciprocity", VELVET, dict(planes=(0.0, 90.0))),
], ids=lambda v: v if isinstance(v, str) else "")
def test_view_text_does_not_overlap(view, fabrics, opts):
    kw = {**SMALL, **opts}
    assert_no_overlap(plot_views.VIEW_FUNCTIONS[view](fabrics, **kw))


def test_table_view_text_does_not_overlap():
    rng = np.random.default_rng(1)
    ti, to = np.meshgrid([0.0, 40.0], np.linspace(-80, 80, 17), indexing="ij")
    ti, to = ti.ravel(), to.ravel()
    def sph(t, p):
        return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)

    wi = sph(np.radians(ti), np.full(ti.shape, np.pi))
    wo = sph(np.radians(np.abs(to)), np.where(to >= 0, 0.0, np.pi))
    values = 0.1 + 0.01 * rng.random((ti.size, 3))
    values[:3] = 0.0                                         # measured zeros, on a log axis
    table = Table(wi, wo, values, meta={"source": "synthetic"})
    fig = plot_views.table_view(table, {"linen_plain": brdf.fabric("linen_plain"),
                                        "fit (linen_plain)": brdf.fabric("silk_shot")},
                                resolution=13)
    assert_no_overlap(fig)
    with pytest.raises(ValueError, match=r"theta_i must be one of the table's incidences.*"
                                         r"\(0, 40\); got 31"):
        plot_views.table_view(table, {"linen_plain": brdf.fabric("linen_plain")},
                              theta_i=(31.0,))


class CapturePage(Page):
    """A report page that keeps its figures instead of saving them."""

    def figure(self, fig, filename, caption):
        self.figures[filename] = fig
        return ""

    def csv(self, filename, header, rows):
        return ""


@pytest.mark.parametrize("builder", [sec_figures.section_lobes, sec_figures.section_slices,
                                     sec_figures.section_hemisphere,
                                     sec_figures.section_masking],
                         ids=lambda b: b.__name__)
def test_report_figures_text_does_not_overlap(tmp_path, builder):
    """Every figure of the report's figure sections, as the report draws it."""
    page = CapturePage(tmp_path, "velvet", THREE["velvet"], QUALITIES["fast"], "velvet")
    page.figures = {}
    builder(page)
    assert page.figures
    for name, fig in page.figures.items():
        assert_no_overlap(fig)


def test_overview_figures_text_does_not_overlap(tmp_path):
    page = CapturePage(tmp_path, "overview", None, QUALITIES["fast"])
    page.figures = {}
    overview._masking(page)
    theta = np.array([0.0, 45.0, 85.0])
    value = np.full((3, 2, 3), 0.3)
    reports = []
    for name in THREE:
        rep = FabricReport(name, THREE[name])
        data = EnergyData(theta, np.array([0.0, 90.0]), value, value * 0.01, 0.0, (0.5, 0.5, 0.5))
        rep.runs.append(SectionRun("energy", "ok", 0.0, Section("", data)))
        reports.append(rep)
    overview._albedo(page, reports)
    overview._lobes(page, reports)
    for fig in page.figures.values():
        assert_no_overlap(fig)


def test_plot_table_draws_the_fits_model_with_its_tangent_and_overall_scales(tmp_path):
    """A fit of relative data with tangent_scale1 = 1.5 and scale = 0.5: the curve drawn is
    what the fit's own forward model predicts at the medians (analysis.fit.FabricModel with
    tangent_scale, times scale), not the preset's f_r."""
    from analysis.fit import FabricModel
    from analysis.params import ParamSpec, defaults_from_fabric
    from reports.cli.plot import fitted_model
    preset = "silk_crepe_de_chine"
    folder = tmp_path / "fit"
    folder.mkdir()
    spec = ParamSpec(["kd1", "tangent_scale1", "scale"],
                     defaults=defaults_from_fabric(brdf.fabric(preset)))
    doc = {"schema": "microcyl-fit", "schema_version": 2, "converged": True, "reason": "",
           "parameters": {"kd1": {"median": 0.05}, "tangent_scale1": {"median": 1.5},
                          "scale": {"median": 0.5}},
           "fit": {"ties": {}}, "quality": {}, "plots": {}}
    (folder / "results.json").write_text(json.dumps(doc))
    (folder / "fit_config.json").write_text(json.dumps(
        {"config": {"spec": spec.describe(), "extra": {"fabric": preset, "options": {}}}}))
    model, label = fitted_model(folder)
    assert label == f"fit ({preset}, × 0.5)"
    x = np.linspace(-90.0, 90.0, 19)
    t = np.radians(np.abs(x))
    wo = np.stack([np.sin(t) * np.sign(x), np.zeros_like(t), np.cos(t)], -1)  # plane φ = 0
    wi = np.array([-np.sin(np.radians(30.0)), 0.0, np.cos(np.radians(30.0))])
    base = brdf.fabric(preset)
    fab0 = base.replace(threads=(base.threads[0].replace(kd=0.05),) + base.threads[1:])
    ref = 0.5 * FabricModel(fab0, np.broadcast_to(wi, wo.shape), wo)(
        tangent_scale=np.array([1.5, 1.0]))
    table = Table(np.broadcast_to(wi, (5, 3)), wo[::4][:5], np.full((5, 3), 0.1))
    from reports.plots.fit import plot_table_models
    fig, ax = plot_table_models(table, {label: model}, 30.0, 0.0, resolution=19,
                            log=False)
    y = {l.get_gid(): l.get_ydata() for l in ax.get_lines()}[f"model {label}"]
    lum = ref @ np.array([0.2126, 0.7152, 0.0722])
    assert np.allclose(y[1:-1], lum[1:-1], rtol=1e-9)
    unscaled = brdf.fabric(preset).eval(np.broadcast_to(wi, wo.shape), wo) @ \
        np.array([0.2126, 0.7152, 0.0722])
    assert not np.allclose(y[1:-1], unscaled[1:-1], rtol=1e-2)     # not the preset's f_r


def _velvet_fit_folder(folder, preset="velvet"):
    """A fit folder whose medians are the preset's own values (free kd1 at the preset's
    kd1): its model is the preset."""
    from analysis.params import ParamSpec, defaults_from_fabric
    folder.mkdir()
    fab = brdf.fabric(preset)
    spec = ParamSpec(["kd1"], defaults=defaults_from_fabric(fab))
    doc = {"schema": "microcyl-fit", "schema_version": 2, "converged": True, "reason": "",
           "parameters": {"kd1": {"median": float(fab.threads[0].kd)}},
           "fit": {"ties": {}}, "quality": {}, "plots": {}}
    (folder / "results.json").write_text(json.dumps(doc))
    (folder / "fit_config.json").write_text(json.dumps(
        {"config": {"spec": spec.describe(), "extra": {"fabric": preset, "options": {}}}}))
    return folder


def _in_plane_table(fab, theta_i, light_phi):
    """A noiseless table of ``fab`` in the plane phi = 0 / 180: the light at azimuth
    ``light_phi`` (radians), the viewer every 5 degrees from -85 to 85 (signed)."""
    ti, to = np.meshgrid(np.radians(theta_i), np.radians(np.arange(-85.0, 86.0, 5.0)),
                         indexing="ij")
    ti, to = ti.ravel(), to.ravel()
    wi = brdf.directions.from_angles(ti, np.full(ti.shape, light_phi))
    wo = brdf.directions.from_angles(np.abs(to), np.where(to >= 0, 0.0, np.pi))
    return Table(wi, wo, fab.eval(wi, wo), sigma=0.01 * fab.eval(wi, wo) + 1e-6,
                 meta={"source": {"fabric": "velvet", "a": list(range(40))}})


def test_plot_table_fit_model_equals_noiseless_data_at_every_point(tmp_path):
    """Velvet measured with the light at phi = 0 (velvet is not symmetric under the half
    turn: the model at phi = 180 is decades off): the CSV of --data holds, at every
    measured point, the fit's model equal to the data; the drawn curve passes through the
    data; the PNG is at most 3,000 px wide with its four panels wrapped; the title names
    the file, not a dict."""
    import csv as csvmod
    fab = brdf.fabric("velvet")
    table = _in_plane_table(fab, [15.0, 30.0, 45.0, 60.0], 0.0)
    turned = fab.eval(table.wi * [-1, 1, 1], table.wo)        # the light at phi = 180
    assert np.max(np.abs(np.log10(turned[:, 1] + 1e-30) - np.log10(table.values[:, 1]))) > 1
    gonio_path = tmp_path / "t.csv"
    import gonio
    gonio.write(table, gonio_path)
    fit = _velvet_fit_folder(tmp_path / "fit")
    png, data = tmp_path / "t.png", tmp_path / "drawn.csv"
    r = microcyl("plot", "table", gonio_path, "--fit", fit, "--theta-i", "15,30,45,60",
                 "--data", data, "-o", png, "--resolution", "35")
    assert r.returncode == 0, r.stderr
    with open(data, newline="") as fh:
        rows = list(csvmod.DictReader(fh))
    assert list(rows[0]) == ["curve", "theta_i", "phi_i", "theta_o", "phi_o", "f_r"]
    curves = {r["curve"] for r in rows}
    assert curves == {"measured", "fit (velvet)"}
    key = lambda r: tuple(round(float(r[k]), 9) for k in ("theta_i", "phi_i", "theta_o", "phi_o"))
    meas = {key(r): float(r["f_r"]) for r in rows if r["curve"] == "measured"}
    model = {key(r): float(r["f_r"]) for r in rows if r["curve"] != "measured"}
    assert len(meas) == 4 * 35 and meas.keys() == model.keys()
    for k, v in meas.items():
        # equal to the precision of the table file's numbers
        assert model[k] == pytest.approx(v, rel=1e-7, abs=1e-15), k
    # the angles are the measured ones: the light at phi = 0, as measured
    assert all(abs(k[1]) < 1e-6 for k in meas)
    lum = table.values @ np.array([0.2126, 0.7152, 0.0722])
    assert sorted(meas.values()) == pytest.approx(sorted(lum.tolist()), rel=1e-7)
    with Image.open(png) as im:
        assert im.size[0] <= 3000, im.size
        assert im.size[1] > im.size[0] / 3                 # wrapped: more than one row


def test_table_view_curve_passes_through_the_data_with_the_light_where_measured():
    """The curve of each panel is the model with the light where it was measured: at the
    data's signed theta_o it equals the data (velvet, light at phi = 0 and at 180)."""
    fab = brdf.fabric("velvet")
    for light in (0.0, np.pi):
        table = _in_plane_table(fab, [15.0], light)
        fig = plot_views.table_view(table, {"velvet": fab}, resolution=37, scale="linear")
        (ax,) = fig.axes
        lines = {l.get_gid(): l for l in ax.get_lines()}
        xd, yd = lines["data"].get_data()
        xc, yc = lines["model velvet"].get_data()
        assert np.allclose(np.interp(xd, xc, yc), yd, rtol=1e-9)
        assert "{" not in fig._suptitle.get_text()
