"""The explorer without a browser: the model adapter, the prepared-pairs evaluator, the
state's frame, the tables' points and a posterior's band, the document and the verb's
refusals (the browser test: tests/test_reports_explore_browser.py)."""

import numpy as np
import pytest
from bokeh.document import Document
from bokeh.models import Select, Slider

import brdf
import gonio
from analysis.views.lobes import plane_directions
from reports.cli import main
from reports.explore import Controller, Explorer, app
from reports.explore.data import Inputs, lobe_band, lobe_points, load_inputs
from reports.explore.fast import FastBRDF, PreparedCache
from reports.explore.models import explore_model, model_names
from test_cli_state_files import fit  # noqa: F401 (fixture: a short real fit and its table)


@pytest.mark.parametrize("name", model_names())
def test_every_model_builds_from_its_sliders_and_the_fast_path_agrees(name):
    model = explore_model(name)
    obj = model.start("silk_shot")
    values = model.values_of(obj)
    assert set(values) == {s.name for s in model.sliders}
    assert all(s.lo <= values[s.name] <= s.hi for s in model.sliders)
    built = model.build(values, obj)
    wi, wo = plane_directions(40.0, np.linspace(-80, 80, 9), 30.0)
    wi = np.broadcast_to(wi, wo.shape)
    want = obj.eval(wi, wo)
    assert np.allclose(built.eval(wi, wo), want, rtol=1e-9, atol=1e-12)
    cache = PreparedCache()
    fast = FastBRDF(model, values, obj, cache, dtype=np.float64)
    assert np.allclose(fast.eval(wi, wo), want, rtol=1e-9, atol=1e-12)   # the model's own
    assert cache.pending == 1 and not cache.prepare_pending() and len(cache) == 1
    assert np.allclose(fast.eval(wi, wo), want, rtol=1e-9, atol=1e-12)   # prepared
    if model.is_microcylinder:                       # float32: a few 1e-6 relative
        f32 = FastBRDF(model, values, obj, PreparedCache()).eval(wi, wo)
        assert np.allclose(f32, want, rtol=1e-4, atol=1e-9 * want.max())


def test_a_slider_move_changes_every_parameter_view_and_reuses_the_prepared_pairs():
    ex = Explorer(load_inputs(["linen_plain"]))
    st = ex.initial_state()
    a = ex.frame(st)
    assert len(ex.cache) == 0 and ex.cache.pending == 5   # shaded by the fabric, queued
    while ex.cache.prepare_pending():                # what the app does when idle
        pass
    held = len(ex.cache)
    b = ex.frame(st.replace(values=dict(st.values, gamma_s1=st.values["gamma_s1"] * 2)))
    assert len(ex.cache) == held == 5 and ex.cache.pending == 0   # the same pairs
    for view in ("lobe_f", "hemisphere", "slice", "sphere", "albedo"):
        assert not np.allclose(getattr(a, view), getattr(b, view)), view
    assert a.compare_f is None
    d = ex.frame(st.replace(compare="velvet"))       # a preset not loaded: compared too
    assert d.compare_f is not None and not np.allclose(d.compare_f, a.lobe_f)
    c = ex.frame(st.replace(options=dict(st.options, masking=False)))
    assert ex.cache.pending == 5 and not np.allclose(a.lobe_f, c.lobe_f)   # new pairs


@pytest.mark.parametrize("field,value", [("theta_i", 55.0), ("plane", 40.0),
                                         ("light_phi", 90.0), ("light_theta", 20.0)])
def test_a_view_slider_changes_the_views_it_names_and_no_other(field, value):
    """Each frame from an explorer of its own (nothing computed before reused): the views
    that views_moved_by leaves out are equal, those it names differ."""
    from reports.explore.engine import views_moved_by
    arrays = {"lobe": "lobe_f", "hemisphere": "hemisphere", "slice": "slice",
              "sphere": "sphere", "albedo": "albedo"}
    fresh = lambda: Explorer(load_inputs(["velvet"]))  # noqa: E731
    st = fresh().initial_state()
    a, b = fresh().frame(st), fresh().frame(st.replace(**{field: value}))
    moved = views_moved_by(field)
    for view, attr in arrays.items():
        same = np.array_equal(getattr(a, attr), getattr(b, attr), equal_nan=True)
        assert same == (view not in moved), (field, view)
    assert set(b.changed(a)) == set(moved)


def test_table_points_lie_where_they_were_measured_with_their_sigma():
    fab = brdf.fabric("velvet")
    theta = np.array([-60.0, -20.0, 10.0, 50.0])
    wi, wo = plane_directions(30.0, theta, 0.0)
    wi = np.broadcast_to(wi, wo.shape)
    f = fab.eval(wi, wo)
    table = gonio.Table(wi, wo, f, sigma=0.1 * f)
    p = lobe_points(table, 30.0, 0.0, "g")
    assert np.allclose(np.sort(p.theta_o_deg), theta)
    order = np.argsort(p.theta_o_deg)
    assert np.allclose(p.value[order], f[:, 1]) and np.allclose(p.sigma[order], 0.1 * f[:, 1])
    assert lobe_points(table, 60.0, 0.0, "g").value.size == 0      # another incidence


def test_a_posterior_band_holds_its_median_and_widens_with_the_draws():
    model = explore_model()
    fab = model.start("linen_plain")
    base = model.values_of(fab)
    rng = np.random.default_rng(1)
    draws = {k: np.full(40, v) for k, v in base.items()}
    theta = np.linspace(-80, 80, 17)
    narrow = lobe_band(FastBRDF(model, draws, fab, PreparedCache()), theta, 30, 0, "luminance")
    assert np.allclose(narrow.lo, narrow.hi, rtol=1e-6)
    draws["gamma_s1"] = base["gamma_s1"] * np.exp(0.3 * rng.standard_normal(40))
    band = lobe_band(FastBRDF(model, draws, fab, PreparedCache()), theta, 30, 0, "luminance")
    assert np.all(band.lo <= band.median + 1e-12) and np.all(band.median <= band.hi + 1e-12)
    assert np.max(band.hi - band.lo) > 0.01 * np.max(band.median)


def test_the_document_has_a_named_control_per_parameter_and_switches_models():
    doc = Document()
    app(inputs=Inputs(load_inputs(["velvet"]).sources, [], {}))(doc)
    names = {m.name for m in doc.select({"type": Slider})}
    assert {f"param-{s.name}" for s in explore_model().sliders} | {"param-rotation"} <= names
    pick = doc.select_one({"name": "param-model"})
    assert isinstance(pick, Select)
    pick.value = "charlie"                           # Python-side change runs the callback
    names = {m.name for m in doc.select({"type": Slider})}
    assert "param-roughness" in names and "param-gamma_s1" not in names
    assert doc.select_one({"name": "param-rotation"}) is None    # the fabric's alone


def test_the_verb_refuses_a_bad_port_and_an_unknown_source(capsys):
    assert main(["explore", "--no-browser", "--port", "70000"]) != 0
    assert "--port" in capsys.readouterr().err
    assert main(["explore", "--no-browser", "no_such_preset_or_file"]) != 0
    assert "no_such_preset_or_file" in capsys.readouterr().err


def test_a_fit_folder_gives_its_medians_and_band_and_its_table_its_points(fit):
    """A short real fit (tests/test_cli_state_files.py's fixture: silk_crepe_de_chine, 40
    steps) and its table: the sliders start at the medians, the lobe carries the band."""
    inputs = load_inputs([str(fit / "fit"), str(fit / "silk.csv")])
    (src,), ((label, table),) = inputs.sources, inputs.tables
    assert src.kind == "fit" and label == "silk.csv" and len(table) == 60
    draws = inputs.draws[src.label]
    assert draws["gamma_s1"].shape == (48,) and np.ptp(draws["gamma_s1"]) > 0
    ex = Explorer(inputs)
    st = ex.initial_state()
    assert st.source == src.label
    assert np.isclose(st.values["gamma_s1"], src.brdf.threads[0].gamma_s)
    band = ex.frame(st).band
    assert band is not None and np.all(band.lo <= band.hi + 1e-12)
    assert np.max(band.hi - band.lo) > 0


def test_a_refused_value_is_said_as_plain_text_and_nothing_is_drawn():
    """SECURITY.md: a message (which may quote a file's text) reaches the page as text."""
    doc = Document()
    ctl = Controller(doc, Explorer(load_inputs(["velvet"])))
    ctl.redraw()
    assert type(ctl.status).__name__ == "Paragraph"        # text, not a Div's HTML
    before = ctl.src["lobe"].data["x"]
    ctl.state = ctl.state.replace(values=dict(ctl.state.values, eta1=-1.0))
    ctl.redraw()
    assert "eta" in ctl.status.text and ctl.src["lobe"].data["x"] is before
    ctl.state = ctl.state.replace(values=dict(ctl.state.values, eta1=1.5))
    ctl.redraw()
    assert ctl.status.text == "" and ctl.src["lobe"].data["x"] is not before


def test_the_rotation_slider_turns_the_fabric_about_its_normal():
    doc = Document()
    ctl = Controller(doc, Explorer(load_inputs(["silk_shot"])))
    doc.add_root(ctl.layout())
    ctl.redraw()
    before = ctl.src["hemisphere"].data["image"][0].copy()
    doc.select_one({"name": "param-rotation"}).value = 90.0
    assert np.isclose(ctl.state.options["rotation"], np.pi / 2)
    ctl.redraw()
    assert not np.allclose(ctl.src["hemisphere"].data["image"][0], before)


def test_the_notebook_server_accepts_the_running_jupyter_servers_pages_only(tmp_path):
    from reports.explore.notebook import jupyter_origins
    (tmp_path / "jpserver-11.json").write_text('{"port": 8891, "url": "http://localhost:8891/"}')
    (tmp_path / "nbserver-12.json").write_text('{"port": 9000}')
    (tmp_path / "jpserver-13.json").write_text('{"port": "8892; evil"}')   # not a port
    (tmp_path / "jpserver-14.json").write_text("not json")
    (tmp_path / "kernel-15.json").write_text('{"port": 7000}')           # a kernel's, not a server
    assert jupyter_origins(tmp_path) == ["localhost:8891", "127.0.0.1:8891",
                                         "localhost:9000", "127.0.0.1:9000"]
    assert jupyter_origins(tmp_path / "none") == ["localhost:8888", "127.0.0.1:8888"]
