"""A chi-square goodness-of-fit test of a direction sampler against its pdf, as pbrt-v4
(src/pbrt/util/tests, ``Chi2Test``) and Mitsuba 3 (``mitsuba.chi2.ChiSquareTest``) check
theirs: a histogram of samples over a (cos theta, phi) grid of the whole sphere against the
pdf integrated over each cell, cells of fewer than 5 expected counts pooled, the p-value from
scipy.stats.chi2.sf, to be compared with a significance corrected for the number of tests."""

from __future__ import annotations

import numpy as np
from scipy import stats

#: Cells of the grid: along cos(theta) in [-1, 1] and along phi in [-pi, pi).
N_COS, N_PHI = 16, 32


def sidak(alpha: float, n_tests: int) -> float:
    """Per-test significance giving a family-wise error rate ``alpha`` over ``n_tests``."""
    return 1.0 - (1.0 - alpha) ** (1.0 / n_tests)


def _gl_rects(pdf, rects, order):
    """Gauss-Legendre integrals (order x order) of pdf over rectangles (k, 4) of
    (theta0, theta1, phi0, phi1), dw = sin(theta) dtheta dphi (polar angle theta from +z:
    the factor sin(theta) cancels a 1/sin(theta) peak of the pdf at the poles +-z)."""
    x, wx = np.polynomial.legendre.leggauss(order)
    ht = 0.5 * (rects[:, 1] - rects[:, 0])
    hp = 0.5 * (rects[:, 3] - rects[:, 2])
    th = (0.5 * (rects[:, 1] + rects[:, 0]))[:, None] + ht[:, None] * x      # (k, order)
    ph = (0.5 * (rects[:, 3] + rects[:, 2]))[:, None] + hp[:, None] * x
    T = np.broadcast_to(th[:, :, None], (len(rects), order, order))
    P = np.broadcast_to(ph[:, None, :], T.shape)
    s = np.sin(T)
    w = np.stack([s * np.cos(P), s * np.sin(P), np.cos(T)], axis=-1).reshape(-1, 3)
    f = np.asarray(pdf(w)).reshape(T.shape) * s
    return np.einsum("kij,i,j->k", f, wx, wx) * ht * hp


def _children(rects):
    c0, c1, p0, p1 = rects.T
    cm, pm = 0.5 * (c0 + c1), 0.5 * (p0 + p1)
    kids = [(c0, cm, p0, pm), (c0, cm, pm, p1), (cm, c1, p0, pm), (cm, c1, pm, p1)]
    return np.stack([np.stack(k, axis=-1) for k in kids], axis=1)           # (k, 4, 4)


def cell_integrals(pdf, n_cos=N_COS, n_phi=N_PHI, order=5, tol=2e-6, max_depth=10):
    """Integral of ``pdf(w)`` (w of shape (m, 3), density per steradian) over each cell of
    the (cos theta, phi) grid: array (n_cos, n_phi).

    Each cell is integrated in (theta, phi). Adaptive: a rectangle's order x order Gauss-Legendre value is compared with the sum over
    its four quarters; where they differ by more than ``tol`` (absolute) the quarters are
    refined in turn (at most ``max_depth`` times), so the integrable
    1/cos(theta) peaks of the pdf at thread tangents are resolved.
    """
    ce = np.arccos(np.linspace(1.0, -1.0, n_cos + 1))[::-1]     # theta edges, cos ascending
    pe = np.linspace(-np.pi, np.pi, n_phi + 1)
    C0, P0 = np.meshgrid(ce[1:], pe[:-1], indexing="ij")
    C1, P1 = np.meshgrid(ce[:-1], pe[1:], indexing="ij")
    rects = np.stack([C0.ravel(), C1.ravel(), P0.ravel(), P1.ravel()], axis=-1)
    owner = np.arange(rects.shape[0])
    out = np.zeros(rects.shape[0])
    coarse = _gl_rects(pdf, rects, order)
    for depth in range(max_depth + 1):
        kids = _children(rects)
        fine_k = _gl_rects(pdf, kids.reshape(-1, 4), order).reshape(-1, 4)
        fine = fine_k.sum(axis=1)
        done = (np.abs(fine - coarse) <= tol) | (depth == max_depth)
        np.add.at(out, owner[done], fine[done])
        rects = kids[~done].reshape(-1, 4)
        coarse = fine_k[~done].ravel()
        owner = np.repeat(owner[~done], 4)
        if rects.size == 0:
            break
    return out.reshape(n_cos, n_phi)


def histogram(wi, n_cos=N_COS, n_phi=N_PHI):
    """Counts of unit directions (m, 3) over the same cells: array (n_cos, n_phi)."""
    ic = np.clip(((wi[:, 2] + 1.0) * 0.5 * n_cos).astype(int), 0, n_cos - 1)
    phi = np.arctan2(wi[:, 1], wi[:, 0])
    ip = np.clip(((phi + np.pi) / (2 * np.pi) * n_phi).astype(int), 0, n_phi - 1)
    return np.bincount(ic * n_phi + ip, minlength=n_cos * n_phi).reshape(n_cos, n_phi)


def chi2_pvalue(observed, expected, min_expected=5.0):
    """Chi-square statistic, degrees of freedom and p-value of counts against expected counts.

    Cells are sorted by expected count; those below ``min_expected`` are pooled (in that
    order) until a pool reaches it, the last pool joining the smallest full cell, as pbrt-v4
    does. A cell with no expected count but observed samples gives p = 0.
    """
    obs = np.asarray(observed, float).ravel()
    exp = np.asarray(expected, float).ravel()
    if np.any((exp <= 0) & (obs > 0)):
        return np.inf, 0, 0.0
    order = np.argsort(exp)
    obs, exp = obs[order], exp[order]
    cells_o, cells_e, po, pe = [], [], 0.0, 0.0
    for o, e in zip(obs, exp):
        if e >= min_expected and pe == 0.0:
            cells_o.append(o)
            cells_e.append(e)
            continue
        po, pe = po + o, pe + e
        if pe >= min_expected:
            cells_o.append(po)
            cells_e.append(pe)
            po = pe = 0.0
    if pe > 0.0:
        if cells_e:
            cells_o[0] += po
            cells_e[0] += pe
        else:
            cells_o, cells_e = [po], [pe]
    o, e = np.array(cells_o), np.array(cells_e)
    stat = float(np.sum((o - e) ** 2 / e))
    dof = o.size - 1
    return stat, dof, float(stats.chi2.sf(stat, dof)) if dof > 0 else 1.0
