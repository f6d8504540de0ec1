"""Readable objects: the short reprs and Jupyter tables of Thread, Fabric, Table and FitResult
say what they hold (checked against the objects' own fields), stay short, and escape text."""

import html.parser

import numpy as np
import pytest

import brdf
import gonio
from analysis.fit import FitResult
from brdf import Fabric, Thread  # noqa: F401  (eval of the reprs)


class _Cells(html.parser.HTMLParser):
    """The text of every cell and caption, and the tags seen."""

    def __init__(self, page):
        super().__init__()
        self.tags, self.text = [], []
        self.feed(page)

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)

    def handle_data(self, data):
        self.text.append(data)


@pytest.mark.parametrize("name", sorted(brdf.PRESETS))
def test_fabric_repr_evaluates_to_the_same_model(name):
    fab = brdf.fabric(name).replace(masking=False, gap="outgoing")
    text = repr(fab)
    assert text.startswith(f"Fabric(name={name!r}, threads=(Thread(eta=")
    assert "masking=False" in text and "gap='outgoing'" in text
    assert "reweighting" not in text            # options at their defaults are left out
    again = eval(text)
    wi = brdf.directions.from_angles(np.radians([10, 40, 70]), np.radians([0, 50, 200]))
    wo = brdf.directions.from_angles(np.radians([30, 60, 20]), np.radians([180, 0, 90]))
    np.testing.assert_allclose(again.eval(wi, wo), fab.eval(wi, wo), rtol=1e-3)
    assert len(text) < 400


def test_thread_repr_rounds_and_keeps_one_tuples():
    t = Thread(1.4623456, (0.2, 0.1, 0.05), 0.3, 12, 24, 0.4, (-25, 25), (1,))
    assert repr(t) == ("Thread(eta=1.462, albedo=(0.2, 0.1, 0.05), kd=0.3, gamma_s=12, "
                       "gamma_v=24, area=0.4, offsets=(-25, 25), lengths=(1,))")
    assert eval(repr(t)).lengths == (1.0,)


def test_fabric_html_is_a_parameter_table_with_escaped_name():
    fab = brdf.fabric("velvet").replace(name="<script>alert(1)</script>")
    cells = _Cells(fab._repr_html_())
    assert "script" not in cells.tags
    assert cells.tags.count("tr") == 3            # a header and one row a thread
    text = "".join(cells.text)
    assert "<script>alert(1)</script>" in text    # shown as text
    assert "gamma_s (deg)" in text and "masking=True" in text


def test_table_repr_names_pairs_channels_sigma_ranges_and_source():
    fab = brdf.fabric("velvet")
    t = gonio.measure(fab, "plane:warp:15", gonio.Instrument(snr=30), seed=1, progress=False)
    text = repr(t)
    assert text.startswith(f"Table({len(t)} pairs, RGB, sigma yes, theta_i 0..75, ")
    assert "phi_o 0..180 deg" in text and "velvet" in text
    grey = gonio.Table(t.wi, t.wo, t.values[:, 0], meta={"source": "x" * 500})
    assert repr(grey).startswith(f"Table({len(t)} pairs, grey, sigma no,")
    assert len(repr(grey)) < 250                 # a long source is cut
    values = t.values.copy()
    values[:2, 1] = np.nan
    assert f"2 of {values.size} values invalid" in repr(t.replace(values=values))


def test_table_html_escapes_its_source():
    t = gonio.Table([[0, 0, 1.0]], [[0, 0, 1.0]], [0.1], meta={"source": "<img src=x>"})
    cells = _Cells(t._repr_html_())
    assert "img" not in cells.tags and "<img src=x>" in "".join(cells.text)


def _result(**changes):
    fields = dict(names=("kd1", "gamma_s1"), units=("1", "deg"),
                  chains=np.zeros((4, 10, 8, 2)), chains_internal=np.zeros((4, 10, 8, 2)),
                  log_prob=np.zeros((4, 10, 8)),
                  summary={"kd1": dict(median=0.3012345, lo68=0.29, hi68=0.31, lo95=0.28,
                                       hi95=0.32, tau=5.0, n_over_tau=60.0, rhat=1.001,
                                       ess=900.0, unit="1"),
                           "gamma_s1": dict(median=12.0, lo68=11.5, hi68=12.5, lo95=11.0,
                                            hi95=13.0, tau=6.0, n_over_tau=55.0, rhat=1.002,
                                            ess=800.0, unit="deg")},
                  converged=True, reason="converged at step 350", steps=350, burn=70,
                  walkers=8, ensembles=4, acceptance=[0.3] * 4, best={}, best_logp=0.0,
                  counts={}, timing={})
    fields.update(changes)
    return FitResult(**fields)


def test_fit_result_repr_shows_medians_not_chains():
    r = _result(chains=np.full((4, 1000, 8, 2), 7.25))
    text = repr(r)
    assert text == ("FitResult(converged, 350 steps x 4 ensembles x 8 walkers, "
                    "kd1=0.3012 [0.28, 0.32], gamma_s1=12 [11, 13])")
    warned = _result(converged=False, warnings=[{"kind": "at_bound", "message": "m"}] * 2)
    assert repr(warned).startswith("FitResult(not converged,")
    assert repr(warned).endswith(", 2 warnings)")


def test_fit_result_html_escapes_reason_and_warnings():
    r = _result(reason="<b>bold</b>", warnings=[{"kind": "x", "message": "<i>it</i>"}])
    cells = _Cells(r._repr_html_())
    assert "b" not in cells.tags and "i" not in cells.tags
    text = "".join(cells.text)
    assert "<b>bold</b>" in text and "<i>it</i>" in text
    assert cells.tags.count("tr") == 3 and "0.3012" in text and "deg" in text
