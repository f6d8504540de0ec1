"""A direct, slow-but-simple transliteration of MODEL.md, for the analysis tests only.

It is independent of the ``brdf`` package (written from the specification alone) and
exposes the same ``eval`` / ``eval_threads`` / ``threads`` / ``options`` shape that the
analysis code needs, so the quadratures can be checked against an independent model.
Only the default variants plus ``gap`` and ``transmission`` are implemented.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

SIGMA_U = math.radians(20.0)


def fresnel(eta, c):
    c = np.clip(c, 0.0, 1.0)
    s2t = (1.0 - c * c) / (eta * eta)
    ct = np.sqrt(np.clip(1.0 - s2t, 0.0, None))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return np.where(s2t >= 1.0, 1.0, 0.5 * (rs * rs + rp * rp))


def g(gamma, x):
    return np.exp(-x * x / (2 * gamma * gamma)) / (gamma * math.sqrt(2 * math.pi))


def u(x):
    return np.exp(-x * x / (2 * SIGMA_U * SIGMA_U))


def wrap(x):
    return np.pi - np.mod(np.pi - x, 2 * np.pi)


def tangent_samples(offsets, lengths, n):
    offsets = np.asarray(offsets, float)
    lengths = np.asarray(lengths, float)
    total = lengths.sum()
    s = (np.arange(n) + 0.5) / n * total
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    out = np.empty(n)
    for m, sm in enumerate(s):
        k = np.searchsorted(cum, sm, side="right") - 1
        k = min(max(k, 0), len(lengths) - 1)
        while lengths[k] == 0:
            k += 1
        t = (sm - cum[k]) / lengths[k]
        out[m] = offsets[k] + t * (offsets[k + 1] - offsets[k])
    return np.radians(out)


@dataclasses.dataclass(frozen=True)
class Thread:
    eta: float
    albedo: tuple
    kd: float
    gamma_s: float
    gamma_v: float
    area: float
    offsets: tuple
    lengths: tuple


PRESETS = {
    "linen_plain": (
        Thread(1.46, tuple(0.3 * np.array([0.2, 0.8, 1.0])), 0.3, 12, 24, 0.33, (-25, 25), (1,)),
        Thread(1.46, tuple(0.3 * np.array([0.2, 0.8, 1.0])), 0.3, 12, 24, 0.33, (-25, 25), (1,))),
    "polyester_satin_charmeuse": (
        Thread(1.539, tuple(0.035 * np.array([1.0, 0.37, 0.3])), 0.1, 2.5, 5, 0.9,
               (-32, -32, -18, 0, 0, 18, 32, 32), (1.33, 0.66, 2, 2, 2, 0.66, 1.33)),
        Thread(1.539, tuple(0.2 * np.array([1.0, 0.37, 0.3])), 0.7, 30, 60, 0.1, (0, 0), (1,))),
}


class RefFabric:
    """The microcylinder model from MODEL.md (defaults: masking, reweighting on)."""

    def __init__(self, threads, n_samples=32, gap="incident", transmission="half_angle"):
        self.threads = tuple(threads)
        self.n_samples = n_samples
        self.options = {"rotation": 0.0, "gap": gap, "transmission": transmission}
        self._alpha = [tangent_samples(t.offsets, t.lengths, n_samples) for t in self.threads]

    def _thread(self, j, wi, wo):
        th = self.threads[j]
        t0 = np.array([1.0, 0, 0]) if j == 0 else np.array([0, 1.0, 0])
        nz = np.array([0, 0, 1.0])
        b = np.cross(nz, t0)
        a = self._alpha[j]
        t = np.cos(a)[:, None] * t0 + np.sin(a)[:, None] * nz      # (N, 3)
        nt = np.cos(a)[:, None] * nz - np.sin(a)[:, None] * t0
        def ang(w):
            wt = np.einsum("...k,nk->...n", w, t)
            wn = np.einsum("...k,nk->...n", w, nt)
            wb = (w @ b)[..., None]
            theta = np.arcsin(np.clip(wt, -1, 1))
            return theta, np.arctan2(wb, wn), np.arctan2(wt, wn)
        ti, pi_, si = ang(wi)
        tr, pr, sr = ang(wo)
        th_h, th_d = 0.5 * (ti + tr), 0.5 * (ti - tr)
        phd, psd = wrap(pi_ - pr), wrap(si - sr)
        cg = np.cos(th_d) * np.cos(phd / 2)
        gs, gv = math.radians(th.gamma_s), math.radians(th.gamma_v)
        F = fresnel(th.eta, cg)
        frs = F * np.cos(phd / 2) * g(gs, th_h)
        if self.options["transmission"] == "half_angle":
            FT = (1 - F) ** 2
        else:
            FT = (1 - fresnel(th.eta, np.cos(ti))) * (1 - fresnel(th.eta, np.cos(tr)))
        denom = np.cos(ti) + np.cos(tr)
        vol = FT * ((1 - th.kd) * g(gv, th_h) + th.kd) / np.where(denom > 0, denom, np.inf)
        frv = vol[..., None] * np.asarray(th.albedo)
        fs = (frs[..., None] + frv) / (np.cos(th_d) ** 2)[..., None]
        Mi, Mo = np.maximum(np.cos(pi_), 0), np.maximum(np.cos(pr), 0)
        M = (1 - u(phd)) * Mi * Mo + u(phd) * np.minimum(Mi, Mo)
        Pi, Po = np.maximum(np.cos(si), 0), np.maximum(np.cos(sr), 0)
        P = (1 - u(psd)) * Pi * Po + u(psd) * np.minimum(Pi, Po)
        S = (fs * (M * P * np.cos(ti))[..., None]).mean(axis=-2)
        return S, P.mean(axis=-1)

    def eval_threads(self, wi, wo):
        wi, wo = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        S1, P1 = self._thread(0, wi, wo)
        S2, P2 = self._thread(1, wi, wo)
        a1, a2 = self.threads[0].area, self.threads[1].area
        ci, co = wi[..., 2], wo[..., 2]
        cgap = ci if self.options["gap"] == "incident" else co
        Q = a1 * P1 + a2 * P2 + (1 - a1 - a2) * cgap
        up = (ci > 0) & (co > 0) & (Q > 0)
        den = np.where(up, Q * ci, 1.0)
        out = np.stack([a1 * S1, a2 * S2], axis=-2) / den[..., None, None]
        return np.where(up[..., None, None], out, 0.0)

    def eval(self, wi, wo):
        return self.eval_threads(wi, wo).sum(axis=-2)
