"""Redraw latency of ``microcyl explore`` with the browser in the loop: the server started
as a user would, the page in headless Chromium (selenium), a slider moved with the keyboard
(arrow keys on a focused control), and the time from the key press to the last of the five
views redrawn (lobe, hemisphere, slice, sphere, albedo), both read in the page
(``performance.now()``). Also the server's own time to compute every view (Explorer.frame).

Goal (issue 39): every view redrawn within 200 ms of a slider move at the default
resolution on a 2-core machine.

    .venv/bin/python bench/bench_explore.py [--moves N]
"""

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import _explore_browser as eb  # noqa: E402
from selenium.webdriver.common.keys import Keys  # noqa: E402

from reports.explore.data import load_inputs  # noqa: E402
from reports.explore.engine import Explorer  # noqa: E402

CONTROLS = ("param-gamma_s1", "param-kd1", "param-gamma_v2", "param-eta1", "param-albedo1_r")


def server_side(moves: int) -> list:
    ex = Explorer(load_inputs(["linen_plain"]))
    st = ex.initial_state()
    ex.frame(st)                                           # prepare the pairs once
    out = []
    for k in range(moves):
        v = dict(st.values, gamma_s1=st.values["gamma_s1"] + 0.1 * (k % 2))
        t = time.perf_counter()
        ex.frame(st.replace(values=v))
        out.append(time.perf_counter() - t)
    return out


def browser(moves: int, control_list=CONTROLS) -> dict:
    proc, url = eb.start_server("linen_plain")
    drv = eb.open_browser()
    out = {}
    try:
        eb.load(drv, url)
        eb.press(drv, "param-theta_i", Keys.ARROW_RIGHT)    # warm: the first redraw
        for c in control_list:
            out[c] = [eb.press(drv, c, Keys.ARROW_RIGHT if k % 2 else Keys.ARROW_LEFT)
                      for k in range(moves)]
        out["param-theta_i (new pairs)"] = [eb.press(drv, "param-theta_i", Keys.ARROW_RIGHT)
                                            for _ in range(3)]
    finally:
        drv.quit()
        eb.stop_server(proc)
    return out


def _line(name, xs):
    ms = sorted(1e3 * x for x in xs)
    return (f"{name:28s} median {statistics.median(ms):6.0f} ms  p90 "
            f"{ms[int(0.9 * (len(ms) - 1))]:6.0f} ms  max {ms[-1]:6.0f} ms  ({len(ms)} moves)")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--moves", type=int, default=10, help="key presses per control")
    a = p.parse_args(argv)
    print(_line("server: every view's numbers", server_side(a.moves)))
    if eb.CHROMIUM is None or eb.DRIVER is None:
        print("browser: skipped (needs chromium and chromium-driver)")
        return 0
    res = browser(a.moves)
    for name, xs in res.items():
        print(_line(name, xs))
    sliders = [x for k, xs in res.items() if k in CONTROLS for x in xs]
    print(_line("all parameter sliders", sliders))
    return 0


if __name__ == "__main__":
    sys.exit(main())
