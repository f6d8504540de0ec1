"""A fit's progress (analysis.fit.progress, analysis.fit.convergence.expected_steps): the bar's
total is the step count the convergence rule is expected to need, re-estimated from tau at each
check; on a pipe one plain line a check. The CLI test runs ``microcyl fit`` as a user would,
its output to a pipe."""

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gonio
from analysis.fit import fit
from analysis.fit import progress as fit_progress_module
from analysis.fit.convergence import Criteria, Diagnosis, expected_steps
from analysis.fit.posterior import FabricModel
from analysis.params import ParamSpec, defaults_from_fabric
from gonio.progress import interactive
from _fitmodels import fabric_table

REPO = Path(__file__).resolve().parents[1]


def _diag(step, burn, tau):
    return Diagnosis(step=step, burn=burn, chains=None, log_prob=None, taus=None,
                     tau=np.asarray(tau, float), rhat=np.ones(len(tau)))


@pytest.mark.parametrize("step, burn, tau, every, cap, want", [
    # N (1 - 0.2) > 50 x 12 -> N > 750 (strictly): the next multiple of 50 above is 800
    (100, 20, [3.0, 12.0], 50, 20000, 800),
    # a refit's burn-in of 400 at step 500: N - 400 > 50 x 10 -> N > 900 (and 500 / 0.8 = 625)
    (500, 400, [10.0], 50, 20000, 950),
    # the rule already met at this check (N/tau = 80 / 1 > 50): at least the next check
    (100, 20, [1.0], 50, 20000, 150),
    # beyond the step limit: the limit
    (100, 20, [100.0], 50, 3000, 3000),
    # tau undefined (a walker that did not move): the limit
    (100, 20, [np.nan, 2.0], 50, 3000, 3000),
])
def test_expected_steps(step, burn, tau, every, cap, want):
    assert expected_steps(_diag(step, burn, tau), Criteria(), every, cap) == want


def test_expected_steps_grows_with_tau_and_stops_at_convergence():
    c = Criteria(min_ratio=20.0, burn_fraction=0.5)
    a = expected_steps(_diag(100, 50, [5.0]), c, 10, 10**6)
    b = expected_steps(_diag(200, 100, [9.0]), c, 10, 10**6)
    assert (a, b) == (210, 370)                 # above 20 x 5 / 0.5 and 20 x 9 / 0.5
    assert expected_steps(_diag(200, 100, [9.0]), c, 10, 10**6, converged=True) == 200


def test_interactive_is_false_for_a_pipe_or_a_file(tmp_path):
    assert not interactive(io.StringIO())
    with open(tmp_path / "log", "w") as fh:
        assert not interactive(fh)


@pytest.fixture
def small_fit():
    table, fab = fabric_table("velvet", n=80, seed=2)
    spec = ParamSpec("gamma_s1", defaults=defaults_from_fabric(fab))
    return table, spec, FabricModel(fab, table.wi, table.wo)


def test_the_bar_total_follows_tau(monkeypatch, small_fit):
    """On a terminal: no total (no ETA) before the first check, then the step count the
    rule needs from the tau of that check (here the fit's last: a time limit stops it
    there), not --max-steps."""
    import tqdm.auto
    totals = []

    class RecordingBar(tqdm.auto.tqdm):
        def refresh(self, *a, **kw):
            totals.append(self.total)
            return super().refresh(*a, **kw)

    monkeypatch.setattr(tqdm.auto, "tqdm", RecordingBar)
    monkeypatch.setattr(fit_progress_module, "interactive", lambda: True)
    table, spec, model = small_fit
    r = fit(table, spec, model, max_steps=20000, check_every=20, time_limit=1e-3,
            threads=1, ensembles=2, progress=True, seed=1)
    assert r.steps == 20 and not r.converged
    assert totals[0] is None
    tau = r.summary["gamma_s1"]["tau"]
    need = max(50 * tau / 0.8, r.burn + 50 * tau, r.steps + 1)   # at least the next check
    assert totals[-1] == int((np.floor(need / 20) + 1) * 20) < 20000


def test_a_pipe_gets_one_line_a_check(monkeypatch, small_fit):
    lines = []
    monkeypatch.setattr(fit_progress_module, "interactive", lambda: False)
    monkeypatch.setattr(fit_progress_module, "progress_line", lines.append)
    table, spec, model = small_fit
    r = fit(table, spec, model, max_steps=60, check_every=20, threads=1, ensembles=2,
            progress=True, seed=1)
    assert [int(s.split("step ")[1].split(",")[0]) for s in lines] == [20, 40, 60][:len(lines)]
    assert len(lines) == r.steps // 20
    assert all("\r" not in s and "\n" not in s for s in lines)


def test_microcyl_fit_to_a_pipe_writes_lines_not_carriage_returns(tmp_path):
    """``microcyl fit`` with its progress on and stdout and stderr piped: no carriage
    return anywhere, one line a check (every 25 steps up to the 75 it is allowed)."""
    table, _ = fabric_table("silk_crepe_de_chine", n=120, seed=9)
    path = tmp_path / "silk.csv"
    gonio.write(table, path)
    out = tmp_path / "fit"
    p = subprocess.run([sys.executable, "-m", "reports", "fit", str(path), "--fabric",
                        "silk_crepe_de_chine", "--free", "gamma_s1,kd1", "--tie", "none",
                        "--max-steps", "75", "--check-every", "25", "--ensembles", "2",
                        "--no-plots", "-o", str(out)],
                       cwd=REPO, env=dict(os.environ, PYTHONPATH=str(REPO)),
                       capture_output=True, timeout=600)
    assert p.returncode == 0, p.stderr.decode()[-2000:]
    assert b"\r" not in p.stderr and b"\r" not in p.stdout
    checks = [s for s in p.stderr.decode().splitlines() if s.startswith("emcee: step")]
    steps = json.loads((out / "results.json").read_text())["fit"]["steps"]
    assert [int(s.split("step ")[1].split(",")[0]) for s in checks] == \
        list(range(25, steps + 1, 25))
    assert steps == 75 or "converged" in checks[-1]
    assert all("expected total" in s for s in checks[:-1])


def test_a_pipe_line_carries_the_time_a_step_took_measured(monkeypatch, small_fit):
    """The start's estimate of a step is one batch timed before the run; on a pipe each
    check's line says the time a step took over the steps run (here made 0.5 s a step by a
    clock that advances 10 s between the start and the first check of 20 steps)."""
    lines = []
    clock = iter([100.0, 110.0, 130.0])
    monkeypatch.setattr(fit_progress_module, "interactive", lambda: False)
    monkeypatch.setattr(fit_progress_module, "progress_line", lines.append)
    monkeypatch.setattr(fit_progress_module.time, "perf_counter", lambda: next(clock))
    from analysis.fit.driver import FitOptions
    opts = FitOptions(max_steps=1000, check_every=20)
    with fit_progress_module.fit_progress(True, opts) as (tick, postfix):
        postfix({}, _diag(20, 4, [2.0]), False)
        postfix({}, _diag(40, 8, [2.0]), False)
    assert "0.5 s a step (measured)" in lines[0]
    assert "0.75 s a step (measured)" in lines[1]       # 30 s over 40 steps
    total = int(lines[1].split("expected total ")[1].split(" ")[0])
    from analysis.budget import format_seconds
    assert f"about {format_seconds(0.75 * (total - 40))} left" in lines[1]


def test_a_bar_on_a_pipe_writes_whole_lines(monkeypatch):
    """On a pipe tqdm is given no width: a long description is not cut at 80 columns."""
    import gonio.progress as gp
    out = io.StringIO()
    monkeypatch.setattr(gp.sys, "stderr", out)
    desc = "render cylinder (mitsuba llvm_ad_rgb) with a long name " + "x" * 60
    with gp.progress_bar(4, desc=desc, unit="section") as bar:
        bar.update(4)
    lines = out.getvalue().splitlines()
    assert lines and all(desc in s for s in lines)
    assert max(map(len, lines)) > 120 and lines[-1].rstrip().endswith("section/s]")
