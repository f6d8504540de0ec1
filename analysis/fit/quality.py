r"""How well a fit explains its table: residuals at the posterior median, and the albedo colour
of the table against the fit's (CIEDE2000, colour-science; :func:`albedo_colours` and
:func:`albedo_delta_e` live in :mod:`analysis.colour` and are re-exported here). A grey table
(the same value in R, G and B at every point: CUReT, a one-column CSV) has no colour: its
colour difference is None, with the reason. :func:`start_colour_difference` measures the same
difference before a fit, at its start, in hue and chroma alone. Whether the model describes
the data at all is
:mod:`analysis.fit.adequacy`.
"""

from __future__ import annotations

import numpy as np

from analysis.colour import albedo_colours, albedo_delta_e, luminance
from analysis.likelihood import is_grey

__all__ = ["residuals", "albedo_colours", "albedo_delta_e", "fit_quality",
           "start_colour_difference"]


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


def fit_quality(result, table) -> dict:
    """The quality figures of ``results.json``: residual rms (likelihood space and normalized),
    the number of values, and the measured and predicted albedo colours with their CIEDE2000
    difference, all at the posterior median (JSON-ready).

    For a grey table ``albedo_delta_e2000`` is None and ``albedo_delta_e2000_reason`` says
    why: its one channel holds no colour, and a CIEDE2000 of two greys would be their
    lightness difference alone (the albedos themselves are still given).
    """
    pred = result.logpost.predict(result.median_internal()[None])[0]
    q = residuals(result, pred)
    meas, prd = albedo_colours(table, pred)
    out = {"rms_residual": q["rms"], "rms_normalized": q["rms_normalized"],
           "values": int(q["residual"].size), "albedo_measured": meas.tolist(),
           "albedo_predicted": prd.tolist()}
    if is_grey(table.values):
        out.update(albedo_delta_e2000=None, albedo_delta_e2000_reason=(
            "grey table (the same value in R, G and B at every point): no colour to compare"))
    else:
        out["albedo_delta_e2000"] = albedo_delta_e(meas, prd)
    return out


def start_colour_difference(table, spec, model) -> float:
    """CIEDE2000 (unitless) between ``table``'s mean albedo colour and that of ``spec``'s start
    (an :class:`analysis.params.ParamSpec`; ``model`` its forward model at the table's pairs)
    (:func:`albedo_colours`), the start's colour scaled to the table's
    luminance (only hue and chroma count); 0 for a grey table.

    Examples
    --------
    >>> import brdf
    >>> from analysis.fit import FabricModel
    >>> from analysis.params import defaults_from_fabric
    >>> from gonio import measure, Instrument
    >>> linen = brdf.fabric("linen_plain")
    >>> warm = linen.with_values({f"albedo{j}_{c}": a for j in (1, 2)
    ...                           for c, a in zip("rgb", (0.8, 0.45, 0.2))})
    >>> t = measure(warm, "full:30:60", Instrument(snr=50), seed=1, progress=False)
    >>> from analysis.params import ParamSpec
    >>> spec = ParamSpec("kd1", defaults=defaults_from_fabric(linen))
    >>> start_colour_difference(t, spec, FabricModel(linen, t.wi, t.wo)) > 10
    True
    """
    if is_grey(np.asarray(table.values, dtype=np.float64)):
        return 0.0
    values = spec.values(spec.start()[None])
    pred = np.asarray(model(**spec.model_kwargs(values)))[0]
    measured, predicted = albedo_colours(table, pred)
    lum = float(luminance(predicted))
    if not lum > 0:
        return float("inf")
    return float(albedo_delta_e(measured, predicted * float(luminance(measured)) / lum))
