"""analysis.fit.ensemble: chains of emcee's stretch move advanced by the runner sample a known
Gaussian, the same seeds give the same chains, and a chain restored from its stored steps
and random state continues exactly as one never stopped (what a checkpoint relies on)."""

import emcee
import numpy as np

from analysis.fit.ensemble import Chain, EnsembleRunner

MEAN, SD = np.array([1.0, -2.0]), np.array([0.5, 2.0])


def log_prob(x):
    return -0.5 * (((np.asarray(x) - MEAN) / SD) ** 2).sum(axis=1)


def _chains(seeds, walkers=8):
    out = []
    for s in seeds:
        random = np.random.RandomState(s)
        start = MEAN + 0.1 * random.normal(size=(walkers, 2))
        out.append(Chain(emcee.moves.StretchMove(), random, start, log_prob(start)))
    return out


def test_runner_samples_the_gaussian_and_repeats_with_the_same_seeds():
    runner = EnsembleRunner(_chains([1, 2]), log_prob)
    ticks = []
    try:
        runner.run_to(1500, tick=ticks.append)
    finally:
        runner.close()
    assert runner.steps == 1500 and ticks[-1] == 1500
    samples = np.concatenate([c.chain(500).reshape(-1, 2) for c in runner.chains])
    np.testing.assert_allclose(samples.mean(axis=0), MEAN, atol=0.25 * SD.max())
    np.testing.assert_allclose(samples.std(axis=0), SD, rtol=0.15)
    c = runner.chains[0]
    np.testing.assert_allclose(c.log_prob(), log_prob(c.chain().reshape(-1, 2)).reshape(1500, 8))
    assert np.all((c.acceptance_fraction > 0.2) & (c.acceptance_fraction < 0.9))
    again = EnsembleRunner(_chains([1, 2]), log_prob)
    try:
        again.run_to(1500)
    finally:
        again.close()
    assert all(np.array_equal(a.chain(), b.chain()) for a, b in zip(runner.chains, again.chains))


def test_a_restored_chain_continues_as_if_never_stopped():
    (whole,) = _chains([5])
    whole.log_prob_fn = log_prob
    whole.run(60)
    (first,) = _chains([5])
    first.log_prob_fn = log_prob
    first.run(25)
    rest = Chain.restore(emcee.moves.StretchMove(), np.random.RandomState(0),
                         first.chain().copy(), first.log_prob().copy(), first.accepted.copy(),
                         first.rng_state)
    rest.log_prob_fn = log_prob
    rest.run(60)
    assert rest.steps == 60
    np.testing.assert_array_equal(rest.chain(), whole.chain())
    np.testing.assert_array_equal(rest.accepted, whole.accepted)
