"""A direct, slow transliteration of MODEL.md, independent of brdf's fast kernel.

Used only by the tests as the reference: every angle is formed exactly as MODEL.md writes it
(asin, atan2, wrap), every one of the N tangent samples is evaluated separately, and the
tangent-curve rule is re-implemented from the text.
"""

import math

import numpy as np

SIGMA_U = math.radians(20.0)


def fresnel(eta, c):
    # Textbook form with Snell's law: sin_t = sin_i / eta.
    c = np.clip(c, 0.0, 1.0)
    sin_t = np.sqrt(1.0 - c * c) / eta
    cos_t = np.sqrt(1.0 - sin_t * sin_t)
    rs = (c - eta * cos_t) / (c + eta * cos_t)
    rp = (eta * c - cos_t) / (eta * c + cos_t)
    return 0.5 * (rs * rs + rp * rp)


def gauss(gamma, x):
    return np.exp(-x * x / (2 * gamma * gamma)) / (gamma * math.sqrt(2 * math.pi))


def u(x):
    return np.exp(-x * x / (2 * SIGMA_U * SIGMA_U))


def wrap(a):
    # into (-pi, pi]
    return np.pi - np.mod(np.pi - a, 2 * np.pi)


def curve_samples(offsets, lengths, n, method="midpoint"):
    if method == "control_points":
        return [math.radians(a) for a in offsets]
    total = sum(lengths)
    out = []
    for m in range(n):
        s = (m + 0.5) / n * total
        acc = 0.0
        value = offsets[-1]
        for k, l in enumerate(lengths):
            if l > 0 and s < acc + l:
                value = offsets[k] + (offsets[k + 1] - offsets[k]) * (s - acc) / l
                break
            acc += l
        out.append(math.radians(value))
    return out


def thread_sample(wi, wo, t0, alpha, th, masking, reweighting, transmission):
    """f_s M P cos(theta_i) and P for one tangent sample; wi, wo (n, 3)."""
    nrm = np.array([0.0, 0.0, 1.0])
    b = np.cross(nrm, t0)
    t = math.cos(alpha) * t0 + math.sin(alpha) * nrm
    nt = math.cos(alpha) * nrm - math.sin(alpha) * t0

    def angles(w):
        wt, wb, wn = w @ t, w @ b, w @ nt
        theta = np.arcsin(np.clip(wt, -1, 1))
        phi = np.arctan2(wb, wn)
        psi = np.arctan2(wt, wn)
        return theta, phi, psi

    ti, pi_, si = angles(wi)
    tr, pr, sr = angles(wo)
    th_h = (ti + tr) / 2
    th_d = (ti - tr) / 2
    phi_d = wrap(pi_ - pr)
    psi_d = wrap(si - sr)
    cos_g = np.cos(th_d) * np.cos(phi_d / 2)
    eta = th.eta
    fr = fresnel(eta, cos_g)
    if transmission == "half_angle":
        ft = (1 - fr) ** 2
    else:
        ft = (1 - fresnel(eta, np.cos(ti))) * (1 - fresnel(eta, np.cos(tr)))
    gs, gv = math.radians(th.gamma_s), math.radians(th.gamma_v)
    f_rs = fr * np.cos(phi_d / 2) * gauss(gs, th_h)
    A = np.asarray(th.albedo)
    f_rv = (ft * ((1 - th.kd) * gauss(gv, th_h) + th.kd) / (np.cos(ti) + np.cos(tr)))[:, None] * A
    f_s = (f_rs[:, None] + f_rv) / (np.cos(th_d) ** 2)[:, None]
    if masking:
        mi, mo = np.maximum(np.cos(pi_), 0), np.maximum(np.cos(pr), 0)
        M = (1 - u(phi_d)) * mi * mo + u(phi_d) * np.minimum(mi, mo)
    else:
        M = np.ones(len(wi))
    if reweighting:
        p_i, p_o = np.maximum(np.cos(si), 0), np.maximum(np.cos(sr), 0)
        P = (1 - u(psi_d)) * p_i * p_o + u(psi_d) * np.minimum(p_i, p_o)
    else:
        P = np.ones(len(wi))
    return f_s * (M * P * np.cos(ti))[:, None], P


def reference_threads(fabric, wi, wo):
    """Each thread's share a_j S_j / (Q n.wi), shape (n, 2, 3), by MODEL.md.

    ``fabric`` supplies parameters and options only (a brdf.Fabric); wi, wo are unit (n, 3)
    directions above the horizon.
    """
    opts = fabric.options
    wi = np.atleast_2d(np.asarray(wi, float))
    wo = np.atleast_2d(np.asarray(wo, float))
    rho = opts["rotation"]
    t0s = [np.array([math.cos(rho), math.sin(rho), 0.0]),
           np.array([math.cos(rho + math.pi / 2), math.sin(rho + math.pi / 2), 0.0])]
    parts = []
    Q = np.zeros(len(wi))
    for th, t0 in zip(fabric.threads, t0s):
        alphas = curve_samples(th.offsets, th.lengths, opts["tangent_samples"],
                               opts["tangent_sampling"])
        S = np.zeros((len(wi), 3))
        Pm = np.zeros(len(wi))
        for a in alphas:
            s, P = thread_sample(wi, wo, t0, a, th, opts["masking"], opts["reweighting"],
                                 opts["transmission"])
            S += s / len(alphas)
            Pm += P / len(alphas)
        parts.append(th.area * S)
        Q += th.area * Pm
    a1, a2 = fabric.threads[0].area, fabric.threads[1].area
    gap = wi[:, 2] if opts["gap"] == "incident" else wo[:, 2]
    Q += (1 - a1 - a2) * gap
    if not opts["reweighting"]:
        Q = np.ones(len(wi))
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.stack(parts, axis=1) / (Q * wi[:, 2])[:, None, None]
    out[Q == 0] = 0
    return out


def reference_eval(fabric, wi, wo):
    """f_r (n, 3) of a brdf.Fabric by MODEL.md, for unit (n, 3) wi, wo above the horizon."""
    return reference_threads(fabric, wi, wo).sum(axis=1)


class ReferenceFabric:
    """A BRDF object (``eval``, ``eval_threads``) backed by this transliteration.

    Directions may have any leading shape; entries below the horizon give 0.
    """

    def __init__(self, fabric):
        self.fabric = fabric
        self.threads = fabric.threads
        self.options = fabric.options

    def eval_threads(self, wi, wo):
        wi, wo = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        shape = wi.shape[:-1]
        wi = wi.reshape(-1, 3) / np.linalg.norm(wi.reshape(-1, 3), axis=-1, keepdims=True)
        wo = wo.reshape(-1, 3) / np.linalg.norm(wo.reshape(-1, 3), axis=-1, keepdims=True)
        up = (wi[:, 2] > 0) & (wo[:, 2] > 0)
        out = np.zeros((len(wi), 2, 3))
        if up.any():
            out[up] = reference_threads(self.fabric, wi[up], wo[up])
        return out.reshape(shape + (2, 3))

    def eval(self, wi, wo):
        return self.eval_threads(wi, wo).sum(axis=-2)


def random_pairs(n, rng):
    """Random unit directions in the upper hemisphere (uniform in solid angle)."""
    def hemi(k):
        z = rng.uniform(1e-3, 1, k)
        p = rng.uniform(-np.pi, np.pi, k)
        r = np.sqrt(1 - z * z)
        return np.stack([r * np.cos(p), r * np.sin(p), z], -1)
    return hemi(n), hemi(n)
