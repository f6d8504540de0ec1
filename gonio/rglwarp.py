"""The tabulated functions of an RGL tensor file as Mitsuba 3 evaluates them: the
coordinates of its parameterization (Mitsuba's stable ``elevation``, the maps of theta and
phi to the unit square) and its 2-D functions over the unit square, sliced by parameters and
interpolated between slices (Mitsuba's ``Marginal2D``: bilinear values and the inverse of
the continuous marginal-conditional warp), which :class:`gonio.rgl.RGLBRDF` evaluates."""

from __future__ import annotations

import numpy as np

__all__ = ["Conditional", "param_weights", "elevation", "theta2u", "phi2u", "mulsign_neg"]


def elevation(d):
    """Polar angle of unit vectors, computed as Mitsuba does (stable near the pole)."""
    dist = np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2 + (d[..., 2] - 1.0) ** 2)
    return 2.0 * np.arcsin(np.clip(0.5 * dist, -1.0, 1.0))


def theta2u(theta):
    """A polar angle (radians) as the first coordinate of the unit square, sqrt(2 theta / pi).

    Examples
    --------
    >>> float(theta2u(np.pi / 2)), float(theta2u(np.pi / 8))
    (1.0, 0.5)
    """
    return np.sqrt(np.maximum(theta, 0.0) * (2.0 / np.pi))


def phi2u(phi):
    """An azimuth (radians) as the second coordinate of the unit square, (phi + pi) / 2 pi."""
    return (phi + np.pi) / (2.0 * np.pi)


def mulsign_neg(x, s):
    """x * -sign(s), with the sign taken from the sign bit (as drjit.mulsign_neg)."""
    return np.where(np.signbit(s), x, -x)


def param_weights(values: np.ndarray, param: np.ndarray):
    """Slice index and linear weight along one parameter axis (Mitsuba's Distribution2D).

    Examples
    --------
    >>> idx, w = param_weights(np.array([0.0, 1.0, 3.0]), np.array([0.5, 2.0, 9.0]))
    >>> idx.tolist(), w.tolist()
    ([0, 1, 1], [0.5, 0.5, 1.0])
    """
    n = values.shape[0]
    if n == 1:
        return np.zeros(param.shape, np.intp), np.zeros(param.shape)
    idx = np.clip(np.searchsorted(values, param, side="left") - 1, 0, n - 2)
    p0, p1 = values[idx], values[idx + 1]
    return idx, np.clip((param - p0) / (p1 - p0), 0.0, 1.0)


class Conditional:
    """Slices of a 2-D function over the unit square indexed by parameters (phi_i, theta_i[, c]).

    ``data`` has shape (P..., ny, nx); parameters are interpolated linearly between slices,
    exactly as Mitsuba's ``Marginal2D`` does (the interpolated quantity is the slice data,
    and, for the continuous warp, its CDFs).
    """

    def __init__(self, data: np.ndarray, params: list[np.ndarray], warp: bool):
        self.params = [np.asarray(p, np.float64) for p in params]
        data = np.asarray(data, np.float64)
        self.ny, self.nx = data.shape[-2:]
        self.pshape = data.shape[:-2]
        flat = data.reshape(-1, self.ny, self.nx)
        if warp:
            cond = np.zeros_like(flat)
            cond[:, :, 1:] = np.cumsum(0.5 * (flat[:, :, :-1] + flat[:, :, 1:]), axis=2)
            marg = np.zeros((flat.shape[0], self.ny))
            marg[:, 1:] = np.cumsum(0.5 * (cond[:, :-1, -1] + cond[:, 1:, -1]), axis=1)
            norm = 1.0 / marg[:, -1]
            self.cond = cond * norm[:, None, None]
            self.marg = marg * norm[:, None]
            flat = flat * norm[:, None, None]
        self.data = flat
        self.strides = []
        s = 1
        for n in reversed(self.pshape):
            self.strides.insert(0, s)
            s *= n

    def _corners(self, param):
        """List of (slice index, weight) pairs for the multilinear parameter interpolation."""
        corners = [(0, 1.0)]
        for values, stride, p in zip(self.params, self.strides, param):
            idx, w1 = param_weights(values, p)
            if values.shape[0] == 1:
                continue
            corners = [(base + stride * (idx + j), w * (w1 if j else 1.0 - w1))
                       for base, w in corners for j in (0, 1)]
        return corners

    @staticmethod
    def _gather(arr, corners, *index):
        return sum(w * arr[(s,) + index] for s, w in corners)

    def eval(self, pos, param):
        """Bilinear interpolation of the (un-normalized) data at ``pos`` (..., 2) in [0, 1]^2."""
        corners = self._corners(param)
        px = np.clip(pos[..., 0], 0.0, 1.0) * (self.nx - 1)
        py = np.clip(pos[..., 1], 0.0, 1.0) * (self.ny - 1)
        ix = np.minimum(px.astype(np.intp), self.nx - 2)
        iy = np.minimum(py.astype(np.intp), self.ny - 2)
        wx, wy = px - ix, py - iy
        g = lambda y, x: self._gather(self.data, corners, y, x)  # noqa: E731
        return ((1 - wy) * ((1 - wx) * g(iy, ix) + wx * g(iy, ix + 1))
                + wy * ((1 - wx) * g(iy + 1, ix) + wx * g(iy + 1, ix + 1)))

    def invert(self, sample, param):
        """Inverse of the continuous marginal-conditional warp (Mitsuba's invert_continuous)."""
        corners = self._corners(param)
        sx = np.clip(sample[..., 0], 0.0, 1.0) * (self.nx - 1)
        sy = np.clip(sample[..., 1], 0.0, 1.0) * (self.ny - 1)
        ix = np.minimum(sx.astype(np.intp), self.nx - 2)
        iy = np.minimum(sy.astype(np.intp), self.ny - 2)
        sx, sy = sx - ix, sy - iy
        d = lambda y, x: self._gather(self.data, corners, y, x)  # noqa: E731
        c = lambda y, x: self._gather(self.cond, corners, y, x)  # noqa: E731
        v00, v10, v01, v11 = d(iy, ix), d(iy, ix + 1), d(iy + 1, ix), d(iy + 1, ix + 1)
        c0 = (1 - sy) * v00 + sy * v01
        c1 = (1 - sy) * v10 + sy * v11
        ux = sx * (c0 + 0.5 * sx * (c1 - c0))
        ux = ux + (1 - sy) * c(iy, ix) + sy * c(iy + 1, ix)
        r0, r1 = c(iy, self.nx - 1), c(iy + 1, self.nx - 1)
        ux = ux / ((1 - sy) * r0 + sy * r1)
        uy = sy * (r0 + 0.5 * sy * (r1 - r0)) + self._gather(self.marg, corners, iy)
        return np.stack([ux, uy], axis=-1)
