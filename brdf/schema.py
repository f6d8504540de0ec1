r"""The one table of the model's parameters: names, units, validated ranges and meanings.

Every layer derives from it: :class:`brdf.Thread` and :class:`brdf.TangentCurve` validate with
it, ``analysis.params`` takes its fit parameter names, units and search ranges from it, and the
command line and reports list parameters in its order with its headings.

A thread has eight parameters (MODEL.md, the columns of the paper's Table II); a fabric adds
its rotation and the constraint a_1 + a_2 <= 1 on its two threads' areas.

Examples
--------
>>> [p.name for p in THREAD_PARAMS]
['eta', 'albedo', 'kd', 'gamma_s', 'gamma_v', 'area', 'offsets', 'lengths']
>>> THREAD["gamma_s"].heading, THREAD["gamma_s"].allowed
('γs (deg)', '> 0')
>>> THREAD["kd"].check(1.2)
Traceback (most recent call last):
    ...
ValueError: kd must be a finite number with 0.0 <= kd <= 1.0; got 1.2
"""

from __future__ import annotations

import dataclasses

import numpy as np

from brdf import validate

__all__ = ["ParamInfo", "THREAD_PARAMS", "THREAD", "THREAD_FIELDS", "SCALAR_PARAMS",
           "FABRIC_PARAMS", "FABRIC", "AREA_SUM_MAX", "RGB_CHANNELS", "check_areas",
           "check_area_sums",
           "parameter_table"]

#: Channel suffixes of an RGB parameter (the albedo A).
RGB_CHANNELS = ("r", "g", "b")
#: The threads' areas may sum to at most this (the rest is gaps), up to a rounding margin.
AREA_SUM_MAX = 1.0
_AREA_SUM_SLACK = 1e-12


@dataclasses.dataclass(frozen=True)
class ParamInfo:
    """One parameter of the model.

    Attributes
    ----------
    name : str
        Attribute name (``Thread.<name>``, keyword of ``Prepared.eval``).
    kind : {"scalar", "rgb", "sequence"}
        One number; one or three numbers (R, G, B); a sequence (the tangent curve).
    unit : str
        ``"1"`` (dimensionless), ``"deg"`` (degrees) or ``"rad"`` (radians).
    lo, hi : float or None
        Validated bounds (None: unbounded on that side), each element for rgb / sequence.
    lo_open, hi_open : bool
        Whether ``lo`` / ``hi`` themselves are excluded.
    column : str
        The column of the paper's Table II (or the symbol of MODEL.md), without unit.
    description : str
        What the parameter means.
    typical : (float, float) or None
        The range real cloth takes: what a fit searches (inside the validated range).
    log_scale : bool
        The typical range spans decades (a fit searches it in the logarithm).
    typical_value : float or None
        A middle value of the typical range (the start of a fit that knows nothing else).
    plausible : (float, float) or None
        Where the literature bounds real fibres more tightly than ``typical`` (the search
        range): a fitted value outside it is physically implausible. None: ``typical``.
    what : str or None
        The allowed values in words, for error messages; None: from the bounds.
    note : str
        More on the parameter (constraints between parameters, conventions).
    """

    name: str
    kind: str
    unit: str
    lo: float | None
    hi: float | None
    column: str
    description: str
    lo_open: bool = False
    hi_open: bool = False
    typical: tuple[float, float] | None = None
    log_scale: bool = False
    typical_value: float | None = None
    what: str | None = None
    note: str = ""
    plausible: tuple[float, float] | None = None

    @property
    def heading(self) -> str:
        """Table heading: the column with its unit, e.g. ``"γs (deg)"``, ``"A (RGB)"``."""
        if self.kind == "rgb":
            return f"{self.column} (RGB)"
        return self.column if self.unit == "1" else f"{self.column} ({self.unit})"

    @property
    def allowed(self) -> str:
        """The validated range in words: ``"> 1"``, ``"[0, 1]"``, ``">= 0"``."""
        if self.lo is not None and self.hi is not None:
            return (f"{'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}"
                    f"{')' if self.hi_open else ']'}")
        if self.lo is not None:
            return f"{'>' if self.lo_open else '>='} {self.lo:g}"
        if self.hi is not None:
            return f"{'<' if self.hi_open else '<='} {self.hi:g}"
        return "any finite number"

    def check(self, value) -> float:
        """``value`` as a float if it lies in the validated range (one scalar, or one element).

        Raises
        ------
        ValueError
            Naming the parameter, its value and what is allowed.
        """
        return validate.real(self.name, value, lo=self.lo, hi=self.hi, lo_open=self.lo_open,
                             hi_open=self.hi_open, what=self.what)

    def check_array(self, arr: np.ndarray) -> np.ndarray:
        """``arr`` (float64, any shape) if every element lies in the validated range: one
        vectorized test; the message names the first element outside it and its index.

        Examples
        --------
        >>> THREAD["kd"].check_array(np.array([[0.3, 5.0]]))
        Traceback (most recent call last):
            ...
        ValueError: kd must be a finite number with 0.0 <= kd <= 1.0; got 5.0 (at index (0, 1))
        """
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(arr)
            if self.lo is not None:
                ok &= arr > self.lo if self.lo_open else arr >= self.lo
            if self.hi is not None:
                ok &= arr < self.hi if self.hi_open else arr <= self.hi
        if not ok.all():
            where = np.unravel_index(int(np.argmin(ok)), arr.shape)
            try:
                self.check(float(arr[where]))
            except ValueError as exc:
                index = tuple(int(i) for i in where)
                raise ValueError(f"{exc} (at index {index[0] if len(index) == 1 else index})") \
                    from None
        return arr

    def contains(self, x: float) -> bool:
        """Whether the number ``x`` lies in the validated range."""
        try:
            self.check(x)
        except ValueError:
            return False
        return True

    def text(self, value) -> str:
        """``value`` as short text: ``1.46``, ``0.06, 0.24, 0.3`` (RGB), ``[-25, 25]``."""
        if self.kind == "scalar":
            return f"{float(value):g}"
        items = ", ".join(f"{float(v):g}" for v in np.atleast_1d(value))
        return items if self.kind == "rgb" else f"[{items}]"


def _thread_params() -> tuple[ParamInfo, ...]:
    P = ParamInfo
    return (
        P("eta", "scalar", "1", 1.0, None, "η", "index of refraction of the fibre",
          lo_open=True, typical=(1.01, 3.0), typical_value=1.46,
          # textile polymers (cotton, wool, silk, nylon, acrylic, polyester) measure 1.5 to
          # 1.72; the paper's Table II takes 1.345 to 1.539
          plausible=(1.3, 1.8)),
        P("albedo", "rgb", "1", 0.0, None, "A", "volume albedo (R, G, B)", typical=(0.0, 1.0), typical_value=0.2,
          what="one or three finite numbers >= 0 (R, G, B)",
          note="scales only the volume term; the surface term is colourless"),
        P("kd", "scalar", "1", 0.0, 1.0, "k_d", "isotropic share of volume scattering",
          typical=(0.0, 1.0), typical_value=0.3),
        P("gamma_s", "scalar", "deg", 0.0, None, "γs", "width of the surface-reflection lobe", lo_open=True, typical=(0.3, 60.0), log_scale=True,
          typical_value=10.0, what="a finite angle > 0 degrees",
          note="standard deviation of a unit-area Gaussian in theta_h"),
        P("gamma_v", "scalar", "deg", 0.0, None, "γv", "width of the volume-scattering lobe", lo_open=True, typical=(0.3, 90.0), log_scale=True,
          typical_value=20.0, what="a finite angle > 0 degrees",
          note="standard deviation of a unit-area Gaussian in theta_h"),
        P("area", "scalar", "1", 0.0, 1.0, "area a", "share a_j of the cloth covered by the "
          "thread", typical=(0.0, 1.0), typical_value=0.5, note="a_1 + a_2 <= 1"),
        P("offsets", "sequence", "deg", -90.0, 90.0, "offsets", "tangent offsets "
          "alpha_0..alpha_K", what="within [-90, 90] degrees",
          note="one more than lengths; the tangent curve's control points"),
        P("lengths", "sequence", "1", 0.0, None, "lengths", "segment lengths l_1..l_K",
          what="finite and >= 0", note="arbitrary units, summing to > 0; 0 is a jump"),
    )


#: The thread's parameters, in the order of ``Thread``'s fields (the paper's Table II).
THREAD_PARAMS: tuple[ParamInfo, ...] = _thread_params()
#: The same by name.
THREAD: dict[str, ParamInfo] = {p.name: p for p in THREAD_PARAMS}
#: Field names of a thread, in order.
THREAD_FIELDS: tuple[str, ...] = tuple(THREAD)
#: The scalar thread parameters (one number each), in order.
SCALAR_PARAMS: tuple[str, ...] = tuple(p.name for p in THREAD_PARAMS if p.kind == "scalar")

#: Fabric-level parameters (beyond the two threads and the toggles of ``brdf.OPTIONS``).
FABRIC_PARAMS: tuple[ParamInfo, ...] = (
    ParamInfo("rotation", "scalar", "rad", None, None, "ρ", "rotation of both threads about "
              "the normal n", what="a finite angle in radians"),
)
#: The same by name.
FABRIC: dict[str, ParamInfo] = {p.name: p for p in FABRIC_PARAMS}


def check_areas(area1: float, area2: float) -> None:
    """Raise ValueError unless the two threads' areas sum to at most :data:`AREA_SUM_MAX`.

    Examples
    --------
    >>> check_areas(0.6, 0.6)
    Traceback (most recent call last):
        ...
    ValueError: area: the threads' areas must sum to at most 1; got 0.6 + 0.6 = 1.2
    """
    total = area1 + area2
    if total > AREA_SUM_MAX + _AREA_SUM_SLACK:
        raise ValueError(f"area: the threads' areas must sum to at most {AREA_SUM_MAX:g}; got "
                         f"{area1} + {area2} = {total:g}")


def check_area_sums(area: np.ndarray) -> None:
    """Vectorized :func:`check_areas` over area pairs on the last axis (shape (..., 2))."""
    total = area[..., 0] + area[..., 1]
    bad = total > AREA_SUM_MAX + _AREA_SUM_SLACK
    if bad.any():
        where = np.unravel_index(int(np.argmax(bad)), total.shape)
        check_areas(float(area[where][0]), float(area[where][1]))


def parameter_table() -> str:
    """The thread parameters as a reStructuredText table (name, meaning, unit, range).

    Examples
    --------
    >>> print(parameter_table().splitlines()[1])
    parameter  meaning                                       unit  allowed
    """
    rows = [(p.name, p.description, p.unit, p.allowed + (" each" if p.kind != "scalar" else ""))
            for p in THREAD_PARAMS]
    head = ("parameter", "meaning", "unit", "allowed")
    widths = [max(len(r[i]) for r in rows + [head]) for i in range(4)]
    rule = "  ".join("=" * w for w in widths)
    line = lambda r: "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip()  # noqa: E731
    return "\n".join([rule, line(head), rule] + [line(r) for r in rows] + [rule])
