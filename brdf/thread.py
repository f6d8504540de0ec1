"""One thread of a fabric: its optical parameters and its tangent curve."""

from __future__ import annotations

import dataclasses
import html

import numpy as np

from brdf import schema
from brdf.curve import TangentCurve

__all__ = ["Thread"]


@dataclasses.dataclass(frozen=True)
class Thread:
    r"""A thread's parameters, in the units of the paper's Table II (:mod:`brdf.schema`).

{parameter_table}

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
        for name in schema.SCALAR_PARAMS:
            set_(name, schema.THREAD[name].check(getattr(self, name)))
        set_("albedo", _rgb(schema.THREAD["albedo"], self.albedo))
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

    def __repr__(self) -> str:
        """``Thread(eta=1.46, albedo=(...), ...)``, numbers to 4 significant digits.

        Examples
        --------
        >>> Thread(1.46, (0.06, 0.24, 0.3), 0.3, 12, 24, 0.33, (-25, 25), (1,))
        Thread(eta=1.46, albedo=(0.06, 0.24, 0.3), kd=0.3, gamma_s=12, gamma_v=24, area=0.33,
               offsets=(-25, 25), lengths=(1,))
        """
        return "Thread(" + ", ".join(f"{k}={_short(v)}" for k, v in self._fields()) + ")"

    def _repr_html_(self) -> str:
        """A one-row parameter table for Jupyter (units in the header)."""
        return html_table([self])

    def _fields(self):
        return [(f.name, getattr(self, f.name)) for f in dataclasses.fields(self)]


def _short(value) -> str:
    """A number to 4 significant digits, or a tuple of them (one-tuples keep their comma)."""
    if isinstance(value, tuple):
        inner = ", ".join(_short(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    return f"{value:.4g}" if isinstance(value, float) else repr(value)


def html_table(threads, caption: str = "") -> str:
    """The threads' parameters as an HTML table (one row a thread, units in the header),
    every value escaped; what ``_repr_html_`` of a Thread or Fabric shows."""
    names = [f.name for f in dataclasses.fields(Thread)]
    unit = {n: "" if schema.THREAD[n].unit == "1" else f" ({schema.THREAD[n].unit})"
            for n in names}
    head = "".join(f"<th>{html.escape(n + unit[n])}</th>" for n in names)
    rows = "".join(
        f"<tr><th>{j}</th>" + "".join(f"<td>{html.escape(_short(getattr(t, n)))}</td>"
                                      for n in names) + "</tr>"
        for j, t in enumerate(threads, 1))
    cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
    return f"<table>{cap}<thead><tr><th>thread</th>{head}</tr></thead><tbody>{rows}</tbody></table>"


Thread.__doc__ = Thread.__doc__.replace("{parameter_table}", "\n".join(
    "    " + line for line in schema.parameter_table().splitlines()))


def _rgb(info: schema.ParamInfo, value) -> tuple[float, float, float]:
    """One or three numbers in ``info``'s range as an (R, G, B) tuple, or ValueError."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.shape not in ((), (1,), (3,)) \
            or not all(info.contains(a) for a in arr.ravel()):
        raise ValueError(f"{info.name} must be {info.what}; got {value!r}")
    return tuple(float(a) for a in np.broadcast_to(arr.ravel() if arr.ndim else arr, (3,)))
