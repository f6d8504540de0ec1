r"""A fabric: two threads woven at right angles, with the options of MODEL.md."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from brdf import sampling, schema
from brdf.microcylinder import MicrocylinderModel
from brdf.options import GAP_METHODS, OPTIONS, TRANSMISSION_METHODS, FabricOptions
from brdf.plan import FabricPlan
from brdf.prepared import Prepared
from brdf.thread import Thread
from brdf.thread import html_table as thread_html_table

__all__ = ["Fabric", "Prepared", "OPTIONS", "TRANSMISSION_METHODS", "GAP_METHODS"]


class Fabric(MicrocylinderModel):
    r"""The microcylinder BRDF of a woven fabric (Sadeghi et al. 2013).

    The model ``microcylinder`` of :data:`brdf.MODELS`: its flat parameters, ``start``,
    ``values``, ``with_values``, ``batch_kwargs`` and ``forward`` come from
    :class:`brdf.microcylinder.MicrocylinderModel`.

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
        Gap term c_gap of Q: n . wi or n . wo. The variants are strings or the members of
        :class:`brdf.TangentSampling`, :class:`brdf.Transmission`, :class:`brdf.Gap`.
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
        self._threads = threads
        self._options = FabricOptions.from_mapping(options)
        self.name = name
        self._plan = FabricPlan.compile(threads, self._options)

    # -- read-only views ---------------------------------------------------------------
    @property
    def threads(self) -> tuple[Thread, Thread]:
        """The two threads (warp, weft)."""
        return self._threads

    @property
    def options(self) -> dict:
        """The options as plain values (a new dict): masking, reweighting, tangent_samples,
        ... rotation; the variants as their strings (JSON, ``replace``). The model reads the
        typed ones, ``plan.options``."""
        return self._options.as_dict()

    @property
    def plan(self) -> FabricPlan:
        """The compiled form (:class:`brdf.FabricPlan`): typed options and each thread's
        constants, what the kernel, :class:`brdf.Prepared`, the sampler and the Mitsuba
        plugin read."""
        return self._plan

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
        return Fabric(threads, name=name, **dict(self.options, **changes))

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
        changed = {k: v for k, v in self.options.items() if v != OPTIONS[k]}
        extra = "".join(f", {k}={v!r}" for k, v in changed.items())
        return f"Fabric({label}threads=({', '.join(map(repr, self._threads))}){extra})"

    def _repr_html_(self) -> str:
        """The threads' parameter table and the options, for Jupyter."""
        opts = ", ".join(f"{k}={v!r}" for k, v in self.options.items())
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
            Q (n . wi) < :data:`brdf.combine.DENOM_MIN` (about 1e-301).

        Raises
        ------
        ValueError
            If the arrays lack a last axis of 3 or do not broadcast.
        """
        return self._plan.eval(wi, wo)

    def eval_threads(self, wi, wo) -> np.ndarray:
        r"""Each thread's share of f_r: :math:`a_j S_j / (Q\, n\cdot\omega_i)`, 1/sr.

        Returns
        -------
        ndarray, shape (..., 2, 3)
            Summing over axis -2 gives :meth:`eval`.
        """
        return self._plan.eval(wi, wo, split=True)

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
        return sampling.sample(self._plan, wo, u)

    def pdf(self, wo, wi) -> np.ndarray:
        """Density (1/sr) of :meth:`sample`'s directions wi for the viewer wo, see
        :func:`brdf.sampling.pdf`."""
        return sampling.pdf(self._plan, wo, wi)

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
        return Prepared(self._plan, wi, wo)
