"""One thread of a fabric: its optical parameters and its tangent curve."""

from __future__ import annotations

import dataclasses

import numpy as np

from brdf import validate
from brdf.curve import TangentCurve

__all__ = ["Thread"]


@dataclasses.dataclass(frozen=True)
class Thread:
    r"""A thread's parameters, in the units of the paper's Table II.

    ==========  ===========================================  ===============
    parameter   meaning                                      unit / range
    ==========  ===========================================  ===============
    eta         index of refraction of the fibre             > 1
    albedo      volume albedo A (R, G, B)                    >= 0 each
    kd          isotropic share of volume scattering         [0, 1]
    gamma_s     width of the surface-reflection lobe         degrees, > 0
    gamma_v     width of the volume-scattering lobe          degrees, > 0
    area        share a_j of the cloth covered by the thread [0, 1]
    offsets     tangent offsets alpha_0..alpha_K             degrees, [-90, 90]
    lengths     segment lengths l_1..l_K                     >= 0, sum > 0
    ==========  ===========================================  ===============

    Raises
    ------
    ValueError
        Any parameter outside its range; the message names it, its value and the range.

    Examples
    --------
    >>> t = Thread(1.46, (0.06, 0.24, 0.3), 0.3, 12, 24, 0.33, (-25, 25), (1,))
    >>> t.replace(kd=0.5).kd
    0.5
    """

    eta: float
    albedo: tuple[float, float, float]
    kd: float
    gamma_s: float
    gamma_v: float
    area: float
    offsets: tuple[float, ...]
    lengths: tuple[float, ...]

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        set_("eta", validate.real("eta", self.eta, lo=1.0, lo_open=True))
        set_("kd", validate.real("kd", self.kd, lo=0.0, hi=1.0))
        set_("gamma_s", validate.real("gamma_s", self.gamma_s, lo=0.0, lo_open=True,
                                      what="a finite angle > 0 degrees"))
        set_("gamma_v", validate.real("gamma_v", self.gamma_v, lo=0.0, lo_open=True,
                                      what="a finite angle > 0 degrees"))
        set_("area", validate.real("area", self.area, lo=0.0, hi=1.0))
        alb = np.asarray(self.albedo, dtype=np.float64) if _numeric(self.albedo) else None
        if alb is None or alb.shape not in ((), (3,)) or not np.all(np.isfinite(alb)) \
                or np.any(alb < 0):
            raise ValueError(f"albedo must be one or three finite numbers >= 0 (R, G, B); "
                             f"got {self.albedo!r}")
        set_("albedo", tuple(float(a) for a in np.broadcast_to(alb, (3,))))
        curve = TangentCurve(self.offsets, self.lengths)
        set_("offsets", curve.offsets)
        set_("lengths", curve.lengths)

    @property
    def curve(self) -> TangentCurve:
        """The tangent curve (offsets and lengths)."""
        return TangentCurve(self.offsets, self.lengths)

    def replace(self, **changes) -> "Thread":
        """Return a copy with the given parameters changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict:
        """Parameters as a JSON-ready dict (degrees for gamma and offsets)."""
        return {f.name: (list(v) if isinstance(v := getattr(self, f.name), tuple) else v)
                for f in dataclasses.fields(self)}


def _numeric(x) -> bool:
    try:
        np.asarray(x, dtype=np.float64)
        return True
    except (TypeError, ValueError):
        return False
