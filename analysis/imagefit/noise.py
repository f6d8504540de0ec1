"""The noise model of ``microcyl fit-images``: what a pixel's residual may be, in variance.

A pixel's residual (the image minus the render at the fabric's parameters) has the variance

    var = shot * max(render, 0) + read^2 + var_mc + floor

per channel, in the image's linear units squared, ``render`` the mean of the Monte Carlo
noise's renders (the expected value, not the noisy image: weights from the image's own values
would favour the pixels whose noise fell low, and pull the fit down):

- ``shot`` (``--shot-noise``): the camera's shot noise, variance per unit of linear value (a
  sensor of gain g electrons per unit has ``shot = 1 / g``);
- ``read`` (``--read-noise``): the camera's read noise, a standard deviation in linear units;
- ``var_mc``: the render's own Monte Carlo noise, the variance of a pixel between renders of
  independent seeds (the diagonal of :func:`mc_covariance`: ``K`` seeds, each pixel's sample
  variance pooled over its 3 x 3 neighbourhood by :func:`pool`, so ``9 (K - 1)`` degrees of
  freedom a pixel), times
  ``1 + image_mc`` when the image is itself a render (a test with the truth known) whose
  own Monte Carlo variance is ``image_mc`` times a fit render's;
- ``floor``: ``(1e-4 max|render|)^2``, so that a black pixel of a noiseless image has a
  variance.

The three channels' Monte Carlo errors of a pixel are correlated (one path carries light to
all three): the intervals use each pixel's channel covariance (:func:`mc_covariance`), not
three independent variances, and each pixel's own, not pooled: pooling spreads a highlight's
large variance over its darker neighbours, where the highlight's pixels tell the most.

The fit renders every step with one seed (common random numbers), so the render is a smooth
function of the parameters whose Monte Carlo error stays put from step to step; ``var_mc``
says how far that error may carry the render from its expectation.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

__all__ = ["NoiseModel", "mc_covariance", "pool", "FLOOR"]

#: The variance floor's share of the image's largest magnitude (as a standard deviation).
FLOOR = 1e-4


@dataclasses.dataclass(frozen=True)
class NoiseModel:
    """A camera's noise: ``shot`` (variance per linear unit) and ``read`` (sd, linear units).

    Examples
    --------
    >>> NoiseModel(shot=1e-4, read=0.002).variance(np.array([0.0, 0.1]), np.zeros(2))
    array([4.0e-06, 1.4e-05])
    >>> NoiseModel(shot=-1.0)
    Traceback (most recent call last):
    ...
    ValueError: --shot-noise -1.0: must be a finite number >= 0 (variance per linear unit)
    """

    shot: float = 0.0
    read: float = 0.0

    def __post_init__(self):
        for name, value, what in (("shot-noise", self.shot, "variance per linear unit"),
                                  ("read-noise", self.read, "sd in linear units")):
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not (math.isfinite(value) and value >= 0):
                raise ValueError(f"--{name} {value!r}: must be a finite number >= 0 ({what})")

    def variance(self, image, var_mc) -> np.ndarray:
        """The residual variance of each pixel whose expected value is ``image`` (the
        render's: module notes)."""
        image = np.asarray(image, float)
        floor = (FLOOR * float(np.max(np.abs(image), initial=0.0))) ** 2
        return self.shot * np.maximum(image, 0.0) + self.read ** 2 + var_mc + floor

    def describe(self) -> dict:
        """The model as ``results.json`` states it."""
        return {"formula": "var = shot * max(render, 0) + read^2 + var_mc + floor",
                "shot": self.shot, "read": self.read,
                "var_mc": "each pixel's variance between renders of independent seeds, "
                          "pooled over 3 x 3 pixels, times 1 + image_mc; the intervals "
                          "use its covariance between the three channels",
                "render": "the mean of the Monte Carlo noise's renders",
                "floor": f"({FLOOR:g} * max|render|)^2"}


def mc_covariance(renders, pooled: bool = True) -> np.ndarray:
    """The Monte Carlo covariance of one render's three channels, per pixel, from renders of
    independent seeds: each pixel's sample covariance (ddof 1), averaged over its 3 x 3
    neighbourhood (edges: the pixels inside) when ``pooled``. A path's light reaches all
    three channels, so their Monte Carlo errors are correlated (0.7 to 0.99 in the
    validation's cylinder): three channels of a pixel carry less than three independent
    values.

    Parameters
    ----------
    renders : sequence of (H, W, 3) arrays
        At least two renders of the same scene and fabric, independent seeds.
    pooled : bool
        Averaged over 3 x 3 pixels (steadier, for weights), or each pixel's own (unbiased
        where the variance changes from pixel to pixel, as at a highlight: for sums over
        many pixels).

    Returns
    -------
    (H, W, 3, 3) float64 ndarray

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> noise = [rng.normal(0.0, 0.1, (20, 30, 1)) * np.ones(3) for _ in range(8)]
    >>> c = mc_covariance(noise)                     # one error in every channel
    >>> c.shape, bool(abs(c[..., 0, 2].mean() - 0.01) < 0.001)
    ((20, 30, 3, 3), True)
    """
    stack = np.asarray(renders, float)
    if stack.ndim != 4 or stack.shape[-1] != 3 or len(stack) < 2:
        raise ValueError("mc_covariance: needs at least two renders of shape (H, W, 3)")
    dev = stack - stack.mean(axis=0)
    cov = np.einsum("khwc,khwd->hwcd", dev, dev) / (len(stack) - 1)
    return pool(cov) if pooled else cov


def pool(x) -> np.ndarray:
    """``x`` (H, W, ...) averaged over each pixel's 3 x 3 neighbourhood (the pixels inside)."""
    h, w = x.shape[:2]
    pad = np.pad(x, ((1, 1), (1, 1)) + ((0, 0),) * (x.ndim - 2))
    ones = np.pad(np.ones((h, w)), 1)
    total = sum(pad[i:i + h, j:j + w] for i in range(3) for j in range(3))
    count = sum(ones[i:i + h, j:j + w] for i in range(3) for j in range(3))
    return total / count.reshape((h, w) + (1,) * (x.ndim - 2))
