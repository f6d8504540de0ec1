r"""Tangent curves: how a thread's tangent tilts out of the cloth plane along its length."""

from __future__ import annotations

import dataclasses

import numpy as np

from brdf import schema, validate
from brdf.options import MAX_TANGENT_SAMPLES, SAMPLING_METHODS, TangentSampling, validate_method

__all__ = ["TangentCurve", "SAMPLING_METHODS"]

_OFFSETS, _LENGTHS = schema.THREAD["offsets"], schema.THREAD["lengths"]

@dataclasses.dataclass(frozen=True)
class TangentCurve:
    r"""A piecewise-linear tangent-offset curve.

    Parameters
    ----------
    offsets : sequence of float
        K + 1 tangent offsets alpha_0..alpha_K (the control points), degrees, each in
        [-90, 90]; at most :data:`brdf.options.MAX_TANGENT_SAMPLES` of them (with
        ``tangent_sampling="control_points"`` each is a tangent sample).
    lengths : sequence of float
        K segment lengths l_1..l_K (>= 0, summing to > 0); arbitrary units. A zero-length
        segment is a jump.

    Raises
    ------
    ValueError
        Offsets outside [-90, 90], more than :data:`brdf.options.MAX_TANGENT_SAMPLES`
        offsets, negative lengths, lengths summing to 0, or
        ``len(offsets) != len(lengths) + 1``.

    Examples
    --------
    >>> c = TangentCurve((-25, 25), (1,))
    >>> alpha, weight = c.samples(4)
    >>> alpha.tolist(), weight.tolist()
    ([-18.75, -6.25, 6.25, 18.75], [0.25, 0.25, 0.25, 0.25])
    """

    offsets: tuple[float, ...]
    lengths: tuple[float, ...]

    def __post_init__(self):
        offsets = _floats("offsets", self.offsets)
        lengths = _floats("lengths", self.lengths)
        if len(offsets) < 1:
            raise ValueError("offsets must list at least one tangent offset (degrees); got ()")
        if len(offsets) > MAX_TANGENT_SAMPLES:
            raise ValueError(f"offsets must list at most {MAX_TANGENT_SAMPLES} tangent offsets "
                             f"(control points) per curve, the most tangent samples a curve "
                             f"takes (brdf.MAX_TANGENT_SAMPLES); got {len(offsets):,}")
        if len(offsets) != len(lengths) + 1:
            raise ValueError(f"offsets must have exactly one more entry than lengths; got "
                             f"{len(offsets)} offsets and {len(lengths)} lengths")
        for a in offsets:
            if not _OFFSETS.contains(a):
                raise ValueError(f"offsets must lie in {_OFFSETS.allowed} degrees; got {a!r} "
                                 f"in {offsets}")
        for l in lengths:
            if not _LENGTHS.contains(l):
                raise ValueError(f"lengths must be {_LENGTHS.what}; got {l!r} in {lengths}")
        if lengths and sum(lengths) <= 0.0:
            raise ValueError(f"lengths must sum to more than 0; got {lengths}")
        if not lengths and len(offsets) != 1:  # pragma: no cover - guarded above
            raise ValueError("a curve without segments has exactly one offset")
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "lengths", lengths)

    def offset_at(self, s) -> np.ndarray:
        """Offset (degrees) at arc length ``s`` (same units as ``lengths``), array_like.

        Segment k covers [c_{k-1}, c_k) of the cumulative length c; at a jump the value
        after the jump is taken, and ``s`` at the very end takes the last offset.
        """
        s = np.asarray(s, dtype=np.float64)
        alpha = np.asarray(self.offsets)
        if not self.lengths:
            return np.full(s.shape, alpha[0])
        ell = np.asarray(self.lengths)
        c = np.concatenate([[0.0], np.cumsum(ell)])
        k = np.clip(np.searchsorted(c, s, side="right"), 1, len(ell))
        lo, hi, length = alpha[k - 1], alpha[k], ell[k - 1]
        frac = np.divide(s - c[k - 1], length, out=np.ones_like(s), where=length > 0)
        frac = np.clip(frac, 0.0, 1.0)
        # lo + (hi - lo) * frac is exact for flat segments: identical offsets stay identical.
        return lo + (hi - lo) * frac

    def samples(self, n: int, method: str = "midpoint") -> tuple[np.ndarray, np.ndarray]:
        r"""Distinct tangent offsets and their weights.

        Parameters
        ----------
        n : int
            Number of samples N (``tangent_samples``), used by ``"midpoint"``: an integer in
            1..:data:`brdf.options.MAX_TANGENT_SAMPLES`.
        method : {"midpoint", "control_points"} or TangentSampling
            ``"midpoint"``: N samples at arc-length midpoints
            :math:`s_m = (m + 1/2) / N \sum l`; ``"control_points"``: the K + 1 listed offsets,
            equally weighted.

        Returns
        -------
        alpha : ndarray
            Distinct offsets, degrees, ascending.
        weight : ndarray
            Their weights (count / number of samples), summing to 1. Evaluating each distinct
            offset once with its weight equals the plain average over all samples.
        """
        method = validate_method("tangent_sampling", method, TangentSampling)
        if method is TangentSampling.CONTROL_POINTS:
            alpha = np.asarray(self.offsets)
        else:
            n = validate.integer("tangent_samples", n, lo=1, hi=MAX_TANGENT_SAMPLES)
            total = float(np.sum(self.lengths)) if self.lengths else 1.0
            s = (np.arange(n) + 0.5) / n * total
            alpha = self.offset_at(s)
        values, counts = np.unique(alpha, return_counts=True)
        return values, counts / alpha.size


def _floats(name, seq) -> tuple[float, ...]:
    try:
        return tuple(float(x) for x in np.atleast_1d(np.asarray(seq, dtype=np.float64)))
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a sequence of numbers (degrees for offsets); "
                         f"got {seq!r}") from None
