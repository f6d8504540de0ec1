r"""Angles that repeat: circular summaries of a parameter whose range holds a whole period.

A fabric whose threads' tangent curves are symmetric is unchanged by a half turn
(:meth:`brdf.Fabric.periods`), so its ``rotation`` on [-90, 90] degrees is a circle: draws
piled at -89 and at +89 are one mode across the wrap, not two modes at two bounds. For such a
parameter (:meth:`analysis.params.ParamSpec.period`: its period, when its range holds a whole
one), the draws are unwrapped around their circular mean (the direction of the mean of
exp(2 pi i x / period)) before anything is summarized: the median, the 68% and 95% intervals,
the sd, the correlations and the plots see one continuous mode. All draws are then shifted by
the whole periods that bring the median into [lo, lo + period); the intervals go with it, so
that an interval about a mode at the wrap may cross a bound by less than half a period
(draws of N(-89.4, 1) degrees held in [-90, 90], 28% of them at the +90 end: median -89.42,
95% interval [-91.34, -87.43], where the plain percentiles give -88.64 [-89.93, 89.93]), and
no bound is reported reached.

Examples
--------
>>> x = np.array([-89.0, -88.5, 88.0, 89.5])     # one mode, across the wrap at +-90
>>> y = unwrap(x, 180.0, -90.0)
>>> y.tolist(), float(np.median(y)), float(np.median(x))   # the plain median is far off
([-89.0, -88.5, -92.0, -90.5], -89.75, -0.25)
"""

from __future__ import annotations

import numpy as np

__all__ = ["unwrap", "circular_natural"]


def unwrap(x, period: float, lo: float) -> np.ndarray:
    """Draws ``x`` of an angle repeating every ``period`` made continuous about their circular
    mean, shifted by whole periods so that their median lies in [lo, lo + period).

    Parameters
    ----------
    x : array_like
        Draws (any shape), natural units.
    period : float
        The period (> 0), the same units.
    lo : float
        The lower bound of the parameter's range.

    Returns
    -------
    ndarray
        Same shape; each value differs from its draw by a whole number of periods.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0:
        return x.copy()
    z = np.mean(np.exp(2j * np.pi * x / period))
    mu = float(np.angle(z)) * period / (2.0 * np.pi) if abs(z) > 1e-12 else lo + period / 2
    y = mu + np.mod(x - mu + period / 2, period) - period / 2
    med = float(np.median(y))
    return y + (lo + np.mod(med - lo, period) - med)


def circular_natural(spec, internal) -> np.ndarray:
    """The natural values of internal draws (..., ndim) of ``spec``'s free parameters, every
    circular one (``spec.period(name)`` not None) unwrapped over all its draws
    (:func:`unwrap`); the other columns as ``spec.to_natural`` gives them."""
    out = spec.to_natural(internal)
    for i, name in enumerate(spec.free):
        period = spec.period(name)
        if period is not None:
            out[..., i] = unwrap(out[..., i], period, spec.params[name].lo)
    return out
