"""The log-posterior's analytic gradient (analysis.fit.gradient) against central differences
of the log-posterior itself, for free sets with ties, albedo, rotation (finite differences of
the model) and the nuisance parameters; the point estimate it drives reaches the same optimum
as the finite-difference one; models without derivatives fall back."""

import numpy as np
import pytest

from analysis.fit import FabricModel
from analysis.fit.driver import with_nuisance
from analysis.fit.gradient import gradient_available, logpost_and_grad
from analysis.fit.optimize import point_estimate
from analysis.fit.posterior import LogPosterior
from analysis.likelihood import Likelihood
from analysis.params import ParamSpec, defaults_from_fabric
from brdf import jit
from _fitmodels import fabric_table

needs_drjit = pytest.mark.skipif(not jit.available()[0],
                                 reason=f"Dr.Jit does not run here: {jit.available()[1]}")


def _central(lp, x, h=1e-5):
    out = []
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        out.append((lp((x + e)[None])[0] - lp((x - e)[None])[0]) / (2 * h))
    return np.array(out)


@needs_drjit
@pytest.mark.parametrize("free, ties, sigma, kind", [
    ("eta1,kd1,kd2,gamma_s1,gamma_v1,gamma_s2,gamma_v2,area1", ("eta2=eta1", "area2=1-area1"),
     True, "gaussian"),
    ("kd1,gamma_v1,albedo1_r,albedo1_g,rotation", ("albedo2_r=albedo1_r",), False,
     "student-t"),
])
def test_gradient_matches_central_differences(free, ties, sigma, kind):
    table, fab = fabric_table("velvet", n=80, seed=3, with_sigma=sigma)
    lik = Likelihood(table, kind=kind)
    spec = with_nuisance(ParamSpec(free, defaults=defaults_from_fabric(fab), ties=ties), lik)
    lp = LogPosterior(spec, lik, FabricModel(fab, table.wi, table.wo))
    assert gradient_available(lp)
    x = spec.start() + np.random.default_rng(1).normal(scale=0.2, size=spec.ndim)
    f, g = logpost_and_grad(lp, x)
    assert f == pytest.approx(lp(x[None])[0], rel=1e-12)
    ref = _central(lp, x)
    assert np.all(np.abs(g - ref) <= 1e-4 * np.abs(ref) + 1e-3), (g, ref)
    # outside the prior's support: -inf, no gradient
    x[0] = 1e3
    f, g = logpost_and_grad(lp, x)
    assert f == -np.inf and not g.any()


@needs_drjit
def test_analytic_point_estimate_reaches_the_fd_optimum():
    table, fab = fabric_table("silk_crepe_de_chine", n=120, seed=4)
    spec = ParamSpec("kd1,gamma_s1,gamma_v1,area1", defaults=defaults_from_fabric(fab),
                     ties=("area2=1-area1",))
    lp = LogPosterior(spec, Likelihood(table), FabricModel(fab, table.wi, table.wo))
    starts = spec.start()[None] + 0.3
    x_fd, f_fd, _ = point_estimate(lp, starts, gradient="fd")
    x_ad, f_ad, _ = point_estimate(lp, starts, gradient="analytic")
    assert f_ad == pytest.approx(f_fd, abs=1e-3)
    assert f_ad > lp(starts)[0] + 1.0
    with pytest.raises(ValueError, match="gradient must be one of auto, fd, analytic; got 'x'"):
        point_estimate(lp, starts, gradient="x")


def test_models_without_derivatives_fall_back():
    table, fab = fabric_table("silk_crepe_de_chine", n=40, seed=5)
    spec = ParamSpec("kd1", defaults=defaults_from_fabric(fab))
    model = FabricModel(fab, table.wi, table.wo)
    lp = LogPosterior(spec, Likelihood(table), lambda **kw: model(**kw))    # no ``prep``
    assert not gradient_available(lp)
    assert logpost_and_grad(lp, spec.start()) is None
    x, f, _ = point_estimate(lp, spec.start()[None], gradient="analytic")   # the FD one
    assert f >= lp(spec.start()[None])[0]
