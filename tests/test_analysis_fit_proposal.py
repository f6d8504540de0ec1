"""Tests of analysis.fit.proposal: the mixture independence proposal and its warps."""

import numpy as np


# ---------------------------------------------------------------- the independence proposal
def _two_blobs(n, rng):
    """Samples of 0.3 N((-3, 0), 0.5^2 I) + 0.7 N((2, 1), diag(1, 0.25))."""
    k = rng.random(n) < 0.3
    x = np.where(k[:, None], rng.normal([-3.0, 0.0], 0.5, (n, 2)),
                 rng.normal([2.0, 1.0], [1.0, 0.5], (n, 2)))
    return x, k


def test_mixture_proposal_finds_the_components():
    from analysis.fit.proposal import LaplaceMove
    x, k = _two_blobs(4000, np.random.default_rng(1))
    from scipy.stats import norm
    move = LaplaceMove.from_samples(x, 2, np.random.default_rng(2), df=1e6, scale=1.0)
    order = np.argsort(move.means[:, 0])
    np.testing.assert_allclose(move.weights[order], [0.3, 0.7], atol=0.03)
    np.testing.assert_allclose(move.means[order], [[-3, 0], [2, 1]], atol=0.1)
    np.testing.assert_allclose(np.sqrt(np.diagonal(move.chols[order] @ np.swapaxes(
        move.chols[order], 1, 2), axis1=1, axis2=2)), [[0.5, 0.5], [1.0, 0.5]], rtol=0.1)
    # its draws (nearly Gaussian at df = 1e6) follow the blobs: left of x = -0.5 lie the left
    # blob and the right blob's tail beyond 2.5 sd
    draws = move.sample(20000, np.random.default_rng(3))
    left = np.mean(draws[:, 0] < -0.5)
    assert abs(left - (0.3 + 0.7 * norm.cdf(-2.5))) < 0.03
    # too few samples for the components: no proposal rather than a degenerate one
    assert LaplaceMove.from_samples(x[:15], 2, np.random.default_rng(2)) is None


def test_mixture_move_leaves_the_target_invariant():
    """Independence MH with a deliberately wrong two-component proposal (wrong weights,
    different widths) must still sample the target: the Hastings factor needs each
    component's normalization."""
    import emcee
    from analysis.fit.proposal import LaplaceMove
    from scipy.special import logsumexp

    def logp(x):
        a = np.log(0.3) - 0.5 * (((x - [-3.0, 0.0]) / 0.5) ** 2).sum(-1) - 2 * np.log(0.5)
        b = np.log(0.7) - 0.5 * (((x - [2.0, 1.0]) / [1.0, 0.5]) ** 2).sum(-1) - np.log(0.5)
        return logsumexp([a, b], axis=0)

    move = LaplaceMove([[-3.0, 0.0], [2.0, 1.0]], [np.eye(2) * 2.0, np.eye(2) * 0.5],
                       df=5, scale=1.0, weights=[0.6, 0.4])
    s = emcee.EnsembleSampler(32, 2, logp, moves=[(move, 1.0)], vectorize=True)
    s.random_state = np.random.RandomState(4).get_state()
    s.run_mcmc(np.random.default_rng(5).normal(size=(32, 2)), 3000, progress=False)
    x = s.get_chain(discard=500, flat=True)
    left = np.mean(x[:, 0] < -0.5)
    # 80,000 draws with an autocorrelation of a few steps: the standard error of the share is
    # below 0.01; 0.03 is three times that
    assert abs(left - 0.3) < 0.03
    np.testing.assert_allclose(x.mean(axis=0), [0.3 * -3 + 0.7 * 2, 0.7 * 1.0], atol=0.1)


def test_warp_round_trip_and_jacobian():
    from analysis.fit.proposal import warp, unwarp
    rng = np.random.default_rng(7)
    u = rng.normal(scale=4.0, size=(500, 3))
    kinds = [0, 1, 2]
    v, lj = warp(u, kinds)
    np.testing.assert_allclose(unwarp(v, kinds), u, rtol=1e-9, atol=1e-9)
    # log q and -log(1 - q) of q = expit(u), and the Jacobian by central differences
    q = 1 / (1 + np.exp(-u))
    np.testing.assert_allclose(v[:, 1], np.log(q[:, 1]), rtol=1e-9)
    np.testing.assert_allclose(v[:, 2], -np.log1p(-q[:, 2]), rtol=1e-9)
    h = 1e-6
    num = sum(np.log((warp(u + h * e, kinds)[0] - warp(u - h * e, kinds)[0])[:, i] / (2 * h))
              for i, e in enumerate(np.eye(3)))
    np.testing.assert_allclose(lj, num, atol=1e-6)
    # outside the image of a warp: NaN rows, the other rows untouched
    w = unwarp(np.array([[0.0, -1.0, 1.0], [0.0, 0.5, 1.0], [0.0, -1.0, -0.1]]), kinds)
    assert np.all(np.isfinite(w[0])) and np.all(np.isnan(w[1:]))


def test_warped_mixture_move_leaves_the_target_invariant():
    """Independence MH whose proposal lives in log q and -log(1 - q) coordinates, deliberately
    off (centres, widths) and putting mass outside the warps' images: the chain must still
    sample the target, which needs the warp's Jacobian in log q(x)."""
    import emcee
    from analysis.fit.proposal import LaplaceMove
    from scipy.special import betaln, expit
    from scipy.stats import beta
    a1, b1, a2, b2 = 2.0, 30.0, 30.0, 2.0

    def logp(u):   # u = logit(q), q1 ~ Beta(2, 30), q2 ~ Beta(30, 2): density q^a (1-q)^b
        q = expit(u)
        return (a1 * np.log(q[:, 0]) + b1 * np.log1p(-q[:, 0]) - betaln(a1, b1)
                + a2 * np.log(q[:, 1]) + b2 * np.log1p(-q[:, 1]) - betaln(a2, b2))

    move = LaplaceMove([-2.0, 2.2], np.diag([0.9, 0.5]), df=5, scale=1.0, warps=[1, 2])
    draws = move.sample(4000, np.random.default_rng(1))
    assert 0.01 < np.mean(np.isnan(draws[:, 0])) < 0.2       # some draws leave the support
    s = emcee.EnsembleSampler(32, 2, logp, moves=[(move, 1.0)], vectorize=True)
    s.random_state = np.random.RandomState(4).get_state()
    s.run_mcmc(np.random.default_rng(5).normal([-3.0, 3.0], 0.3, size=(32, 2)), 3000,
               progress=False)
    q = expit(s.get_chain(discard=500, flat=True))
    # 80,000 draws with an autocorrelation of a few steps; Beta means 1/16 and 15/16 with a
    # standard deviation of 0.042: the standard error of each mean is below 5e-4
    np.testing.assert_allclose(q.mean(axis=0), [a1 / (a1 + b1), a2 / (a2 + b2)], atol=2e-3)
    assert abs(np.mean(q[:, 0] < 0.05) - beta.cdf(0.05, a1, b1)) < 0.02


def test_proposal_quality_is_the_expected_acceptance():
    """Target N(0, 1), proposal N(0, 2^2) (a Student-t with huge df): the expected acceptance of
    independence MH at stationarity, E min(1, w(y) / w(x)) with x ~ p, y ~ q and w = p / q, by
    brute-force Monte Carlo here; the importance-sampling ESS fraction of N(0, 4) for N(0, 1)
    is sqrt(7) / 4 in closed form (E_q w^2 = 4 / sqrt(7))."""
    from analysis.fit.proposal import LaplaceMove, proposal_quality

    def logp(x):
        return -0.5 * (np.asarray(x)[:, 0] ** 2)

    move = LaplaceMove([0.0], [[4.0]], df=1e9, scale=1.0)
    rng = np.random.default_rng(11)
    x, y = rng.normal(size=10**6), rng.normal(scale=2.0, size=10**6)
    lw = lambda v: -0.5 * v ** 2 + v ** 2 / 8        # log p - log q up to a constant
    expected = np.mean(np.minimum(1.0, np.exp(lw(y) - lw(x))))
    chain = rng.normal(size=(4096, 1))
    acc = proposal_quality(logp, move, np.random.default_rng(12), n=4096, chain=chain,
                           chain_logp=logp(chain))
    assert abs(acc - expected) < 0.02
    ess = proposal_quality(logp, move, np.random.default_rng(13), n=20000)
    assert abs(ess - np.sqrt(7) / 4) < 0.03
    # a proposal equal to the target (the Student-t itself): every move accepted
    same = LaplaceMove([0.0], [[1.0]], df=5.0, scale=1.0)
    t = same.sample(2048, np.random.default_rng(14))
    assert proposal_quality(same.logq, same, np.random.default_rng(15), chain=t,
                            chain_logp=same.logq(t)) > 1 - 1e-12
