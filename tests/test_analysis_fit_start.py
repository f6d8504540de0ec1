"""A fit's start (analysis.fit.optimize, driver): a start that cannot be evaluated is refused
with what to change and leaves nothing in the folder; a point estimate is never worse than its
start; a fit's estimate of its time comes before any work."""

import json

import numpy as np
import pytest

from analysis.fit import FabricModel, fit
from analysis.fit.checkpoint import CONFIG_FILE
from analysis.fit.driver import FitOptions, estimate_time
from analysis.fit.optimize import point_estimate
from analysis.fit.posterior import LogPosterior
from analysis.likelihood import Likelihood
from analysis.params import ParamSpec, defaults_from_fabric
from _fitmodels import fabric_table


def test_a_start_that_cannot_be_evaluated_leaves_nothing(tmp_path):
    table, fab = fabric_table("silk_crepe_de_chine", n=60, seed=2)
    spec = ParamSpec("kd1,gamma_s1", defaults=defaults_from_fabric(fab))
    model = FabricModel(fab, table.wi, table.wo)

    def broken(**kw):
        return np.full_like(model(**kw), np.nan)
    with pytest.raises(ValueError, match="not finite at the start.*check that the fabric "
                                         "matches the table"):
        fit(table, spec, broken, out_dir=tmp_path, max_steps=10, progress=False)
    assert list(tmp_path.iterdir()) == []
    # a configuration with a failed start left by an older version is estimated again
    lines = []
    r = fit(table, spec, model, out_dir=tmp_path, max_steps=20, check_every=10,
            progress=False, notify=lines.append)
    doc = json.loads((tmp_path / CONFIG_FILE).read_text())
    doc["best_logp"] = float("-inf")                  # written as -Infinity
    (tmp_path / CONFIG_FILE).write_text(json.dumps(doc))
    (tmp_path / "checkpoint.h5").unlink()
    r2 = fit(table, spec, model, out_dir=tmp_path, max_steps=20, check_every=10,
             progress=False)
    assert np.isfinite(r2.best_logp) and r2.best_logp == pytest.approx(r.best_logp)
    assert lines == []                  # seconds: not worth a line
    opts = FitOptions(max_steps=1000).resolve(2)
    lp = LogPosterior(spec, Likelihood(table), model)
    seconds, line = estimate_time(lp, opts, 180, True)
    assert line.startswith("fit: 180 values, 2 free parameters; about ") and "a step" in line
    assert "for --max-steps 1000" in line and "the point estimate first" in line
    assert 0 < seconds < 600


def test_the_point_estimate_is_never_worse_than_its_start():
    """A log-posterior of -1e43 at the start and -inf towards the bounds: the old optimizer
    took the bounds for better (its stand-in for -inf was 1e30)."""
    table, fab = fabric_table("silk_crepe_de_chine", n=40, seed=5)
    spec = ParamSpec("kd1", defaults=defaults_from_fabric(fab))

    class Awful(LogPosterior):
        def __call__(self, theta):
            theta = np.atleast_2d(theta)
            return np.where(np.abs(theta[:, 0]) < 2.0, -1e43 * (1 + theta[:, 0] ** 2), -np.inf)

    lp = Awful(spec, Likelihood(table), FabricModel(fab, table.wi, table.wo))
    start = np.array([[0.5]])
    best, best_logp, _ = point_estimate(lp, start)
    assert np.isfinite(best_logp) and best_logp >= lp(start)[0]
    assert abs(best[0]) < 2.0
