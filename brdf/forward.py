"""A model's forward model: its f_r at n fixed direction pairs, batched over parameter sets.

What a fit evaluates: ``model.forward(wi, wo)`` (:class:`brdf.Model`) prepares the pairs once
(``model.prepare``) and is called with the keyword arguments of the prepared ``eval``, which
``type(model).batch_kwargs(values)`` makes from the flat values a fit samples.

Examples
--------
>>> import numpy as np
>>> from brdf.baselines import Lambert
>>> fwd = Forward(Lambert(), [[0.0, 0.0, 1.0]], [[0.6, 0.0, 0.8]])
>>> f = fwd(**Lambert.batch_kwargs({"base_r": np.array([np.pi]), "base_g": np.array([0.0]),
...                                  "base_b": np.array([0.0])}))
>>> f.shape, np.round(f[0, 0], 12).tolist()
((1, 1, 3), [1.0, 0.0, 0.0])
"""

from __future__ import annotations

import numpy as np

__all__ = ["Forward"]


class Forward:
    """``model.prepare(wi, wo)`` called with batched keyword arguments -> f_r (B..., n, 3) in
    1/sr, float64 (see the module notes).

    Parameters
    ----------
    model : brdf.Model
    wi, wo : array_like, shape (n, 3)
        Direction pairs (broadcast; below the horizon 0, bad directions NaN).
    """

    def __init__(self, model, wi, wo):
        self.model = model
        self.wi = np.asarray(wi, dtype=np.float64)
        self.wo = np.asarray(wo, dtype=np.float64)
        self.prep = model.prepare(self.wi, self.wo)

    def __call__(self, **kw) -> np.ndarray:
        return self.prep.eval(**kw)
