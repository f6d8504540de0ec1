"""The report in a real browser: headless Chromium (Debian's ``chromium`` and
``chromium-driver``, driven by selenium) opens every page at 1400 px and checks what a
reviewer would see: no horizontal scrolling, every image loaded, no text under 12 px high
(HTML text by its computed font size; figure text by the image's displayed width over its
natural width times the figure's smallest font in its own pixels, ``data-font-px``).

Skipped, with the reason, where selenium, chromium or chromedriver is missing (``.ci/run``
installs them on Debian). ``MICROCYL_SCREENSHOTS=DIR`` keeps a screenshot of each page.
"""

import os
import shutil
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

from reports import report as rep  # noqa: E402
from reports.report.settings import QUALITIES  # noqa: E402

webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed "
                                "(pip install -e '.[dev]')")

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")
pytestmark = pytest.mark.skipif(
    CHROMIUM is None or DRIVER is None,
    reason="needs Debian's chromium and chromium-driver (apt-get install chromium "
           "chromium-driver; .ci/run does)")

WIDTH = 1400
MIN_PX = 12.0

#: Run in the page: overflow, images not loaded, and text under MIN_PX (HTML and figures).
CHECK = """
const min = arguments[0], out = {overflow: 0, broken: [], small_text: [], small_fig: []};
const de = document.documentElement;
out.overflow = de.scrollWidth - de.clientWidth;
for (const t of document.querySelectorAll('table')) {   // a table scrolling inside itself
  if (t.scrollWidth - t.clientWidth > 1) out.overflow = Math.max(out.overflow, t.scrollWidth - t.clientWidth);
}
for (const img of document.images) {
  if (!(img.complete && img.naturalWidth > 0)) {
    out.broken.push(img.getAttribute('src')); continue;
  }
  const fp = parseFloat(img.dataset.fontPx || '0');
  if (fp > 0) {
    const shown = img.getBoundingClientRect().width / img.naturalWidth * fp;
    if (shown < min) out.small_fig.push([img.getAttribute('src'), shown]);
  }
}
const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
while (walker.nextNode()) {
  const t = walker.currentNode; if (!t.textContent.trim()) continue;
  const el = t.parentElement; const r = el.getBoundingClientRect();
  if (r.width === 0 && r.height === 0) continue;
  const px = parseFloat(getComputedStyle(el).fontSize);
  if (px < min) out.small_text.push([el.tagName, t.textContent.trim().slice(0, 40), px]);
}
return out;
"""


@pytest.fixture(scope="module", params=["default dpi", "fast dpi"])
def report(request, tmp_path_factory):
    """The pages as the default quality lays them out (its dpi: figure text size), drawn
    from the fast quality's few samples; and as ``--quality fast`` itself (the quality the
    tests build: its low dpi must not shrink the figures' text below the limit)."""
    out = tmp_path_factory.mktemp("browser") / "report"
    with pytest.MonkeyPatch.context() as mp:
        if request.param == "default dpi":
            mp.setitem(QUALITIES["fast"], "dpi", QUALITIES["default"]["dpi"])
        rep.build_report(["velvet", "polyester_satin_charmeuse",
                          "polyester_satin_charmeuse_back"], out, quality="fast",
                         progress=False, command="microcyl report --quality fast")
    return out


@pytest.fixture(scope="module")
def browser():
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service
    opts = Options()
    opts.binary_location = CHROMIUM
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--hide-scrollbars", "--force-device-scale-factor=1",
              f"--window-size={WIDTH},900"):
        opts.add_argument(a)
    drv = webdriver.Chrome(service=Service(DRIVER), options=opts)
    try:
        drv.set_window_size(WIDTH, 900)
        yield drv
    finally:
        drv.quit()


def _load(drv, path: Path):
    drv.get(path.as_uri())
    # lazy images load when scrolled to: make them eager, wait for every one
    drv.execute_script("for (const i of document.images) i.loading = 'eager';")
    drv.execute_async_script(
        "const done = arguments[0]; Promise.all([...document.images].map(i => i.complete ? 1 :"
        " new Promise(r => {i.onload = i.onerror = r;}))).then(() => done(1));")


def test_every_page_fits_1400px_loads_its_images_and_has_readable_text(report, browser):
    pages = sorted(report.glob("*.html"))
    assert len(pages) == 4
    shots = os.environ.get("MICROCYL_SCREENSHOTS")
    width = browser.execute_script("return window.innerWidth")
    assert width == pytest.approx(WIDTH, abs=20)
    for page in pages:
        _load(browser, page)
        res = browser.execute_script(CHECK, MIN_PX)
        assert res["overflow"] <= 0, f"{page.name} scrolls sideways by {res['overflow']} px"
        assert res["broken"] == [], f"{page.name}: images not loaded {res['broken']}"
        assert res["small_fig"] == [], f"{page.name}: figure text under {MIN_PX} px"
        assert res["small_text"] == [], f"{page.name}: text under {MIN_PX} px"
        n_img = browser.execute_script("return document.images.length")
        assert n_img >= 3, f"{page.name} shows {n_img} images"
        if shots:
            h = browser.execute_script("return document.documentElement.scrollHeight")
            browser.set_window_size(WIDTH, min(h + 100, 16000))
            browser.save_screenshot(str(Path(shots) / f"{page.stem}.png"))
            browser.set_window_size(WIDTH, 900)


def test_the_checks_catch_a_page_that_breaks_them(tmp_path, browser):
    """The same script on a bad page: a wide table, a missing image, small figure text."""
    (tmp_path / "bad.html").write_text(
        '<!DOCTYPE html><html><body><div style="width:2000px">wide</div>'
        '<img src="missing.png"><p style="font-size:9px">tiny</p></body></html>')
    _load(browser, tmp_path / "bad.html")
    res = browser.execute_script(CHECK, MIN_PX)
    assert res["overflow"] > 0 and res["broken"] == ["missing.png"]
    assert [t[1] for t in res["small_text"]] == ["tiny"]


def test_the_checks_catch_a_table_that_scrolls_inside_itself(tmp_path, browser):
    """A table the stylesheet lets scroll (display:block, overflow-x:auto) hides its last
    columns without scrolling the page: the check counts it as overflow."""
    cells = "".join(f"<td>a_long_unbroken_cell_{k}</td>" for k in range(40))
    (tmp_path / "table.html").write_text(
        '<!DOCTYPE html><html><body><table style="display:block;max-width:100%;'
        f'overflow-x:auto;white-space:nowrap"><tr>{cells}</tr></table></body></html>')
    _load(browser, tmp_path / "table.html")
    assert browser.execute_script(CHECK, MIN_PX)["overflow"] > 0
