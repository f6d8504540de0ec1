"""Fast re-evaluation for the explorer: a model's f_r on fixed direction pairs, prepared once
(:meth:`brdf.Fabric.prepare`: the geometry of the pairs) and shaded again for each slider
move (:meth:`brdf.Prepared.eval` with the sliders' values), in a small cache keyed by the
pairs, the fabric's options and tangent curves.

Preparing costs about three times what one evaluation of the model itself costs (the
geometry of every sample written out and read back), which pays from the second move on
the same pairs. So pairs seen for the first time (a new incidence, plane, light or
rotation) are shaded by the model at the sliders' values and queued; the app prepares the
queue when it is idle (:meth:`PreparedCache.prepare_pending`, one pair set a call), and the
next parameter move finds them prepared.

A :class:`FastBRDF` has the ``eval(wi, wo)`` of any BRDF, so the views of
:mod:`analysis.views` (lobes, hemisphere, slices, sphere, albedo) run on it unchanged.

Examples
--------
>>> import brdf
>>> from reports.explore.models import explore_model
>>> m = explore_model()
>>> fab = m.start("linen_plain")
>>> cache = PreparedCache()
>>> fast = FastBRDF(m, m.values_of(fab), fab, cache, dtype=np.float64)
>>> wi, wo = np.array([[0.0, 0.0, 1.0]]), np.array([[0.5, 0.0, 0.866]])
>>> bool(np.allclose(fast.eval(wi, wo), fab.eval(wi, wo)))
True
>>> len(cache), cache.pending                 # shaded by the fabric itself, then queued
(0, 1)
>>> cache.prepare_pending(), len(cache), bool(np.allclose(fast.eval(wi, wo), fab.eval(wi, wo)))
(False, 1, True)
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from typing import Mapping

import numpy as np

from analysis.families import family
from reports.explore.models import APP_CONTROLLED

__all__ = ["PreparedCache", "FastBRDF", "batch_kwargs"]


class PreparedCache:
    """The last ``size`` prepared pair sets (least recently used dropped first), and a queue
    of the last ``size`` pair sets seen but not prepared (:meth:`want`)."""

    def __init__(self, size: int = 16):
        self.size = int(size)
        self._items: OrderedDict = OrderedDict()
        self._wanted: OrderedDict = OrderedDict()

    def __len__(self) -> int:
        return len(self._items)

    @property
    def pending(self) -> int:
        """How many pair sets wait to be prepared."""
        return len(self._wanted)

    def get(self, key, make):
        """The item of ``key``, made by ``make()`` when it is not held."""
        if key in self._items:
            self._items.move_to_end(key)
            return self._items[key]
        self._wanted.pop(key, None)
        item = self._items[key] = make()
        while len(self._items) > self.size:
            self._items.popitem(last=False)
        return item

    def peek(self, key):
        """The item of ``key``, or None when it is not held."""
        if key in self._items:
            self._items.move_to_end(key)
        return self._items.get(key)

    def want(self, key, make) -> None:
        """Queue ``make`` for :meth:`prepare_pending` (the newest first)."""
        self._wanted[key] = make
        self._wanted.move_to_end(key)
        while len(self._wanted) > self.size:
            self._wanted.popitem(last=False)

    def prepare_pending(self) -> bool:
        """Make the newest queued item; whether more wait."""
        if self._wanted:
            key, make = self._wanted.popitem(last=True)
            self.get(key, make)
        return bool(self._wanted)


def _pairs_key(wi: np.ndarray, wo: np.ndarray) -> bytes:
    h = hashlib.blake2b(digest_size=16)
    for a in (wi, wo):
        a = np.ascontiguousarray(a, dtype=np.float64)
        h.update(repr(a.shape).encode())
        h.update(a.tobytes())
    return h.digest()


def batch_kwargs(model_name: str, values: Mapping) -> dict:
    """The keyword arguments of ``prepare(...).eval`` from slider values (scalars or arrays
    of a batch shape B...). The microcylinder's tangent scales and rotation are not among
    them: they change the tangent curves and the frame, which the base fabric holds
    (``prepare`` is made of it; the explorer's own rotation control rebuilds it):
    :data:`reports.explore.models.APP_CONTROLLED`."""
    fam = family(model_name)
    return fam.model_kwargs({k: np.asarray(values[k], float) for k in fam.model_names
                             if k in values and k not in APP_CONTROLLED})


class FastBRDF:
    """``eval(wi, wo)``: the model of ``explore_model`` at ``values`` (every slider, natural
    units; arrays of a batch shape B... give (B..., n, 3)), prepared on ``base`` (a fabric:
    its options and tangent curves; a baseline model) through ``cache``; the microcylinder
    shaded in ``dtype`` (float32 by default: about twice as fast, a relative error of a few
    1e-6, :meth:`brdf.Prepared.eval`). With ``defer`` (the default), pairs not prepared
    yet are shaded by the model built at ``values`` (float64) and queued in ``cache``
    (module notes); a batch of values prepares them at once."""

    def __init__(self, explore_model, values: Mapping, base, cache: PreparedCache,
                 dtype=np.float32, defer: bool = True):
        self.model = explore_model
        self.dtype = dtype
        self.base = base
        self.cache = cache
        self.values = values
        self.kwargs = batch_kwargs(explore_model.name, values)
        self.defer = defer and all(np.ndim(v) == 0 for v in values.values())
        self._built = None
        if explore_model.is_microcylinder:
            self._tag = (repr(sorted(base.options.items())),
                         tuple((t.offsets, t.lengths) for t in base.threads))
        else:
            self._tag = (explore_model.name,)

    def _shade(self, prepared) -> np.ndarray:
        if self.model.is_microcylinder:
            return prepared.eval(dtype=self.dtype, **self.kwargs)
        return prepared.eval(**self.kwargs)

    def eval(self, wi, wo) -> np.ndarray:
        """f_r (1/sr) of the pairs (n, 3) each, (B..., n, 3) for a batch of values."""
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        key = (self._tag, _pairs_key(wi, wo))
        def make():            # prepared, and shaded once (float32 copies, NumPy geometry)
            prepared = self.base.prepare(wi, wo)
            self._shade(prepared)
            return prepared
        if not self.defer:
            return self._shade(self.cache.get(key, make))
        prepared = self.cache.peek(key)
        if prepared is not None:
            return self._shade(prepared)
        self.cache.want(key, make)
        if self._built is None:
            self._built = self.model.build(self.values, self.base)
        return np.asarray(self._built.eval(wi, wo), dtype=np.float64)
