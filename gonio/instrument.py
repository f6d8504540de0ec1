"""The instrument of a virtual gonioreflectometer: finite source and detector cones, and noise.

A real gonioreflectometer's source and detector subtend small cones, so each reading is an
average of f_r over directions near the nominal ones, and each reading is noisy. An
:class:`Instrument` models both:

- **Cones.** The source and the detector are cones of half-angles ``cone_source`` and
  ``cone_detector`` (degrees) about the nominal directions. The measured value is the average
  of f_r over both cones, each direction uniform over the solid angle of its cone and the two
  independent::

      v(wi, wo) = (1 / (Omega_s Omega_d)) int_{C_s(wi)} int_{C_d(wo)} f_r(wi', wo') dwo' dwi'

  computed by a deterministic product rule (:func:`cap_quadrature`): Gauss-Legendre in
  u = 1 - cos(theta) (uniform in solid angle) times equally spaced azimuths, the same points
  for every pair. A half-angle of 0 is a point (one evaluation). Directions of a cone that
  fall below the horizon count with the BRDF's value there (0).
- **Noise.** Independent per value and RGB channel, added to the cone average v:

  ``"multiplicative"`` (default): m = v (1 + eps_1 / snr) + floor eps_2, with eps_1, eps_2
  standard normal; std sigma = sqrt((v / snr)^2 + floor^2). The signal-to-noise ratio is
  ``snr`` at every value (without floor).

  ``"shot"`` (photon counting): m = N / k + floor eps_2 with N ~ Poisson(k v),
  k = snr^2 / snr_reference; mean v, std sigma = sqrt(v snr_reference / snr^2 + floor^2).
  The SNR is ``snr`` at v = ``snr_reference`` (1/sr) and grows as sqrt(v).

  ``snr=None`` (or inf) turns the first part off; ``floor`` is the std of the additive
  Gaussian floor in 1/sr. Noisy values may be negative: they are kept (an instrument reports
  them) and flagged by ``Table.valid``. The reported sigma is the model's std at the true
  value v.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from gonio.limits import check_limits, check_reachable, describe_limits, reachable

__all__ = ["Instrument", "cap_quadrature", "cone_directions", "NOISE_MODELS",
           "MAX_CONE_POINTS", "MAX_EVALUATIONS_PER_PAIR"]

#: Names of the noise models.
NOISE_MODELS = ("multiplicative", "shot")
#: Accepted snr and snr_reference (1/sr): within them v / snr, snr^2 and the Poisson rate
#: snr^2 v / snr_reference stay finite for any f_r (beyond, the noise is no measurement).
SNR_RANGE = (1e-3, 1e12)
REFERENCE_RANGE = (1e-12, 1e12)

#: Largest ``rings`` and ``azimuths`` (the Gauss-Legendre rule of a cone is built whole).
MAX_CONE_POINTS = 256
#: Largest number of BRDF evaluations of one pair (source points x detector points): a pair's
#: evaluations are made at once (a chunk of ``gonio.measure`` holds one pair at least), so
#: this bounds its memory: about 2 GiB.
MAX_EVALUATIONS_PER_PAIR = 1 << 22
#: Peak bytes of one BRDF evaluation inside a chunk, for the estimate in the size refusal:
#: a fabric's eval with 32 tangent samples about 340 (measured with tracemalloc, 2^15
#: pairs), the chunk's directions, weights and values the rest.
BYTES_PER_EVALUATION = 500

#: Above this Poisson mean the normal approximation is drawn (numpy's Poisson has a ceiling).
_POISSON_MAX = 1e7


def cap_quadrature(half_angle: float, rings: int = 2, azimuths: int = 6):
    """A quadrature rule for the uniform average over a spherical cap about +z.

    Parameters
    ----------
    half_angle : float
        Cap half-angle in degrees, in [0, 90). 0 gives the single point +z.
    rings : int
        Gauss-Legendre nodes in u = 1 - cos(theta) over [0, 1 - cos(half_angle)].
    azimuths : int
        Equally spaced azimuths per ring (odd rings shifted by half a step).

    Returns
    -------
    points : ndarray, shape (K, 3)
        Unit directions in the cap (K = rings * azimuths, or 1 for a point).
    weights : ndarray, shape (K,)
        Positive weights summing to 1.

    Notes
    -----
    Since solid angle is dOmega = du dphi, the uniform average over the cap is
    (1 / (2 pi U)) int_0^U int_0^{2 pi} f du dphi with U = 1 - cos(half_angle). The rule is
    exact for f = P(cos theta) e^{i m phi} with P of degree <= 2 rings - 1 and
    |m| <= azimuths - 1; in particular for constants and for every linear function of the
    direction.

    Examples
    --------
    >>> p, w = cap_quadrature(10.0, 2, 4)
    >>> p.shape, float(w.sum())
    ((8, 3), 1.0)
    >>> mean_cos = float(w @ p[:, 2])  # exact: (1 + cos 10 deg) / 2
    >>> abs(mean_cos - (1 + math.cos(math.radians(10))) / 2) < 1e-15
    True
    """
    half_angle = float(half_angle)
    if not (math.isfinite(half_angle) and 0.0 <= half_angle < 90.0):
        raise ValueError(f"cone half-angle must be in [0, 90) degrees; got {half_angle!r}")
    for name, v in (("rings", rings), ("azimuths", azimuths)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ValueError(f"{name} must be a positive integer; got {v!r}")
    if half_angle == 0.0:
        return np.array([[0.0, 0.0, 1.0]]), np.array([1.0])
    U = -math.expm1(math.log(math.cos(math.radians(half_angle))))  # 1 - cos, accurate
    x, wx = np.polynomial.legendre.leggauss(rings)
    u = 0.5 * U * (x + 1.0)
    cos_t = 1.0 - u
    sin_t = np.sqrt(np.maximum(u * (2.0 - u), 0.0))
    shift = 0.5 * (np.arange(rings) % 2)
    phi = 2.0 * np.pi * (np.arange(azimuths)[None, :] + shift[:, None]) / azimuths
    pts = np.stack([sin_t[:, None] * np.cos(phi), sin_t[:, None] * np.sin(phi),
                    np.broadcast_to(cos_t[:, None], phi.shape)], axis=-1).reshape(-1, 3)
    w = np.repeat(wx / 2.0 / azimuths, azimuths)
    return pts, w


def _frame(axis: np.ndarray):
    """Tangent and bitangent of an orthonormal frame about (..., 3) unit ``axis``.

    Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017.
    """
    x, y, z = axis[..., 0], axis[..., 1], axis[..., 2]
    sign = np.where(z >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + z)
    b = x * y * a
    t = np.stack([1.0 + sign * x * x * a, sign * b, -sign * x], axis=-1)
    bt = np.stack([b, sign + y * y * a, -y], axis=-1)
    return t, bt


def cone_directions(axis, points) -> np.ndarray:
    """Place cap points (about +z) about each of the (..., 3) unit ``axis`` directions.

    Returns
    -------
    ndarray, shape (..., K, 3)
        ``points[k]`` expressed in a fixed orthonormal frame whose pole is the axis.

    Examples
    --------
    >>> p, w = cap_quadrature(5.0, 1, 3)
    >>> d = cone_directions(np.array([[1.0, 0.0, 0.0]]), p)
    >>> np.degrees(np.arccos(d[0] @ [1.0, 0.0, 0.0])).round(6).tolist()  # all on one ring
    [3.534973, 3.534973, 3.534973]
    """
    axis = np.asarray(axis, float)
    t, b = _frame(axis)
    p = np.asarray(points, float)
    return (p[:, 0, None] * t[..., None, :] + p[:, 1, None] * b[..., None, :]
            + p[:, 2, None] * axis[..., None, :])


@dataclasses.dataclass(frozen=True)
class Instrument:
    """Source and detector cones and a noise model; see the module notes for the equations.

    The limits ``max_theta``, ``min_separation`` and ``in_plane`` (gonio/limits.py: their
    readings with open cones) say which pairs :meth:`reachable` accepts and
    :func:`gonio.measure` measures; they change no value.

    Parameters
    ----------
    cone_source, cone_detector : float
        Half-angles of the source and detector cones in degrees, in [0, 90); 0 is a point.
    snr : float or None
        Signal-to-noise ratio of the multiplicative or shot noise, in :data:`SNR_RANGE`;
        None or inf for none.
    floor : float
        Standard deviation of the additive Gaussian noise floor, in 1/sr (>= 0).
    noise : {"multiplicative", "shot"}
        The noise model.
    snr_reference : float
        For ``noise="shot"``: the f_r (1/sr) at which the SNR equals ``snr``.
    rings, azimuths : int
        The cone quadrature: Gauss-Legendre rings x equally spaced azimuths per cone, each in
        1..:data:`MAX_CONE_POINTS` (so a pair costs (rings * azimuths)^2 evaluations with
        both cones open, at most :data:`MAX_EVALUATIONS_PER_PAIR`). Checked on construction,
        before any quadrature is built.
    max_theta : float or None
        Largest polar angle of the source and the detector (their nominal directions),
        degrees in (0, 90]; None for no limit.
    min_separation : float or None
        Smallest angle between the source and detector cones, edge to edge (the angle
        between the nominal directions less both half-angles), degrees in [0, 180); None
        for no limit. Any value > 0 makes retro-reflection unreachable.
    in_plane : bool
        Measures in the plane of incidence only (phi_o = phi_i or phi_i + 180 within
        1e-6 rad; normal incidence is in every plane).

    Examples
    --------
    >>> ins = Instrument(cone_detector=2.0, snr=50)
    >>> ins.n_source, ins.n_detector, ins.is_noisy
    (1, 12, True)
    >>> ins.sigma(np.array([[1.0, 2.0, 0.0]])).tolist()
    [[0.02, 0.04, 0.0]]
    """

    cone_source: float = 0.0
    cone_detector: float = 0.0
    snr: float | None = None
    floor: float = 0.0
    noise: str = "multiplicative"
    snr_reference: float = 1.0
    rings: int = 2
    azimuths: int = 6
    max_theta: float | None = None
    min_separation: float | None = None
    in_plane: bool = False

    def __post_init__(self):
        for name in ("cone_source", "cone_detector"):
            v = getattr(self, name)
            try:
                v = float(v)
            except (TypeError, ValueError):
                raise ValueError(f"{name} must be degrees in [0, 90); got {v!r}") from None
            if not (math.isfinite(v) and 0.0 <= v < 90.0):
                raise ValueError(f"{name} must be degrees in [0, 90); got {v!r}")
            object.__setattr__(self, name, v)
        snr = self.snr
        if snr is not None:
            try:
                snr = float(snr)
            except (TypeError, ValueError):
                raise ValueError(f"snr must be a positive number or None; got {snr!r}") from None
            if math.isnan(snr) or snr <= 0 or (math.isfinite(snr) and not
                                                 SNR_RANGE[0] <= snr <= SNR_RANGE[1]):
                raise ValueError(f"snr must be a number in [{SNR_RANGE[0]:g}, {SNR_RANGE[1]:g}], "
                                 f"or None or inf for none; got {self.snr!r}")
            snr = None if math.isinf(snr) else snr
        object.__setattr__(self, "snr", snr)
        try:
            floor = float(self.floor)
        except (TypeError, ValueError):
            raise ValueError(f"floor must be a number >= 0 (1/sr); got {self.floor!r}") from None
        if not (math.isfinite(floor) and 0 <= floor <= REFERENCE_RANGE[1]):
            raise ValueError(f"floor must be a finite number in [0, {REFERENCE_RANGE[1]:g}] "
                             f"(1/sr); got {self.floor!r}")
        object.__setattr__(self, "floor", floor)
        if self.noise not in NOISE_MODELS:
            raise ValueError(f"noise must be one of {', '.join(NOISE_MODELS)}; got {self.noise!r}")
        try:
            ref = float(self.snr_reference)
        except (TypeError, ValueError):
            ref = math.nan
        if not (math.isfinite(ref) and REFERENCE_RANGE[0] <= ref <= REFERENCE_RANGE[1]):
            raise ValueError(f"snr_reference must be a positive f_r in 1/sr, in "
                             f"[{REFERENCE_RANGE[0]:g}, {REFERENCE_RANGE[1]:g}]; "
                             f"got {self.snr_reference!r}")
        object.__setattr__(self, "snr_reference", ref)
        limits = check_limits(self.max_theta, self.min_separation, self.in_plane)
        for name, v in zip(("max_theta", "min_separation", "in_plane"), limits):
            object.__setattr__(self, name, v)
        self._check_size()

    def _check_size(self) -> None:
        """Refuse quadratures too large to build or to evaluate a pair with, before any is
        built: rings and azimuths in 1..MAX_CONE_POINTS, and at most
        MAX_EVALUATIONS_PER_PAIR evaluations a pair (its memory estimated in the message)."""
        for name in ("rings", "azimuths"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not (
                    1 <= v <= MAX_CONE_POINTS):
                raise ValueError(f"{name} must be an integer in 1..{MAX_CONE_POINTS}; got "
                                 f"{v!r}")
        per_pair = self.n_source * self.n_detector
        if per_pair > MAX_EVALUATIONS_PER_PAIR:
            gib = per_pair * BYTES_PER_EVALUATION / 2 ** 30
            raise ValueError(
                f"rings x azimuths = {self.rings} x {self.azimuths} points a cone, with both "
                f"cones open, is {per_pair:,} evaluations for each pair (about {gib:.3g} GiB "
                f"at once); at most {MAX_EVALUATIONS_PER_PAIR:,}: lower rings or azimuths, "
                f"or use a point source or detector (cone 0)")

    # ------------------------------------------------------------------------- quadrature

    @property
    def source_rule(self):
        """(points (K, 3), weights (K,)) of the source cone about +z."""
        return cap_quadrature(self.cone_source, self.rings, self.azimuths)

    @property
    def detector_rule(self):
        """(points (K, 3), weights (K,)) of the detector cone about +z."""
        return cap_quadrature(self.cone_detector, self.rings, self.azimuths)

    @property
    def n_source(self) -> int:
        """Evaluation points of the source cone."""
        return 1 if self.cone_source == 0 else self.rings * self.azimuths

    @property
    def n_detector(self) -> int:
        """Evaluation points of the detector cone."""
        return 1 if self.cone_detector == 0 else self.rings * self.azimuths

    # ------------------------------------------------------------------------- noise

    @property
    def is_noisy(self) -> bool:
        """True when the instrument adds noise."""
        return self.snr is not None or self.floor > 0

    def sigma(self, values) -> np.ndarray | None:
        """The noise model's standard deviation (1/sr) at true values (1/sr), or None.

        None when the instrument is noiseless. Negative true values count as 0 for the
        signal-dependent part; non-finite values give NaN.
        """
        if not self.is_noisy:
            return None
        v = np.asarray(values, float)
        var = np.full(v.shape, self.floor ** 2)
        if self.snr is not None:
            vp = np.maximum(v, 0.0)
            if self.noise == "multiplicative":
                var = var + (vp / self.snr) ** 2
            else:
                var = var + vp * self.snr_reference / self.snr ** 2
        return np.where(np.isfinite(v), np.sqrt(var), np.nan)

    def add_noise(self, values, rng: np.random.Generator) -> np.ndarray:
        """Noisy readings of true values (1/sr), drawn from ``rng``; see the module notes.

        The draws are made in a fixed order over the whole array (signal-dependent part,
        then floor), so the same generator state gives the same bytes.
        """
        v = np.asarray(values, float)
        if not self.is_noisy:
            return v.copy()
        out = v.copy()
        finite = np.isfinite(v)
        vp = np.where(finite, np.maximum(v, 0.0), 0.0)
        if self.snr is not None:
            if self.noise == "multiplicative":
                out = out + vp / self.snr * rng.standard_normal(v.shape)
            else:
                k = self.snr ** 2 / self.snr_reference
                lam = vp * k
                big = lam > _POISSON_MAX
                counts = rng.poisson(np.where(big, 0.0, lam)).astype(float)
                if np.any(big):
                    lb = lam[big]
                    counts[big] = lb + np.sqrt(lb) * rng.standard_normal(lb.shape)
                out = np.where(v > 0, counts / k, v + counts / k)
        if self.floor > 0:
            out = out + self.floor * rng.standard_normal(v.shape)
        return np.where(finite, out, v)

    # ------------------------------------------------------------------------- limits

    def _limits(self) -> dict:
        return {"max_theta": self.max_theta, "min_separation": self.min_separation,
                "in_plane": self.in_plane, "cone_source": self.cone_source,
                "cone_detector": self.cone_detector}

    @property
    def has_limits(self) -> bool:
        """True when some limit is on (``max_theta``, ``min_separation`` or ``in_plane``)."""
        return self.max_theta is not None or self.min_separation is not None or self.in_plane

    def reachable(self, wi, wo) -> np.ndarray:
        """Whether the instrument can take each pair: bool array of the broadcast shape of
        directions ``wi``, ``wo`` (..., 3) in the local frame (z up); see :mod:`gonio.limits`.

        >>> ins = Instrument(min_separation=5.0)
        >>> ins.reachable([0.0, 0.0, 1.0], [[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]]).tolist()
        [False, True]
        """
        return reachable(wi, wo, **self._limits())

    def check_reachable(self, wi, wo, what: str = "geometry") -> None:
        """Raise a one-line ValueError naming ``what`` when some pair is out of reach: how
        many pairs break which limit, the first one's angles in degrees, and the limits."""
        check_reachable(wi, wo, what, **self._limits())

    def describe_limits(self) -> str:
        """The limits in words, e.g. ``'max_theta 80 deg, in the plane of incidence only'``."""
        return describe_limits(**self._limits())

    def describe(self) -> dict:
        """A JSON-serializable description (what :func:`gonio.measure` puts in ``meta``)."""
        d = dataclasses.asdict(self)
        d["cone_unit"] = "deg"
        d["floor_unit"] = "1/sr"
        d["limit_unit"] = "deg"
        d["evaluations_per_pair"] = self.n_source * self.n_detector
        return d
