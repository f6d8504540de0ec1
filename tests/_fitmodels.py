"""Simulated tables for the fitting tests (a helper module, not a test module)."""

import numpy as np

from gonio.table import Table


def random_pairs(n, seed):
    """n random (wi, wo) pairs with cos(theta) uniform in [0.1, 1] and uniform azimuths."""
    rng = np.random.default_rng(seed)

    def hemi(k):
        ct = rng.uniform(0.1, 1.0, k)
        ph = rng.uniform(-np.pi, np.pi, k)
        st = np.sqrt(1 - ct * ct)
        return np.stack([st * np.cos(ph), st * np.sin(ph), ct], -1)
    return hemi(n), hemi(n)


def fabric_table(name, n=400, rel=0.05, seed=0, with_sigma=True, fab=None):
    """A noisy table of a preset from brdf's own eval: values = f + sigma N(0, 1) with
    sigma = rel f + 1e-4 (1/sr), at ``random_pairs(n, seed)``."""
    import brdf
    fab = fab or brdf.fabric(name)
    wi, wo = random_pairs(n, seed)
    f = fab.eval(wi, wo)
    sig = rel * f + 1e-4
    vals = f + sig * np.random.default_rng(seed + 1).normal(size=f.shape)
    return Table(wi, wo, vals, sigma=sig if with_sigma else None,
                 meta={"source": f"simulated {name}"}), fab
