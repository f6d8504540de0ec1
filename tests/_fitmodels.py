"""Cheap analytic stand-ins for the fabric model, for fitting tests (not a test module)."""

import numpy as np

from gonio.table import Table


def gauss(gamma_deg, x):
    g = np.radians(gamma_deg)
    return np.exp(-0.5 * (x / g) ** 2) / (g * np.sqrt(2 * np.pi))


class AnalyticModel:
    """Two crossed thread lobes: f = sum_j a_j [F(eta_j) g(gs_j, th_j) + A_j (kd_j + (1-kd_j)
    g(gv_j, th_j)) / pi], th_j = asin(h . t_j), t_1 = x, t_2 = y; F = ((eta-1)/(eta+1))^2."""

    def __init__(self, wi, wo, defaults):
        h = np.asarray(wi) + np.asarray(wo)
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        self.th = np.arcsin(np.clip(h[:, :2], -1, 1))          # (n, 2): per thread
        self.defaults = defaults
        self.calls = 0

    def __call__(self, eta=None, kd=None, gamma_s=None, gamma_v=None, area=None, albedo=None):
        self.calls += 1
        eta, kd, gs, gv, area = (np.asarray(v)[..., None, :] for v in (eta, kd, gamma_s,
                                                                       gamma_v, area))
        th = self.th
        F = ((eta - 1) / (eta + 1)) ** 2
        spec = F * gauss(gs, th)                                 # (B, n, 2)
        vol = kd + (1 - kd) * gauss(gv, th)                      # (B, n, 2)
        alb = np.asarray(albedo)[..., None, :, :]                # (B, 1, 2, 3)
        f = area[..., None] * (spec[..., None] + alb * vol[..., None] / np.pi)
        return f.sum(axis=-2)


def fabric_defaults(name="silk_crepe_de_chine"):
    if name == "silk_crepe_de_chine":
        a1, a2 = 0.12 * np.array([1.0, 0.95, 0.05]), 0.16 * np.array([1.0, 0.95, 0.05])
        th = [(1.345, a1, 0.2, 5.0, 10.0, 0.75), (1.345, a2, 0.3, 18.0, 32.0, 0.25)]
    d = {}
    for j, (eta, alb, kd, gs, gv, area) in enumerate(th, 1):
        d.update({f"eta{j}": eta, f"kd{j}": kd, f"gamma_s{j}": gs, f"gamma_v{j}": gv,
                  f"area{j}": area})
        for c, a in zip("rgb", alb):
            d[f"albedo{j}_{c}"] = float(a)
    return d


def random_pairs(n, seed):
    rng = np.random.default_rng(seed)
    def hemi(k):
        ct = rng.uniform(0.1, 1.0, k)
        ph = rng.uniform(-np.pi, np.pi, k)
        st = np.sqrt(1 - ct * ct)
        return np.stack([st * np.cos(ph), st * np.sin(ph), ct], -1)
    return hemi(n), hemi(n)


def simulated_table(model_factory, truth, n=2000, rel=0.05, seed=0, with_sigma=True):
    """Simulated noisy table: values = f (1 + rel N(0,1)), sigma = rel f (+ tiny floor)."""
    from analysis.params import ParamSpec
    wi, wo = random_pairs(n, seed)
    model = model_factory(wi, wo)
    spec = ParamSpec(["eta1"], defaults=truth)
    kw = spec.model_kwargs(spec.values(spec.start()[None]))
    f = model(**kw)[0]
    rng = np.random.default_rng(seed + 1)
    sig = rel * f + 1e-4
    vals = f + sig * rng.normal(size=f.shape)
    return Table(wi, wo, vals, sigma=sig if with_sigma else None), model


def fabric_table(name, n=400, rel=0.05, seed=0, with_sigma=True, fab=None):
    """A noisy table of a preset from brdf's own eval: values = f (1 + rel N), sigma = rel f
    + 1e-4 (1/sr); random pairs with cos(theta) in [0.1, 1]."""
    import brdf
    fab = fab or brdf.fabric(name)
    wi, wo = random_pairs(n, seed)
    f = fab.eval(wi, wo)
    sig = rel * f + 1e-4
    vals = f + sig * np.random.default_rng(seed + 1).normal(size=f.shape)
    return Table(wi, wo, vals, sigma=sig if with_sigma else None,
                 meta={"source": f"simulated {name}"}), fab
