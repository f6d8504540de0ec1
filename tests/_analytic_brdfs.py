"""Small analytic BRDFs with known albedo or known symmetry, for the analysis tests."""

import numpy as np


def _up(wi, wo):
    wi, wo = np.asarray(wi, float), np.asarray(wo, float)
    return (wi[..., 2] > 0) & (wo[..., 2] > 0)


class Lambert:
    """f = rho / pi: albedo rho for every direction, reciprocal."""

    def __init__(self, rho=(0.2, 0.5, 0.8)):
        self.rho = np.asarray(rho, float)

    def eval(self, wi, wo):
        return np.where(_up(wi, wo)[..., None], self.rho / np.pi, 0.0)


class SeparableLobe:
    """f = k (n + 2) / (2 pi) cos^n(theta_i) cos^n(theta_o), reciprocal.

    Since the integral of cos^(n+1) over the hemisphere is 2 pi / (n + 2), the albedo is
    integral of f cos(theta_i) dwi = k cos^n(theta_o).
    """

    def __init__(self, n=20, k=(0.9, 0.6, 0.3)):
        self.n, self.k = n, np.asarray(k, float)

    def eval(self, wi, wo):
        wi, wo = np.asarray(wi, float), np.asarray(wo, float)
        ci, co = np.clip(wi[..., 2], 0, None), np.clip(wo[..., 2], 0, None)
        f = (self.n + 2) / (2 * np.pi) * ci ** self.n * co ** self.n
        return np.where(_up(wi, wo), f, 0.0)[..., None] * self.k

    def albedo(self, theta_o):
        return np.cos(theta_o)[..., None] ** self.n * self.k


class Phong:
    """Normalized Phong lobe about the mirror direction: ks (n + 2) / (2 pi) cos^n(alpha).

    At wo = n its albedo is exactly ks (the lobe about the normal lies in the hemisphere).
    """

    def __init__(self, n=50, ks=0.7):
        self.n, self.ks = n, ks

    def eval(self, wi, wo):
        wi, wo = np.asarray(wi, float), np.asarray(wo, float)
        r = wo * np.array([-1.0, -1.0, 1.0])
        c = np.clip(np.sum(wi * r, axis=-1), 0, None)
        f = self.ks * (self.n + 2) / (2 * np.pi) * c ** self.n
        return np.where(_up(wi, wo), f, 0.0)[..., None] * np.ones(3)


class BlinnPhong:
    """Symmetric Blinn-Phong: k (n + 8) / (8 pi) (n . h)^n, reciprocal by construction."""

    def __init__(self, n=30, k=(0.5, 0.4, 0.3)):
        self.n, self.k = n, np.asarray(k, float)

    def eval(self, wi, wo):
        wi, wo = np.asarray(wi, float), np.asarray(wo, float)
        h = wi + wo
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        f = (self.n + 8) / (8 * np.pi) * np.clip(h[..., 2], 0, None) ** self.n
        return np.where(_up(wi, wo), f, 0.0)[..., None] * self.k


class ViewCosine:
    """f = c cos(theta_o): not reciprocal; r = |cos_o - cos_i| / max(cos_o, cos_i)."""

    def eval(self, wi, wo):
        wi, wo = np.asarray(wi, float), np.asarray(wo, float)
        return np.where(_up(wi, wo), 0.3 * wo[..., 2], 0.0)[..., None] * np.ones(3)


class TwoLambertThreads:
    """A fake fabric: two Lambertian 'thread shares' c_1/pi and c_2/pi via eval_threads."""

    threads = (None, None)
    options = {"rotation": 0.3}

    def __init__(self, c1=0.25, c2=0.5):
        self.c = np.array([c1, c2])

    def eval_threads(self, wi, wo):
        up = _up(wi, wo)
        out = np.where(up[..., None, None], (self.c / np.pi)[:, None] * np.ones(3), 0.0)
        return out

    def eval(self, wi, wo):
        return self.eval_threads(wi, wo).sum(axis=-2)
