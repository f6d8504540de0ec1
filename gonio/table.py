"""The BRDF table: measured or simulated f_r values at (wi, wo) pairs."""

from __future__ import annotations

import dataclasses
import html
from collections.abc import Mapping
from typing import Any

import numpy as np

from brdf.frames import normalize, to_angles
from gonio.errors import FormatError

__all__ = ["Table", "MAX_META_BYTES", "check_meta_size"]

#: The most bytes a table file's metadata may take (a CSV file's ``# key: value`` comment
#: lines, an OpenEXR file's ``microcyl_meta`` attribute): the metadata microcyl writes is a
#: few kilobytes, and parsed JSON takes tens of times its bytes.
MAX_META_BYTES = 1 << 20


def check_meta_size(path, nbytes: int, what: str) -> None:
    """Refuse, before it is parsed, a table file's metadata of more than
    :data:`MAX_META_BYTES`.

    Raises
    ------
    FormatError
        ``t.csv: the # comment lines: 25,000,000 bytes, more than ...``, naming the file.

    Examples
    --------
    >>> check_meta_size("t.exr", 2 << 20, "the microcyl_meta attribute")
    Traceback (most recent call last):
    ...
    gonio.errors.FormatError: t.exr: the microcyl_meta attribute: 2,097,152 bytes, more than \
the 1,048,576 a table's metadata may hold (microcyl writes a few KB)
    """
    if nbytes > MAX_META_BYTES:
        raise FormatError(path, f"{what}: {nbytes:,} bytes, more than the {MAX_META_BYTES:,} "
                                "a table's metadata may hold (microcyl writes a few KB)")


def _as_n3(name: str, value, n: int | None) -> np.ndarray:
    try:
        arr = np.array(value, dtype=np.float64)   # a copy: the caller's arrays are never changed
    except (TypeError, ValueError):
        raise ValueError(f"Table {name} must be a numeric array of shape (n, 3); got "
                         f"{value!r}"[:200]) from None
    if arr.ndim == 1 and name in ("values", "sigma"):
        arr = np.repeat(arr[:, None], 3, axis=1)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"Table {name} must have shape (n, 3); got {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(f"Table {name} has {arr.shape[0]} rows; wi has {n}")
    return arr


@dataclasses.dataclass(frozen=True, eq=False)
class Table:
    """A BRDF table: RGB f_r (1/sr, no cosine) at n direction pairs.

    Parameters
    ----------
    wi, wo : array_like, shape (n, 3)
        Unit directions toward the light and toward the viewer, in the sample's local frame
        (n = +z, warp = +x). Re-normalized on construction.
    values : array_like, shape (n, 3) or (n,)
        f_r in 1/sr per RGB channel (a 1-D array is grey and repeated to 3 channels). NaN or
        negative values are kept: they mark missing or invalid measurements (see ``valid``).
    sigma : array_like, shape (n, 3) or (n,), optional
        Standard deviation of each value in 1/sr, or None when unknown.
    meta : dict, optional
        What was measured and how: source, geometry, instrument, seed, units, version.

    Examples
    --------
    >>> t = Table([[0, 0, 1.0]], [[0, 0, 1.0]], [[0.1, 0.2, 0.3]])
    >>> len(t), t.values.shape, t.sigma
    (1, (1, 3), None)
    """

    wi: np.ndarray
    wo: np.ndarray
    values: np.ndarray
    sigma: np.ndarray | None = None
    meta: dict[str, Any] = dataclasses.field(default_factory=dict)

    def __post_init__(self):
        wi = _as_n3("wi", self.wi, None)
        n = wi.shape[0]
        wo = _as_n3("wo", self.wo, n)
        for name, w in (("wi", wi), ("wo", wo)):
            with np.errstate(over="ignore", under="ignore"):
                norm = np.linalg.norm(w, axis=1, keepdims=True)
            if not np.all((norm > 2.0 ** -500) & (norm < 2.0 ** 500)):  # scale first
                unit, bad = normalize(w)
                if bad.any():
                    raise ValueError(f"Table {name} holds zero or non-finite directions (row "
                                     f"{int(np.argmax(bad))})")
                w[...] = unit
            else:
                w /= norm
        values = _as_n3("values", self.values, n)
        sigma = None if self.sigma is None else _as_n3("sigma", self.sigma, n)
        object.__setattr__(self, "wi", wi)
        object.__setattr__(self, "wo", wo)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "sigma", sigma)
        if not isinstance(self.meta, Mapping):
            raise ValueError(f"Table meta must be a dict; got {type(self.meta).__name__}")
        object.__setattr__(self, "meta", dict(self.meta))

    def __len__(self) -> int:
        return self.wi.shape[0]

    @property
    def valid(self) -> np.ndarray:
        """(n, 3) bool: True where the value is finite and non-negative."""
        return np.isfinite(self.values) & (self.values >= 0)

    @property
    def angles(self) -> np.ndarray:
        """(n, 4) array of theta_i, phi_i, theta_o, phi_o in radians.

        theta is the polar angle from n = +z; phi the azimuth from +x toward +y, in (-pi, pi].
        """
        ti, pi_ = to_angles(self.wi)
        to, po = to_angles(self.wo)
        return np.stack([ti, pi_, to, po], axis=1)

    def replace(self, **changes) -> "Table":
        """Return a copy with the given fields replaced."""
        return dataclasses.replace(self, **changes)

    def describe(self) -> dict:
        """What the table holds, in words and numbers: pairs, channels (``"RGB"`` or
        ``"grey"``: three equal channels), sigma, valid values, the angle ranges in degrees
        (theta_i, phi_i, theta_o, phi_o: min and max) and the source named in ``meta``.

        Examples
        --------
        >>> t = Table([[0, 0, 1.0], [1, 0, 1]], [[0, 0, 1.0], [0, 1, 1]], [0.1, 0.2])
        >>> d = t.describe()
        >>> d["pairs"], d["channels"], d["sigma"], d["theta_o"]
        (2, 'grey', False, (0.0, 45.0))
        """
        finite = np.isfinite(self.values)
        grey = bool(np.all((self.values[:, 0] == self.values[:, 1])
                           & (self.values[:, 1] == self.values[:, 2]) | ~finite.all(axis=1)))
        out = {"pairs": len(self), "channels": "grey" if grey else "RGB",
               "sigma": self.sigma is not None, "valid": int(self.valid.sum()),
               "values": int(self.values.size)}
        if len(self):
            deg = np.degrees(self.angles)
            for k, name in enumerate(("theta_i", "phi_i", "theta_o", "phi_o")):
                out[name] = (round(float(deg[:, k].min()), 4) + 0.0,
                             round(float(deg[:, k].max()), 4) + 0.0)
        out["source"] = _source(self.meta.get("source"))
        return out

    def __repr__(self) -> str:
        """``Table(n pairs, RGB|grey, sigma yes|no, theta_i lo..hi, ... deg, source '...')``.

        Examples
        --------
        >>> Table([[0, 0, 1.0]], [[1, 0, 1.0]], [[0.1, 0.2, 0.3]], meta={"source": "hand"})
        Table(1 pairs, RGB, sigma no, theta_i 0..0, phi_i 0..0, theta_o 45..45, phi_o 0..0 deg,
              source 'hand')
        """
        d = self.describe()
        parts = [f"{d['pairs']} pairs", d["channels"], f"sigma {'yes' if d['sigma'] else 'no'}"]
        if d["valid"] < d["values"]:
            parts.append(f"{d['values'] - d['valid']} of {d['values']} values invalid")
        if len(self):
            parts.append(", ".join(f"{k} {_g(d[k][0])}..{_g(d[k][1])}" for k in
                                   ("theta_i", "phi_i", "theta_o", "phi_o")) + " deg")
        if d["source"]:
            src = d["source"] if len(d["source"]) <= 60 else d["source"][:57] + "..."
            parts.append(f"source {src!r}")
        return f"Table({', '.join(parts)})"

    def _repr_html_(self) -> str:
        """A small table of :meth:`describe` for Jupyter, every value escaped."""
        rows = "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>"
                       for k, v in self.describe().items())
        return f"<table><caption>gonio.Table</caption><tbody>{rows}</tbody></table>"


def _g(x: float) -> str:
    return f"{x:.4g}"


def _source(source) -> str | None:
    """``meta["source"]`` in a few words: the text, or what simulated the table (a dict such
    as gonio.measure writes: its type and name)."""
    if isinstance(source, str):
        return source
    if isinstance(source, Mapping) and isinstance(source.get("type"), str):
        name = source.get("name")
        return f"simulated {source['type']}" + (f" {name}" if isinstance(name, str) else "")
    return None
