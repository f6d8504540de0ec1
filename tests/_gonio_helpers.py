"""Small analytic BRDFs and tables for the gonio format tests."""

import numpy as np

import gonio


class Lambert:
    """f_r = albedo / pi, RGB."""

    def __init__(self, albedo=(0.5, 0.4, 0.3)):
        self.albedo = np.asarray(albedo, float)

    def eval(self, wi, wo):
        wi, wo = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
        return np.where(up[..., None], self.albedo / np.pi, 0.0)


class Glossy:
    """Lambert + a broad normalized Blinn-Phong half-vector lobe; smooth and isotropic."""

    def __init__(self, n=8.0, ks=(0.3, 0.3, 0.3), kd=(0.4, 0.2, 0.1)):
        self.n, self.ks, self.kd = n, np.asarray(ks, float), np.asarray(kd, float)

    def eval(self, wi, wo):
        wi, wo = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        h = wi + wo
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        lobe = (self.n + 2) / (2 * np.pi) * np.clip(h[..., 2], 0, 1) ** self.n
        up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
        return np.where(up[..., None], self.kd / np.pi + self.ks * lobe[..., None] / 4, 0.0)


def random_dirs(rng, n):
    theta = np.arccos(rng.uniform(0.05, 1.0, n))
    phi = rng.uniform(-np.pi, np.pi, n)
    return gonio.exr.from_angles(theta, phi)


def random_table(seed=0, n=50, sigma=True, grey=False):
    rng = np.random.default_rng(seed)
    values = rng.lognormal(-2, 1, (n, 1 if grey else 3))
    values = np.repeat(values, 3, axis=1) if grey else values
    values[3, slice(None) if grey else 1] = np.nan
    values[7, slice(None) if grey else 0] = -0.5
    sig = 0.1 * values if sigma else None
    if sig is not None:
        sig[3, 1] = 0.01
        sig[7, 0] = 0.01
    return gonio.Table(random_dirs(rng, n), random_dirs(rng, n), values, sig,
                       {"source": "test", "seed": seed, "instrument": {"snr": 50.0}})
