"""Redraw latency of ``microcyl explore`` with the browser in the loop: the server started
as a user would, the page in headless Chromium (selenium), a control moved with the keyboard
(arrow keys on a focused control), and the time from the key press to the last of the views
that the control changes redrawn (a parameter: lobe, hemisphere, slice, sphere, albedo; the
incidence: the lobe and the hemisphere; the plane: those and the albedo; the light: the
sphere; tests/_explore_browser.views_of), both read in the page (``performance.now()``).
Every press moves the control one step the same way, to a value not shown before (no
prepared pairs, no numbers computed before are reused). Also the server's own time to
compute a frame (Explorer.frame) after a parameter's and after the incidence's move (the
pairs queued for preparing prepared in between, untimed, as the app does when idle).

``--baseline REV`` serves another revision of the source tree (a git worktree of REV, in
a temporary folder) beside this one, each in its own headless Chromium, and presses the
same key on both in turn: before and after, interleaved in one run on one load.

Goal (issue 39): every view redrawn within 200 ms of a slider move at the default
resolution on a 2-core machine.

    .venv/bin/python bench/bench_explore.py [--moves N] [--baseline REV]
"""

import argparse
import contextlib
import math
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import _explore_browser as eb  # noqa: E402
from selenium.webdriver.common.keys import Keys  # noqa: E402

from reports.explore.data import load_inputs  # noqa: E402
from reports.explore.engine import Explorer  # noqa: E402

#: The parameter sliders, then the view's sliders (each move of these prepares new pairs).
CONTROLS = ("param-gamma_s1", "param-kd1", "param-gamma_v2", "param-eta1", "param-albedo1_r")
GEOMETRY = ("param-theta_i", "param-plane", "param-light_theta", "param-light_phi",
            "param-rotation")


def server_side(moves: int) -> dict:
    ex = Explorer(load_inputs(["linen_plain"]))
    st = ex.initial_state()
    ex.frame(st)                                           # prepare the pairs once
    out = {"server: a parameter's move": [], "server: the incidence's move": []}
    for k in range(1, moves + 1):
        v = dict(st.values, gamma_s1=st.values["gamma_s1"] * (1.0 + 0.01 * k))
        for name, s in zip(out, (st.replace(values=v), st.replace(theta_i=30.0 + k))):
            t = time.perf_counter()
            ex.frame(s)
            out[name].append(time.perf_counter() - t)
            while ex.cache.prepare_pending():           # what the app does when idle
                pass
    return out


def _direction(drv, testid, moves):
    """The arrow that moves ``testid`` ``moves`` steps without reaching its end."""
    lo, hi, v, step = drv.execute_script(
        "for (const d of Bokeh.documents) { const m = d.get_model_by_name(arguments[0]);"
        " if (m) return [m.start, m.end, m.value, m.step]; } return null;", testid)
    return Keys.ARROW_RIGHT if v + moves * step <= hi else Keys.ARROW_LEFT


@contextlib.contextmanager
def _page(root):
    proc, url = eb.start_server("linen_plain", root=root)
    drv = eb.open_browser()
    try:
        eb.load(drv, url)
        eb.press(drv, "param-theta_i", Keys.ARROW_RIGHT)    # warm: the first redraw
        yield drv
    finally:
        drv.quit()
        eb.stop_server(proc)


@contextlib.contextmanager
def _worktree(rev):
    with tempfile.TemporaryDirectory(prefix="bench-explore-") as tmp:
        path = Path(tmp) / "tree"
        git = ["git", "-C", str(eb.ROOT)]
        subprocess.run(git + ["worktree", "add", "-q", "--detach", str(path), rev],
                       check=True)
        try:
            yield path
        finally:
            subprocess.run(git + ["worktree", "remove", "--force", str(path)], check=False)


def browser(moves: int, baseline=None) -> dict:
    """{(tree, control): [seconds]} for ``this`` tree and, with ``baseline``, ``REV``'s,
    the presses interleaved."""
    with contextlib.ExitStack() as stack:
        trees = {"this": eb.ROOT}
        if baseline:
            trees[baseline] = stack.enter_context(_worktree(baseline))
        drivers = {t: stack.enter_context(_page(root)) for t, root in trees.items()}
        out = {}
        for c in CONTROLS + GEOMETRY:
            keys = {t: _direction(d, c, moves) for t, d in drivers.items()}
            for _ in range(moves):
                for t, d in drivers.items():
                    out.setdefault((t, c), []).append(eb.press(d, c, keys[t]))
    return out


def _line(name, xs):
    ms = sorted(1e3 * x for x in xs)
    return (f"{name:40s} median {statistics.median(ms):5.0f} ms  p90 "
            f"{ms[math.ceil(0.9 * len(ms)) - 1]:5.0f} ms  max {ms[-1]:5.0f} ms  "
            f"({len(ms)} moves)")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--moves", type=int, default=10, help="key presses per control")
    p.add_argument("--baseline", metavar="REV",
                   help="a git revision served beside this tree, presses interleaved")
    a = p.parse_args(argv)
    for name, xs in server_side(a.moves).items():
        print(_line(name, xs))
    if eb.CHROMIUM is None or eb.DRIVER is None:
        print("browser: skipped (needs chromium and chromium-driver)")
        return 0
    res = browser(a.moves, a.baseline)
    trees = dict.fromkeys(t for t, _ in res)
    for c in CONTROLS + GEOMETRY:
        for t in trees:
            print(_line(f"{t}: {c} ({'+'.join(eb.views_of(c))})"[:40], res[t, c]))
    for t in trees:
        for label, group in (("parameter sliders", CONTROLS), ("view sliders", GEOMETRY),
                             ("every slider", CONTROLS + GEOMETRY)):
            print(_line(f"{t}: {label}", [x for c in group for x in res[t, c]]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
