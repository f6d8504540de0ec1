r"""Importance sampling of a fabric: directions toward the light drawn for a given viewer.

The sampler is a mixture of components whose densities are all known in closed form, so that
:func:`pdf` is exactly the density of what :func:`sample` draws:

* a cosine-weighted hemisphere about n, share :data:`COSINE_SHARE`: density
  :math:`\max(n\cdot\omega_i, 0) / \pi`. It makes the pdf > 0 wherever f_r > 0;
* for each thread j, each distinct tangent offset alpha (the curve's sample weights), three
  lobes in the frame (t, b, n_t) of that tangent sample (MODEL.md):

  - *surface* and *volume*: the longitudinal angle
    :math:`\theta_i = \operatorname{asin}(\omega_i\cdot t)` from a Gaussian of mean
    :math:`-\theta_r` (specular longitudinal reflection) and standard deviation
    :math:`2\gamma_s` or :math:`2\gamma_v` (the lobe :math:`g(\gamma, \theta_h)`,
    :math:`\theta_h = (\theta_i + \theta_r)/2`, is a Gaussian of width :math:`2\gamma` in
    :math:`\theta_i`);
  - *isotropic* (the k_d part of the volume term): :math:`\sin\theta_i` uniform;

  and the azimuth :math:`\phi_i = \operatorname{atan2}(\omega_i\cdot b, \omega_i\cdot n_t)`
  from the density :math:`p_\phi = \max(\cos\phi, 0)/2` when ``masking`` is on (M(wi) =
  max(cos phi, 0) is a factor of f_r) and :math:`1/(2\pi)` when it is off.

Each lobe is restricted to the upper hemisphere (:mod:`brdf.horizon`): :math:`\theta_i` is
drawn from its distribution truncated to :math:`[\theta_{lo}, \theta_{hi}] = [\max(-\pi/2,
\alpha - \pi/2), \min(\pi/2, \alpha + \pi/2)]`, the angles that have some azimuth above
the horizon, then :math:`\phi_i` from :math:`p_\phi` truncated to the window
:math:`|\phi| < m(\theta_i)` above it, of mass :math:`M(\theta_i)`. No draw lands below the
surface (the untruncated lobes put up to 71% of velvet's draws there: a tilted thread
reflects part of its lobe downward), and the density above it is never less than the
untruncated lobe's, so weights only shrink.

Since :math:`d\omega = \cos\theta\, d\theta\, d\phi = d(\sin\theta)\, d\phi`, a lobe's
density in solid angle is :math:`p_\theta(\theta)\, p_\phi(\phi) / (M(\theta)\cos\theta)`
and the isotropic one's :math:`p_\phi(\phi) / (M(\theta)(\sin\theta_{hi} -
\sin\theta_{lo}))`. The integrand :math:`f_r \cos\theta_i` carries the same Gaussian and a
factor :math:`\cos^2\theta_i` in these coordinates, so the lobe weights stay bounded; the pdf
grows like :math:`1/\cos\theta` toward the thread's tangent (where the weight goes to 0) and
like :math:`1/m` where the azimuth window closes (at the horizon, where
:math:`\cos\theta_i = 0`), integrable singularities. The pdf is a density on the whole
sphere, 0 at and below the horizon, integrating to 1 over the upper hemisphere.
"""

from __future__ import annotations

import numpy as np

from brdf import horizon
from brdf.frames import as_directions, flat_pairs, normalize
from brdf.plan import plan_of
from brdf.shading import GAUSS_NORM

__all__ = ["COSINE_SHARE", "LOBE_FLOOR", "sample", "pdf", "lobe_probabilities"]

#: Probability of the cosine-weighted hemisphere component.
COSINE_SHARE = 0.25
#: Least probability of each lobe within a thread and of each thread with area > 0.
LOBE_FLOOR = 0.05
#: Longitudinal cosines are clamped below at this value in the pdf (directions within
#: 1e-12 rad of a tangent), which keeps the 1/cos(theta) density finite.
_COS_MIN = 1e-12
#: (pair, tangent sample) elements per chunk of the pdf.
_CHUNK = 1 << 15


def lobe_probabilities(fabric) -> tuple[np.ndarray, np.ndarray]:
    r"""Probabilities of the sampler's components (they do not depend on the directions).

    Parameters
    ----------
    fabric : brdf.Fabric or brdf.FabricPlan

    Returns
    -------
    thread : ndarray, shape (2,)
        Probability of choosing each thread's lobes; ``thread.sum() = 1 - COSINE_SHARE``
        (1 - COSINE_SHARE is spread over the threads with area > 0; with none, it is 0 and
        the cosine-weighted part takes all: its probability is ``1 - thread.sum()``).
    lobe : ndarray, shape (2, 3)
        Within a thread, the probabilities of the surface, volume and isotropic lobes
        (rows sum to 1).

    Notes
    -----
    A rough energy of each lobe, with :math:`F_0 = ((\eta - 1)/(\eta + 1))^2` and
    :math:`A_{max}` the largest albedo channel: surface :math:`2F_0`, volume
    :math:`2(1 - k_d)(1 - F_0)^2 A_{max}`, isotropic :math:`(\pi/2) k_d (1 - F_0)^2 A_{max}`
    (the Gaussian in theta_i has area 2; the flat part k_d weighted by cos^2 has area
    pi/2). Lobe shares are :math:`L + (1 - 3L)\, e / \sum e` with ``L = LOBE_FLOOR``; thread
    shares :math:`L + (1 - 2L)\, a_j E_j / \sum_k a_k E_k` over the threads with area > 0.

    Examples
    --------
    >>> import brdf
    >>> thread, lobe = lobe_probabilities(brdf.fabric("linen_plain"))
    >>> thread.round(3).tolist(), lobe.sum(axis=1).round(12).tolist()
    ([0.375, 0.375], [1.0, 1.0])
    """
    plan = plan_of(fabric)
    energy = np.empty((2, 3))
    for j, t in enumerate(plan.threads):
        f0 = ((t.eta - 1.0) / (t.eta + 1.0)) ** 2
        vol = (1.0 - f0) ** 2 * max(t.albedo)
        energy[j] = (2.0 * f0, 2.0 * (1.0 - t.kd) * vol, 0.5 * np.pi * t.kd * vol)
    lobe = LOBE_FLOOR + (1.0 - 3.0 * LOBE_FLOOR) * energy / energy.sum(axis=1, keepdims=True)
    area = np.array([t.area for t in plan.threads])
    e = area * energy.sum(axis=1)
    live = area > 0
    thread = np.zeros(2)
    if live.all():
        thread = LOBE_FLOOR + (1.0 - 2.0 * LOBE_FLOOR) * e / e.sum()
    elif live.any():
        thread[live] = 1.0
    return thread * (1.0 - COSINE_SHARE) if live.any() else thread, lobe


def _axes(plan):
    """In-plane tangent t0 and binormal b = n x t0 of each thread, shape (2, 3) each."""
    rot = plan.options.rotation
    c, s = np.cos(rot), np.sin(rot)
    t0 = np.array([[c, s, 0.0], [-s, c, 0.0]])
    b = np.array([[-s, c, 0.0], [-c, -s, 0.0]])
    return t0, b


def _sigmas(plan):
    """Standard deviations 2 gamma_s, 2 gamma_v of the longitudinal lobes, (2, 2) radians."""
    return np.array([[2.0 * c.gamma_s, 2.0 * c.gamma_v] for c in plan.threads])


def pdf(fabric, wo, wi) -> np.ndarray:
    r"""Density of :func:`sample`'s directions wi for the viewer wo, 1/sr (solid angle).

    Parameters
    ----------
    fabric : brdf.Fabric or brdf.FabricPlan
    wo : array_like, shape (..., 3)
        Directions toward the viewer (normalized here).
    wi : array_like, shape (..., 3)
        Directions toward the light; broadcasts with ``wo``.

    Returns
    -------
    ndarray, shape (...)
        The mixture density of the module notes (0 at and below the horizon, z <= 0); NaN
        where either vector is zero or not finite.

    Raises
    ------
    ValueError
        If the arrays lack a last axis of 3 or do not broadcast.

    Notes
    -----
    .. math::
        p(\omega_i) = c\,\frac{\max(z_i, 0)}{\pi} + [z_i > 0] \sum_j P_j \sum_\alpha
        w_\alpha \Big[\sum_{L=s,v} P_{jL}\, \frac{N_{[\theta_{lo},\theta_{hi}]}(\theta_i;
        -\theta_r, 2\gamma_L)}{\cos\theta_i} + \frac{P_{ji}}{\sin\theta_{hi} -
        \sin\theta_{lo}}\Big] \frac{p_\phi(\phi_i)}{M(\theta_i)}

    with :math:`N_{[a,b]}` the normal density truncated to [a, b] (its normaliser in
    logarithms: :func:`brdf.horizon.truncnorm_logmass`) and :math:`\theta_{lo}`,
    :math:`\theta_{hi}`, :math:`M` of each tangent offset alpha (:mod:`brdf.horizon`).

    Examples
    --------
    >>> import brdf
    >>> fab = brdf.fabric("linen_plain")
    >>> wo = brdf.directions.from_angles(np.radians(30), np.pi)
    >>> bool(pdf(fab, wo, [0.5, 0.0, 0.8660254]) > 0)
    True
    """
    plan = plan_of(fabric)
    wi, wo, shape, bad, _ = flat_pairs(wi, wo)
    out = np.empty(wi.shape[0])
    chunk = max(64, _CHUNK // plan.samples)
    for start in range(0, wi.shape[0], chunk):
        sl = slice(start, start + chunk)
        out[sl] = _pdf_flat(plan, wi[sl], wo[sl])
    out[bad] = np.nan
    return out.reshape(shape)


def _pdf_flat(plan, wi, wo):
    """The mixture density for unit (n, 3) arrays."""
    thread, lobe = lobe_probabilities(plan)
    t0, b = _axes(plan)
    sig = _sigmas(plan)
    masking = plan.options.masking
    if wo.shape[0] > 1 and np.all(wo == wo[:1]):
        wo = wo[:1]                     # one viewer (the common case): its terms once
    up = wi[:, 2] > 0.0
    total = (1.0 - thread.sum()) / np.pi * np.maximum(wi[:, 2], 0.0)
    for j, c in enumerate(plan.threads):
        if thread[j] == 0.0:
            continue
        (ti, bi, zi), (to, zo) = (wi @ t0[j], wi @ b[j], wi[:, 2]), (wo @ t0[j], wo[:, 2])
        ca, sa = c.ca[None, :], c.sa[None, :]
        si = ti[:, None] * ca + zi[:, None] * sa          # wi . t
        xi = zi[:, None] * ca - ti[:, None] * sa          # wi . n_t
        cth = np.maximum(np.sqrt(xi * xi + bi[:, None] ** 2), _COS_MIN)
        sr = to[:, None] * ca + zo[:, None] * sa
        xr = zo[:, None] * ca - to[:, None] * sa
        br = wo @ b[j]                                    # only theta_r of wo is needed
        mu = -np.arctan2(sr, np.sqrt(xr * xr + br[:, None] ** 2))
        th = np.arctan2(si, cth)
        lo, hi = horizon.theta_range(ca, sa)
        mass_phi = horizon.azimuth_mass(si, cth, ca, sa, masking)
        # p_phi / (M cos(theta)): the azimuth's density truncated to its window
        if masking:
            pphi = np.maximum(xi, 0.0) / (2.0 * cth)
        else:
            pphi = np.full_like(cth, 0.5 / np.pi)
        pphi = np.divide(pphi, mass_phi, out=np.zeros_like(pphi),
                         where=up[:, None] & (mass_phi > 0))
        dens = lobe[j, 2] / (np.sin(hi) - np.sin(lo))
        for k in range(2):
            s = sig[j, k]
            z = (th - mu) / s
            log_mass = horizon.truncnorm_logmass(mu, s, lo, hi)
            g = np.exp(-0.5 * z * z - log_mass) * (GAUSS_NORM / s)
            dens = dens + lobe[j, k] * g / cth
        total += thread[j] * ((dens * pphi) @ c.weight)
    return total


def _check_u(u, shape):
    """u as a float (..., 2) array in [0, 1) broadcasting with the leading ``shape``."""
    try:
        arr = np.asarray(u, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"u must be a numeric array of shape (..., 2); got {u!r}") from None
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise ValueError(f"u must have shape (..., 2) (two uniform numbers per sample); got "
                         f"shape {arr.shape}")
    if arr.size and not (np.all(np.isfinite(arr)) and arr.min() >= 0.0 and arr.max() < 1.0):
        raise ValueError(f"u must lie in [0, 1); got values from {np.nanmin(arr)!r} to "
                         f"{np.nanmax(arr)!r}")
    try:
        out = np.broadcast_shapes(shape, arr.shape[:-1])
    except ValueError:
        raise ValueError(f"u of shape {arr.shape} does not broadcast with wo of leading shape "
                         f"{shape}") from None
    return arr, out


def _components(plan):
    """Flat component table: cumulative probabilities and, per lobe component, its thread,
    tangent offset (cos, sin) and kind (0 surface, 1 volume, 2 isotropic). Component 0 is
    the cosine-weighted hemisphere."""
    thread, lobe = lobe_probabilities(plan)
    prob, jj, ca, sa, kind = [1.0 - thread.sum()], [0], [1.0], [0.0], [-1]
    for j, c in enumerate(plan.threads):
        if thread[j] == 0.0:
            continue
        p = thread[j] * c.weight[:, None] * lobe[j][None, :]        # (S, 3)
        prob += p.ravel().tolist()
        jj += [j] * p.size
        ca += np.repeat(c.ca, 3).tolist()
        sa += np.repeat(c.sa, 3).tolist()
        kind += [0, 1, 2] * c.ca.size
    prob = np.asarray(prob)
    cdf = np.cumsum(prob)
    cdf /= cdf[-1]
    return cdf, np.asarray(jj), np.asarray(ca), np.asarray(sa), np.asarray(kind)


def _draw(plan, wo, u0, u1):
    """Directions wi (n, 3) for unit wo (n, 3) and uniforms u0, u1 (n,)."""
    cdf, jj, ca, sa, kind = _components(plan)
    k = np.minimum(np.searchsorted(cdf, u0, side="right"), cdf.size - 1)
    start = np.where(k > 0, cdf[np.maximum(k - 1, 0)], 0.0)
    v = np.clip((u0 - start) / (cdf[k] - start), 0.0, np.nextafter(1.0, 0.0))
    j, ca, sa, kind = jj[k], ca[k], sa[k], kind[k]
    t0, b = _axes(plan)
    t0, b = t0[j], b[j]
    n = np.array([0.0, 0.0, 1.0])
    t = ca[:, None] * t0 + sa[:, None] * n
    nt = ca[:, None] * n - sa[:, None] * t0
    # longitudinal angle of wo about the chosen tangent: theta_r
    sr = np.einsum("ij,ij->i", wo, t)
    xr = np.einsum("ij,ij->i", wo, nt)
    br = np.einsum("ij,ij->i", wo, b)
    mu = -np.arctan2(sr, np.hypot(xr, br))
    sig = _sigmas(plan)[j, np.minimum(kind, 1)]
    lo, hi = horizon.theta_range(ca, sa)
    th = horizon.truncnorm_draw(mu, sig, lo, hi, v)
    s, c = np.sin(th), np.cos(th)
    iso = kind == 2                                    # sin(theta) uniform in its range
    s[iso] = np.sin(lo[iso]) + v[iso] * (np.sin(hi[iso]) - np.sin(lo[iso]))
    c[iso] = np.sqrt(np.maximum(1.0 - s[iso] ** 2, 0.0))
    m, _ = horizon.azimuth_window(s, c, ca, sa, plan.options.masking)
    phi = horizon.azimuth_draw(m, u1, plan.options.masking)
    wi = s[:, None] * t + c[:, None] * (np.cos(phi)[:, None] * nt + np.sin(phi)[:, None] * b)
    cos = kind < 0                                     # cosine-weighted hemisphere
    r = np.sqrt(v[cos])
    ph = 2.0 * np.pi * u1[cos]
    wi[cos] = np.stack([r * np.cos(ph), r * np.sin(ph), np.sqrt(1.0 - v[cos])], axis=-1)
    return wi


def sample(fabric, wo, u) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Draw directions toward the light for the viewer ``wo``.

    Parameters
    ----------
    fabric : brdf.Fabric or brdf.FabricPlan
    wo : array_like, shape (..., 3)
        Directions toward the viewer, local frame (normalized here).
    u : array_like, shape (..., 2)
        Uniform numbers in [0, 1), the caller's (a seeded generator's, or a low-discrepancy
        sequence's); the leading shapes of ``wo`` and ``u`` broadcast. The first picks the
        component and, rescaled, the longitudinal angle; the second the azimuth.

    Returns
    -------
    wi : ndarray, shape (..., 3)
        Unit directions toward the light, above the surface (z > 0).
    weight : ndarray, shape (..., 3)
        :math:`f_r(\omega_i, \omega_o) \cos\theta_i / p(\omega_i)`, RGB, dimensionless (0
        where f_r = 0).
    pdf : ndarray, shape (...)
        :math:`p(\omega_i)` in 1/sr, equal to :func:`pdf` at the returned directions.

    NaN in all three where ``wo`` is zero or not finite.

    Raises
    ------
    ValueError
        If ``wo`` is not (..., 3), ``u`` not (..., 2) in [0, 1), or they do not broadcast.

    Notes
    -----
    The component is chosen by ``u[..., 0]`` against the cumulative probabilities of
    :func:`lobe_probabilities` (and ``COSINE_SHARE``), then rescaled to [0, 1) within it to
    draw the longitudinal angle from its truncated Gaussian (:func:`brdf.horizon.truncnorm_draw`,
    inverted in logarithms with ``scipy.special.ndtri_exp``) or :math:`\sin\theta` uniform
    on its range; ``u[..., 1]`` draws the azimuth in its window
    (:func:`brdf.horizon.azimuth_draw`).

    Examples
    --------
    >>> import brdf
    >>> fab = brdf.fabric("silk_shot")
    >>> wo = brdf.directions.from_angles(np.radians(40), 0.3)
    >>> u = np.random.default_rng(1).random((1000, 2))
    >>> wi, weight, p = sample(fab, wo, u)
    >>> wi.shape, weight.shape, p.shape
    ((1000, 3), (1000, 3), (1000,))
    >>> bool(np.allclose(p, pdf(fab, wo, wi)))
    True
    """
    plan = plan_of(fabric)
    wo = as_directions("wo", wo)
    u, shape = _check_u(u, wo.shape[:-1])
    wo_f = np.broadcast_to(wo, shape + (3,)).reshape(-1, 3)
    u_f = np.broadcast_to(u, shape + (2,)).reshape(-1, 2)
    wo_f, bad = normalize(wo_f)
    wi = _draw(plan, wo_f, u_f[:, 0], u_f[:, 1])
    p = pdf(plan, wo_f, wi)
    f = plan.eval(wi, wo_f)
    zi = np.maximum(wi[:, 2], 0.0)
    weight = np.divide(f * zi[:, None], p[:, None], out=np.zeros_like(f),
                       where=(p[:, None] > 0) & (f > 0))
    wi[bad] = np.nan
    weight[bad] = np.nan
    p[bad] = np.nan
    return wi.reshape(shape + (3,)), weight.reshape(shape + (3,)), p.reshape(shape)
