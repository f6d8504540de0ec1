"""Helpers of the explorer's browser test and bench (bench/bench_explore.py): start
``microcyl explore --no-browser --port 0`` in a subprocess, open it in headless Chromium
(selenium, Debian's chromium and chromium-driver), find elements by ``data-testid`` through
Bokeh's shadow roots, move a control with the keyboard and wait until every view has
redrawn (its ``data-version``)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")
#: The views every slider move redraws.
VIEWS = ("lobe", "hemisphere", "slice", "sphere", "albedo")
#: The controls that set a field of the state (engine.State) of their own name.
_FIELDS = {"theta_i", "plane", "light_theta", "light_phi", "channel", "compare", "model",
           "source"}


def views_of(testid: str) -> tuple:
    """The views of :data:`VIEWS` that control ``testid`` changes (the engine's
    ``views_moved_by``: the incidence moves the lobe and the hemisphere only)."""
    from reports.explore.engine import views_moved_by
    from reports.explore.figures import SCALED
    from reports.explore.models import VARIANTS
    name = testid.removeprefix("param-")
    if name == "scale":
        moved = SCALED
    elif name in _FIELDS:
        moved = views_moved_by(name)
    else:
        moved = views_moved_by("options" if name in (*VARIANTS, "rotation") else "values")
    return tuple(v for v in VIEWS if v in moved)

#: JS: every element under the document and its shadow roots matching a selector.
DEEP = """
function deep(root, sel, out) {
  for (const el of root.querySelectorAll('*')) {
    if (el.matches(sel)) out.push(el);
    if (el.shadowRoot) deep(el.shadowRoot, sel, out);
  }
  return out;
}
"""


def start_server(*sources, timeout: float = 120.0, root: Path = ROOT):
    """``(process, url)`` of ``microcyl explore --no-browser --port 0 SOURCES``, run from
    the source tree ``root`` (another checkout's: its packages before the installed ones)."""
    env = dict(os.environ, PYTHONUNBUFFERED="1", PYTHONPATH=str(root))
    proc = subprocess.Popen([sys.executable, "-m", "reports", "explore", "--no-browser",
                             "--port", "0", *sources], cwd=root, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + timeout
    for line in proc.stdout:
        m = re.search(r"serving (http://127\.0\.0\.1:\d+/)", line)
        if m:
            return proc, m.group(1)
        if time.monotonic() > deadline:
            break
    proc.kill()
    raise RuntimeError(f"microcyl explore did not print its address: {line!r}")


def stop_server(proc) -> None:
    proc.terminate()
    try:
        proc.wait(10)
    except subprocess.TimeoutExpired:
        proc.kill()


def open_browser(width: int = 1500, height: int = 800):
    from selenium import webdriver                        # the dev extra's
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service
    opts = Options()
    opts.binary_location = CHROMIUM
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--hide-scrollbars", "--force-device-scale-factor=1"):
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    drv = webdriver.Chrome(service=Service(DRIVER), options=opts)
    drv.set_window_size(width, height)
    return drv


def testids(drv) -> list:
    """Every ``data-testid`` on the page (through shadow roots)."""
    return drv.execute_script(DEEP + "return deep(document, '[data-testid]', [])"
                              ".map(e => e.dataset.testid);")


def by_testid(drv, testid):
    return drv.execute_script(DEEP + "return deep(document, arguments[0], [])[0] || null;",
                              f'[data-testid="{testid}"]')


def versions(drv) -> dict:
    """Each view's redraw count."""
    return drv.execute_script(
        "const o = {}, v = window.__microcylViews || {};"
        "for (const k in v) o[k] = Number(v[k].dataset.version); return o;")


def wait_for(fn, timeout: float = 60.0, every: float = 0.01):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        got = fn()
        if got:
            return got
        time.sleep(every)
    raise TimeoutError("condition not met")


def load(drv, url, views=VIEWS, controls=("param-theta_i",)):
    """Open the page and wait until every view and the controls are tagged."""
    drv.get(url)
    wait_for(lambda: all(v in versions(drv) for v in views)
             and all(by_testid(drv, c) is not None for c in controls), timeout=120)


def press(drv, testid, key, views=None, timeout: float = 30.0) -> float:
    """Focus control ``testid``, press ``key`` once, and wait until every view of ``views``
    (by default those the control changes, :func:`views_of`) redrew; the seconds from the
    key press (the page's keydown) to the last view's redraw (its ``data-drawn-at``), both
    measured in the page."""
    views = views_of(testid) if views is None else views
    el = by_testid(drv, testid)
    drv.execute_script("arguments[0].focus();", el)
    before = versions(drv)
    el.send_keys(key)
    wait_for(lambda: all(versions(drv).get(v, 0) > before.get(v, 0) for v in views),
             timeout=timeout, every=0.05)
    return drv.execute_script(
        "const v = window.__microcylViews;"
        "const t = arguments[0].map(k => Number(v[k].dataset.drawnAt));"
        "return (Math.max(...t) - window.__microcylKeyAt) / 1000;", list(views))


def foreign_requests(drv, host: str) -> list:
    """Every resource the page loaded from anywhere but ``host``."""
    urls = drv.execute_script("return performance.getEntriesByType('resource')"
                              ".map(e => e.name).concat([location.href]);")
    return [u for u in urls if not u.startswith(host)]
