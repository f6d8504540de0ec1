r"""A fabric: two threads woven at right angles, with the options of MODEL.md."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from brdf import sampling, schema, validate
from brdf.curve import MAX_TANGENT_SAMPLES, SAMPLING_METHODS
from brdf.frames import flat_pairs
from brdf.kernel import thread_geometry
from brdf.shading import combine_rgb, inverse_denominator, thread_shade
from brdf.prepared import Prepared
from brdf.thread import Thread
from brdf.thread import html_table as thread_html_table

__all__ = ["Fabric", "Prepared", "OPTIONS", "TRANSMISSION_METHODS", "GAP_METHODS"]

TRANSMISSION_METHODS = ("half_angle", "longitudinal")
GAP_METHODS = ("incident", "outgoing")

#: Option names and defaults of a Fabric (MODEL.md's toggles and variants).
OPTIONS = {
    "masking": True,
    "reweighting": True,
    "tangent_samples": 32,
    "tangent_sampling": "midpoint",
    "transmission": "half_angle",
    "gap": "incident",
    "rotation": 0.0,
}

#: Target number of (pair, sample) elements per chunk: large enough to amortize NumPy's
#: per-call cost, small enough that the working set stays in cache. 2^15 since the kernel's
#: named blocks and underflow guards added per-chunk calls (2026-12-01, 2-core EPYC, CPU time
#: per 10^5 pairs: velvet 0.337-0.352 s at 2^15 against 0.343-0.354 at 2^14 and 0.424-0.438
#: at 2^16, which falls out of the 1 MiB L2).
_CHUNK_ELEMENTS = 1 << 15


@dataclasses.dataclass(frozen=True)
class _ThreadConst:
    """Everything about one thread that does not depend on the directions."""

    ca: np.ndarray        # cos of the distinct tangent offsets
    sa: np.ndarray        # sin of the distinct tangent offsets
    weight: np.ndarray    # weight of each distinct offset (sum 1)
    gamma_s: float        # radians
    gamma_v: float        # radians


class Fabric:
    r"""The microcylinder BRDF of a woven fabric (Sadeghi et al. 2013).

    Parameters
    ----------
    threads : sequence of two Thread
        Thread 1 (the warp, along +x) and thread 2 (the weft, along +y); their areas sum to
        at most 1 (:func:`brdf.schema.check_areas`).
    masking : bool, default True
        Shadowing and masking M; off means M = 1.
    reweighting : bool, default True
        Reweighting by visible length P and the normalization Q; off means P = Q = 1.
    tangent_samples : int, default 32
        Samples N per tangent curve (arc-length midpoints), 1..:data:`MAX_TANGENT_SAMPLES`.
    tangent_sampling : {"midpoint", "control_points"}, default "midpoint"
    transmission : {"half_angle", "longitudinal"}, default "half_angle"
    gap : {"incident", "outgoing"}, default "incident"
        Gap term c_gap of Q: n . wi or n . wo.
    rotation : float, default 0
        Rotation of both threads about n, radians (:data:`brdf.schema.FABRIC`).
    name : str, optional
        A label (preset name).

    Raises
    ------
    ValueError
        Wrong number of threads, areas summing above 1, unknown option names or values.

    Notes
    -----
    .. math::
        S_j = \frac{1}{N_j}\sum_{t\in T_j} f_s(t) M(t) P(t)\cos\theta_i(t),\quad
        Q = \sum_j a_j \frac{1}{N_j}\sum_{T_j} P(t) + (1 - a_1 - a_2)\, c_{gap},\quad
        f_r = \frac{a_1 S_1 + a_2 S_2}{Q\,(n\cdot\omega_i)}.

    Examples
    --------
    >>> import brdf
    >>> fab = brdf.fabric("linen_plain")
    >>> wi = brdf.directions.from_angles(np.radians(30), 0.0)
    >>> wo = brdf.directions.from_angles(np.radians(30), np.pi)
    >>> fab.eval(wi, wo).shape
    (3,)
    >>> fab.replace(masking=False).options["masking"]
    False
    """

    def __init__(self, threads: Sequence[Thread], *, name: str | None = None, **options):
        try:
            threads = tuple(threads)
        except TypeError:
            raise ValueError(f"threads must be two brdf.Thread objects (warp, weft); got "
                             f"{threads!r}") from None
        if len(threads) != 2 or not all(isinstance(t, Thread) for t in threads):
            raise ValueError(f"threads must be two brdf.Thread objects (warp, weft); got "
                             f"{len(threads)} item(s)")
        schema.check_areas(threads[0].area, threads[1].area)
        unknown = set(options) - set(OPTIONS)
        if unknown:
            raise ValueError(f"unknown option(s) {', '.join(sorted(map(repr, unknown)))}; "
                             f"valid options are {', '.join(OPTIONS)}")
        opts = dict(OPTIONS, **options)
        opts["masking"] = validate.flag("masking", opts["masking"])
        opts["reweighting"] = validate.flag("reweighting", opts["reweighting"])
        opts["tangent_samples"] = validate.integer("tangent_samples", opts["tangent_samples"],
                                                   lo=1, hi=MAX_TANGENT_SAMPLES)
        validate.choice("tangent_sampling", opts["tangent_sampling"], SAMPLING_METHODS)
        validate.choice("transmission", opts["transmission"], TRANSMISSION_METHODS)
        validate.choice("gap", opts["gap"], GAP_METHODS)
        opts["rotation"] = schema.FABRIC["rotation"].check(opts["rotation"])
        self._threads = threads
        self._options = opts
        self.name = name
        self._const = tuple(self._thread_const(t) for t in threads)

    def _thread_const(self, t: Thread) -> _ThreadConst:
        alpha, weight = t.curve.samples(self._options["tangent_samples"],
                                        self._options["tangent_sampling"])
        a = np.radians(alpha)
        return _ThreadConst(np.cos(a), np.sin(a), weight, np.radians(t.gamma_s),
                            np.radians(t.gamma_v))

    # -- read-only views ---------------------------------------------------------------
    @property
    def threads(self) -> tuple[Thread, Thread]:
        """The two threads (warp, weft)."""
        return self._threads

    @property
    def options(self) -> dict:
        """The options (a copy): masking, reweighting, tangent_samples, ... rotation."""
        return dict(self._options)

    def replace(self, **changes) -> "Fabric":
        """Return a variant with options, ``threads`` or ``name`` changed.

        Examples
        --------
        >>> import brdf
        >>> brdf.fabric("velvet").replace(gap="outgoing").options["gap"]
        'outgoing'
        """
        threads = changes.pop("threads", self._threads)
        name = changes.pop("name", self.name)
        return Fabric(threads, name=name, **dict(self._options, **changes))

    def as_dict(self) -> dict:
        """Threads and options as a JSON-ready dict."""
        return {"name": self.name, "threads": [t.as_dict() for t in self._threads],
                "options": self.options}

    def __repr__(self) -> str:
        """``Fabric(name=..., threads=(Thread(...), Thread(...)), option=...)``: the threads'
        parameters and the options that differ from :data:`OPTIONS` (valid Python).

        Examples
        --------
        >>> import brdf
        >>> brdf.fabric("velvet").replace(masking=False)  # doctest: +ELLIPSIS
        Fabric(name='velvet', threads=(Thread(eta=1.46, ...), Thread(eta=1.46, ...)), masking=False)
        """
        label = f"name={self.name!r}, " if self.name else ""
        changed = {k: v for k, v in self._options.items() if v != OPTIONS[k]}
        extra = "".join(f", {k}={v!r}" for k, v in changed.items())
        return f"Fabric({label}threads=({', '.join(map(repr, self._threads))}){extra})"

    def _repr_html_(self) -> str:
        """The threads' parameter table and the options, for Jupyter."""
        opts = ", ".join(f"{k}={v!r}" for k, v in self._options.items())
        return thread_html_table(self._threads, f"Fabric {self.name or ''} ({opts})")

    # -- evaluation --------------------------------------------------------------------
    def eval(self, wi, wo) -> np.ndarray:
        r"""The BRDF f_r(wi, wo), RGB, in 1/sr (no cosine factor).

        Parameters
        ----------
        wi : array_like, shape (..., 3)
            Directions toward the light, in the local frame (n = +z, warp = +x).
        wo : array_like, shape (..., 3)
            Directions toward the viewer. Broadcasts with ``wi``.

        Returns
        -------
        ndarray, shape (..., 3)
            f_r per RGB channel, 1/sr. Zero where either direction is at or below the
            horizon; NaN in the entries of zero or non-finite vectors. Non-unit vectors are
            normalized. Finite for every direction above the horizon: MODEL.md's f_r grows
            like 1/(n . wi) toward it (f_r (n . wi) has a limit), and saturates where
            Q (n . wi) < :data:`brdf.shading.DENOM_MIN` (about 1e-301).

        Raises
        ------
        ValueError
            If the arrays lack a last axis of 3 or do not broadcast.
        """
        return self._evaluate(wi, wo, split=False)

    def eval_threads(self, wi, wo) -> np.ndarray:
        r"""Each thread's share of f_r: :math:`a_j S_j / (Q\, n\cdot\omega_i)`, 1/sr.

        Returns
        -------
        ndarray, shape (..., 2, 3)
            Summing over axis -2 gives :meth:`eval`.
        """
        return self._evaluate(wi, wo, split=True)

    def _evaluate(self, wi, wo, split):
        wi, wo, shape, bad, below = flat_pairs(wi, wo)
        n = wi.shape[0]
        out = np.zeros((n, 2, 3) if split else (n, 3))
        ok = ~(bad | below)
        if ok.all():
            self._eval_into(wi, wo, out, split)
        elif ok.any():
            res = np.zeros((int(ok.sum()),) + out.shape[1:])
            self._eval_into(wi[ok], wo[ok], res, split)
            out[ok] = res
        out[bad] = np.nan
        return out.reshape(shape + out.shape[1:])

    def _eval_into(self, wi, wo, out, split):
        smax = max(c.ca.size for c in self._const)
        chunk = max(64, _CHUNK_ELEMENTS // smax)
        for start in range(0, wi.shape[0], chunk):
            sl = slice(start, start + chunk)
            sides = self._frames(wi[sl], wo[sl])
            geoms = [self._geometry(j, sides[j]) for j in range(2)]
            shades = [thread_shade(g, c.weight, t.eta, t.kd, c.gamma_s, c.gamma_v,
                                   self._options["transmission"])
                      for g, c, t in zip(geoms, self._const, self._threads)]
            out[sl] = self._combine(geoms, shades, wi[sl, 2], wo[sl, 2], split)

    def _frames(self, wi, wo):
        """Per-pair dot products with each thread's t0 and b, shape (C, 1) each."""
        rot = self._options["rotation"]
        c, s = np.cos(rot), np.sin(rot)
        out = []
        for w in (wi, wo):
            t = w[:, 0:1] * c + w[:, 1:2] * s      # w . t0 of thread 1
            b = w[:, 1:2] * c - w[:, 0:1] * s      # w . b  of thread 1 (= w . t0 of thread 2)
            out.append((t, b, w[:, 2:3]))
        (t_i, b_i, z_i), (t_o, b_o, z_o) = out
        # Thread 2 is thread 1 turned 90 degrees about n: t0' = b, b' = n x b = -t0.
        return ((t_i, b_i, z_i, t_o, b_o, z_o), (b_i, -t_i, z_i, b_o, -t_o, z_o))

    def _geometry(self, j, side):
        c = self._const[j]
        return thread_geometry(*side, c.ca, c.sa, c.weight,
                               with_masking=self._options["masking"],
                               with_reweighting=self._options["reweighting"],
                               keep_cos=self._options["transmission"] == "longitudinal")

    def _q(self, pmeans, area1, area2, zi, zo):
        """Q of MODEL.md from the threads' P means; 1 with reweighting off. Broadcasts area
        (B..., 1) over pairs."""
        if not self._options["reweighting"]:
            return 1.0
        gap = zi if self._options["gap"] == "incident" else zo
        return area1 * pmeans[0] + area2 * pmeans[1] + (1.0 - area1 - area2) * gap

    def _combine(self, geoms, shades, zi, zo, split):
        t1, t2 = self._threads
        q = self._q([g.pmean for g in geoms], t1.area, t2.area, zi, zo)
        inv = inverse_denominator(q, zi)
        if split:
            parts = [t.area * (s[0][:, None] + np.asarray(t.albedo) * s[1][:, None])
                     for t, s in zip(self._threads, shades)]
            return np.stack([p * inv[:, None] for p in parts], axis=1)
        area = np.array([[t1.area, t2.area]])
        albedo = np.array([[t1.albedo, t2.albedo]], dtype=np.float64)
        out = np.empty((1, zi.size, 3))
        combine_rgb([s[0][None] for s in shades], [s[1][None] for s in shades], area,
                    albedo, inv[None], out)
        return out[0]

    # -- importance sampling (brdf/sampling.py) ------------------------------------------
    def sample(self, wo, u):
        r"""Draw directions toward the light: ``(wi, weight, pdf)``, see :func:`brdf.sampling.sample`.

        ``u`` (..., 2) uniform in [0, 1); ``weight`` = f_r cos(theta_i) / pdf (RGB); ``pdf``
        in 1/sr.

        Examples
        --------
        >>> import brdf
        >>> fab = brdf.fabric("velvet")
        >>> wo = brdf.directions.from_angles(np.radians(60), 0.0)
        >>> wi, weight, pdf = fab.sample(wo, np.random.default_rng(0).random((4, 2)))
        >>> bool(np.allclose(pdf, fab.pdf(wo, wi)))
        True
        """
        return sampling.sample(self, wo, u)

    def pdf(self, wo, wi) -> np.ndarray:
        """Density (1/sr) of :meth:`sample`'s directions wi for the viewer wo, see
        :func:`brdf.sampling.pdf`."""
        return sampling.pdf(self, wo, wi)

    def prepare(self, wi, wo) -> "Prepared":
        """Precompute the geometry of fixed pairs for repeated shading (fits).

        Parameters
        ----------
        wi, wo : array_like, shape (n, 3)
            Direction pairs (broadcast, normalized; below-horizon or bad pairs give 0 / NaN).

        Returns
        -------
        Prepared
            Call ``.eval(eta=..., albedo=..., kd=..., gamma_s=..., gamma_v=..., area=...)``.
        """
        return Prepared(self, wi, wo)
