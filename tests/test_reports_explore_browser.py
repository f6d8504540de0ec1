"""``microcyl explore`` in a real browser: the server started as a user would
(``--no-browser --port 0``, in a subprocess), the page opened in headless Chromium, controls
moved with the keyboard. Every control and view carries its ``data-testid``; an arrow key
on a focused control changes its value and redraws every view; the page logs no error and
loads nothing from another host.

Skipped, with the reason, where selenium, chromium or chromedriver is missing.
``MICROCYL_EXPLORE_SHOT=FILE`` writes a screenshot of the page (docs/_static/explore.png).
"""

import os

import pytest

from reports.explore.models import explore_model

webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed "
                                "(pip install -e '.[dev]')")
from selenium.webdriver.common.keys import Keys  # noqa: E402

import _explore_browser as eb  # noqa: E402

pytestmark = pytest.mark.skipif(
    eb.CHROMIUM is None or eb.DRIVER is None,
    reason="needs Debian's chromium and chromium-driver (apt-get install chromium "
           "chromium-driver; .ci/run does)")


@pytest.fixture(scope="module")
def page():
    proc, url = eb.start_server("linen_plain", "velvet")
    drv = eb.open_browser()
    try:
        eb.load(drv, url)
        yield drv, url
    finally:
        drv.quit()
        eb.stop_server(proc)


def _value(drv, name):
    return drv.execute_script(
        "for (const d of Bokeh.documents) { const m = d.get_model_by_name(arguments[0]);"
        " if (m) return m.value; } return null;", name)


def test_every_control_and_view_has_a_testid(page):
    drv, _ = page
    ids = set(eb.testids(drv))
    params = {f"param-{s.name}" for s in explore_model("microcylinder").sliders}
    assert "param-gamma_s1" in params and params <= ids
    views = {f"view-{v}" for v in ("lobe", "hemisphere", "slice", "sphere", "albedo")}
    assert views <= ids
    assert {"param-theta_i", "param-plane", "param-channel", "param-masking",
            "param-preset", "param-compare"} <= ids


@pytest.mark.parametrize("control,key,delta", [("param-gamma_s1", Keys.ARROW_RIGHT, 1),
                                               ("param-theta_i", Keys.ARROW_LEFT, -1),
                                               ("param-kd2", Keys.ARROW_UP, 1)])
def test_arrow_keys_move_a_control_and_redraw_every_view(page, control, key, delta):
    drv, _ = page
    before, drawn = _value(drv, control), eb.versions(drv)
    seconds = eb.press(drv, control, key)        # waits until the views it moves redrew
    after, now = _value(drv, control), eb.versions(drv)
    assert (after - before) * delta > 0, (control, before, after)
    assert 0 < seconds < 30
    moved = eb.views_of(control)                 # a parameter: every view
    assert control == "param-theta_i" or moved == eb.VIEWS
    unchanged = {v for v in eb.VIEWS if now[v] == drawn[v]}
    assert unchanged == set(eb.VIEWS) - set(moved), (control, unchanged)


def test_a_choice_moves_with_the_keyboard(page):
    drv, _ = page
    assert _value(drv, "param-channel") == "luminance"
    eb.press(drv, "param-channel", Keys.ARROW_DOWN)
    assert _value(drv, "param-channel") == "r"
    eb.press(drv, "param-channel", Keys.ARROW_UP)
    assert _value(drv, "param-channel") == "luminance"


def test_no_console_error_and_nothing_from_another_host(page):
    drv, url = page
    if os.environ.get("MICROCYL_EXPLORE_SHOT"):
        drv.set_window_size(1400, 1040)
        drv.execute_script("window.scrollTo(0, 0);")
        drv.save_screenshot(os.environ["MICROCYL_EXPLORE_SHOT"])
        drv.set_window_size(1500, 800)
    errors = [e for e in drv.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]
    assert not errors, errors
    assert eb.foreign_requests(drv, url.rstrip("/")) == []
    scripts = drv.execute_script("return [...document.scripts].map(s => s.src)"
                                 ".filter(s => s);")
    assert scripts and all(s.startswith(url.rstrip("/")) for s in scripts), scripts
