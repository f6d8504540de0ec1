r"""How well a fit explains its table: residuals at the posterior median, and the albedo colour
of the table against the fit's (CIEDE2000, colour-science).
"""

from __future__ import annotations

import numpy as np

from analysis.likelihood import is_grey

__all__ = ["residuals", "albedo_colours", "albedo_delta_e", "fit_quality"]


def residuals(result, prediction=None) -> dict:
    """Residuals of a :class:`~analysis.fit.results.FitResult` at its posterior median.

    ``prediction`` (n, 3), the model f_r (1/sr) at the median, is computed when not given.

    Returns
    -------
    dict
        ``residual`` (n_used,): data minus model in the likelihood's space (log(1 + f_r
        cos theta_i) by default; log f_r for "relative"), ``normalized``: the same over the
        noise scale (the table's sigma propagated, with the fitted extra noise), and their root
        mean squares ``rms`` and ``rms_normalized`` (near 1 when the model explains the data to
        within its noise).
    """
    med = result.median_internal()
    lik = result.logpost.lik
    if prediction is None:
        prediction = result.logpost.predict(med[None])[0]
    r = lik.y - lik.transform(prediction[None])[0]
    s2 = np.zeros_like(r) if lik.sigma_y2 is None else lik.sigma_y2
    if "log_noise" in result.names:
        s2 = s2 + np.exp(2 * result.spec.to_natural(med)[result.names.index("log_noise")])
    z = r / np.sqrt(s2)
    return {"residual": r, "normalized": z, "rms": float(np.sqrt(np.mean(r * r))),
            "rms_normalized": float(np.sqrt(np.mean(z * z)))}


def albedo_colours(table, prediction):
    r"""Albedo colours (linear RGB) of the table and of a prediction, by the same estimator.

    rho = 2 pi mean over valid points of f_r cos(theta_o): the uniform-hemisphere Monte Carlo
    estimate of the directional albedo averaged over the table's incidences (unitless); the
    prediction (f_r in 1/sr at the table's pairs, (n, 3)) uses the same points and mask, so
    the two are comparable whatever the sampling. A grey table (R = G = B everywhere: CUReT)
    is compared with the grey of the prediction, the mean of its channels.

    Returns
    -------
    measured, predicted : ndarray (3,)

    Examples
    --------
    >>> from gonio.table import Table
    >>> t = Table([[0, 0, 1.0]], [[0, 0, 1.0]], [[0.1, 0.2, 0.3]])
    >>> m, p = albedo_colours(t, np.array([[0.1, 0.2, 0.3]]))
    >>> np.allclose(m, p), round(float(m[0]), 4)           # 2 pi 0.1
    (True, 0.6283)
    """
    prediction = np.asarray(prediction, dtype=np.float64)
    if is_grey(table.values):
        prediction = np.repeat(prediction.mean(axis=-1, keepdims=True), 3, axis=-1)
    valid = table.valid & np.isfinite(prediction)
    cos_o = np.clip(table.wo[:, 2], 0, None)[:, None]
    meas = np.where(valid, table.values, 0.0) * cos_o
    pred = np.where(valid, prediction, 0.0) * cos_o
    cnt = np.maximum(valid.sum(0), 1)
    return 2 * np.pi * meas.sum(0) / cnt, 2 * np.pi * pred.sum(0) / cnt


def albedo_delta_e(measured, predicted) -> float:
    """CIEDE2000 difference between two linear-sRGB colours (colour-science).

    Examples
    --------
    >>> albedo_delta_e([0.2, 0.2, 0.2], [0.2, 0.2, 0.2])
    0.0
    >>> albedo_delta_e([0.2, 0.1, 0.05], [0.2, 0.2, 0.2]) > 5
    True
    """
    import colour
    labs = [colour.XYZ_to_Lab(colour.sRGB_to_XYZ(np.clip(np.asarray(c, float), 0, None),
                                                 apply_cctf_decoding=False))
            for c in (measured, predicted)]
    return float(colour.delta_E(labs[0], labs[1], method="CIE 2000"))


def fit_quality(result, table) -> dict:
    """The quality figures of ``results.json``: residual rms (likelihood space and normalized),
    the number of values, and the measured and predicted albedo colours with their CIEDE2000
    difference, all at the posterior median (JSON-ready)."""
    pred = result.logpost.predict(result.median_internal()[None])[0]
    q = residuals(result, pred)
    meas, prd = albedo_colours(table, pred)
    return {"rms_residual": q["rms"], "rms_normalized": q["rms_normalized"],
            "values": int(q["residual"].size), "albedo_measured": meas.tolist(),
            "albedo_predicted": prd.tolist(), "albedo_delta_e2000": albedo_delta_e(meas, prd)}
