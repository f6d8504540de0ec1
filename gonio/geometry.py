"""Measurement geometries: sets of (wi, wo) direction pairs with their own coordinates.

A :class:`Geometry` holds n pairs of unit directions in the *instrument* (lab) frame, the
coordinates they were built from (a dict of named (n,) arrays in radians, e.g. ``theta_i,
phi_i, theta_o, phi_o`` or ``theta_h, phi_h, theta_d, phi_d``), a ``kind`` and its
parameters, and a sample rotation (azimuth of the sample on the instrument's stage).

Conventions
-----------
- theta is the polar angle from the normal n = +z; phi the azimuth from +x (the warp of an
  unrotated sample) toward +y. Coordinates are stored in radians.
- Constructors take the angles that define a grid (steps, lists of angles) in **degrees**,
  as the command line does, and the sample ``rotation`` in **radians** (as
  ``brdf.fabric(rotation=...)`` does).
- The sample rotation r turns the sample by +r about n: the warp points at lab azimuth r.
  The directions handed to a BRDF, :attr:`Geometry.wi` and :attr:`Geometry.wo`, are the lab
  directions turned by -r about z, i.e. expressed in the sample's own frame. Measuring a BRDF
  f with rotation r therefore equals measuring f rotated by r (f_r(w, w') = f(R(-r) w,
  R(-r) w')) with rotation 0.
- Horizon: pairs with either direction at or below the horizon (z <= 1e-9) are **dropped**
  when the geometry is built (f_r is 0 there by definition and a measurement there is
  meaningless). ``info["dropped_below_horizon"]`` counts them, ``info["n_layout"]`` is the
  size of the full layout, and :attr:`Geometry.index` gives each kept pair's position in
  that layout (the flat MERL index for the MERL layout), so tables can be put back in place.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from brdf.frames import (directions_to_half_diff, directions_to_plane, from_angles,
                         half_diff_to_directions, plane_to_directions, rotate_z,
                         to_angles)
from gonio.jsonplain import plain
from gonio.merl import merl_index

#: The frame helpers under the names gonio has always exported (:mod:`brdf.frames`).
directions_from_angles = from_angles
angles_from_directions = to_angles

__all__ = [
    "Geometry",
    "HORIZON_EPS",
    "directions_from_angles",
    "angles_from_directions",
    "half_diff_to_directions",
    "directions_to_half_diff",
    "plane_to_directions",
    "directions_to_plane",
    "rotate_z",
    "SPEC_HELP",
]

#: Directions with z at or below this are at or below the horizon and are dropped.
HORIZON_EPS = 1e-9

#: One-line description of the spec grammar, used in error messages and CLI help.
SPEC_HELP = ("full:STEP[:PHI_STEP] | full:TI:PI:TO:PO | plane:{warp,weft,45,AZ}:STEP[:TI,TI,...] | "
             "rusinkiewicz:STEP | rusinkiewicz:TH:PH:TD:PD | merl[:STRIDE] | pairs:FILE.csv "
             "(angles in degrees)")


# ----------------------------------------------------------------------------- the class

@dataclasses.dataclass(frozen=True, eq=False)
class Geometry:
    """n (wi, wo) direction pairs of a measurement, with their own coordinates.

    Build one with a constructor of :mod:`gonio.layouts` (:func:`~gonio.layouts.full_grid`,
    :func:`~gonio.layouts.plane`, :func:`~gonio.layouts.rusinkiewicz`,
    :func:`~gonio.layouts.merl`, :func:`~gonio.layouts.pairs`,
    :func:`~gonio.layouts.pairs_from_angles`) or :func:`gonio.geomspec.from_spec`.

    Parameters
    ----------
    wi_lab, wo_lab : ndarray, shape (n, 3)
        Unit directions toward the light and toward the detector in the instrument (lab) frame.
    coords : dict of str to ndarray
        The geometry's own coordinates, each of shape (n,), in radians (for example
        ``theta_i, phi_i, theta_o, phi_o``; ``theta_h, phi_h, theta_d, phi_d``; or the signed
        ``theta_i, theta_o`` of a plane). They describe the lab directions (before rotation).
    kind : str
        "full", "plane", "rusinkiewicz", "merl" or "pairs".
    params : dict
        The constructor's parameters (angles in degrees), JSON-serializable.
    rotation : float
        Sample azimuth on the stage, radians. See the module notes.
    index : ndarray of int, shape (n,)
        Position of each pair in the full layout of ``kind`` (before pairs below the horizon
        were dropped); for "merl", the flat MERL index phi_d + 180 (theta_d + 90 theta_h).
    info : dict
        ``n_layout`` (size of the full layout), ``dropped_below_horizon`` (pairs dropped).

    Examples
    --------
    >>> from gonio.layouts import full_grid
    >>> g = full_grid(30)
    >>> len(g), g.kind, sorted(g.coords)
    (625, 'full', ['phi_i', 'phi_o', 'theta_i', 'theta_o'])
    >>> g.spec
    'full:30:30:30:30'
    """

    wi_lab: np.ndarray
    wo_lab: np.ndarray
    coords: dict
    kind: str = "pairs"
    params: dict = dataclasses.field(default_factory=dict)
    rotation: float = 0.0
    index: np.ndarray | None = None
    info: dict = dataclasses.field(default_factory=dict)

    def __post_init__(self):
        wi = np.array(self.wi_lab, float).reshape(-1, 3)
        wo = np.array(self.wo_lab, float).reshape(-1, 3)
        if wi.shape != wo.shape:
            raise ValueError(f"Geometry wi has shape {wi.shape} but wo has {wo.shape}")
        n = wi.shape[0]
        coords = {}
        for k, v in dict(self.coords).items():
            v = np.array(v, float).reshape(-1)
            if v.shape != (n,):
                raise ValueError(f"Geometry coordinate {k!r} has {v.size} values; expected {n}")
            coords[k] = v
        try:
            rotation = float(self.rotation)
        except (TypeError, ValueError):
            rotation = math.nan
        if not math.isfinite(rotation):
            raise ValueError(f"rotation must be a finite angle in radians; got {self.rotation!r}")
        index = np.arange(n) if self.index is None else np.array(self.index, np.int64).reshape(-1)
        if index.shape != (n,):
            raise ValueError(f"Geometry index has {index.size} values; expected {n}")
        info = {"n_layout": n, "dropped_below_horizon": 0}
        info.update(self.info)
        for arr in (wi, wo, index, *coords.values()):   # shared by reference: keep them intact
            arr.flags.writeable = False
        object.__setattr__(self, "wi_lab", wi)
        object.__setattr__(self, "wo_lab", wo)
        object.__setattr__(self, "coords", coords)
        object.__setattr__(self, "params", plain(dict(self.params)))
        object.__setattr__(self, "rotation", rotation)
        object.__setattr__(self, "index", index)
        object.__setattr__(self, "info", plain(info))

    def __len__(self) -> int:
        return self.wi_lab.shape[0]

    def __repr__(self) -> str:
        rot = f", rotation={self.rotation:.6g} rad" if self.rotation else ""
        return f"Geometry({self.spec or self.kind!r}, n={len(self)}{rot})"

    @property
    def wi(self) -> np.ndarray:
        """(n, 3) light directions in the sample frame (lab directions turned by -rotation)."""
        return rotate_z(self.wi_lab, -self.rotation) if self.rotation else self.wi_lab

    @property
    def wo(self) -> np.ndarray:
        """(n, 3) detector directions in the sample frame (lab directions turned by -rotation)."""
        return rotate_z(self.wo_lab, -self.rotation) if self.rotation else self.wo_lab

    @property
    def spec(self) -> str | None:
        """The compact spec string that rebuilds this layout (without rotation), or None."""
        p = self.params
        if self.kind == "full":
            return f"full:{_fmt(p['theta_i_step'])}:{_fmt(p['phi_i_step'])}:" \
                   f"{_fmt(p['theta_o_step'])}:{_fmt(p['phi_o_step'])}"
        if self.kind == "plane":
            ti = ",".join(_fmt(t) for t in p["theta_i"])
            return f"plane:{_fmt(p['azimuth'])}:{_fmt(p['theta_o_step'])}:{ti}"
        if self.kind == "rusinkiewicz":
            return (f"rusinkiewicz:{_fmt(p['theta_h_step'])}:{_fmt(p['phi_h_step'])}:"
                    f"{_fmt(p['theta_d_step'])}:{_fmt(p['phi_d_step'])}")
        if self.kind == "merl":
            return f"merl:{p['stride']}"
        if self.kind == "pairs" and p.get("file"):
            return f"pairs:{p['file']}"
        return None

    def with_rotation(self, rotation: float) -> "Geometry":
        """The same layout with the sample turned to ``rotation`` (radians, absolute)."""
        return dataclasses.replace(self, rotation=rotation)

    def subset(self, keep) -> "Geometry":
        """The pairs selected by a boolean mask or an index array, coordinates kept."""
        keep = keep if isinstance(keep, slice) else np.asarray(keep)
        return dataclasses.replace(
            self, wi_lab=self.wi_lab[keep], wo_lab=self.wo_lab[keep],
            coords={k: v[keep] for k, v in self.coords.items()}, index=self.index[keep])

    def describe(self) -> dict[str, Any]:
        """A JSON-serializable description (what :func:`gonio.measure` puts in ``meta``).

        Examples
        --------
        >>> from gonio.layouts import plane
        >>> d = plane("weft", 30, theta_i=[30]).describe()
        >>> d["kind"], d["n"], d["spec"], d["coords"]
        ('plane', 5, 'plane:90:30:30', ['theta_i', 'theta_o'])
        """
        return {"kind": self.kind, "spec": self.spec, "params": self.params,
                "rotation": self.rotation, "rotation_deg": math.degrees(self.rotation),
                "n": len(self), "coords": list(self.coords), "coords_unit": "rad",
                **self.info}

    # --------------------------------------------------------------------- alternative builds

    @classmethod
    def from_table(cls, table) -> "Geometry":
        """Rebuild the geometry of a table made by :func:`gonio.measure`.

        Uses ``table.meta["geometry"]`` (kind, params, rotation) and the table's directions;
        the coordinates are recomputed from the directions (exact up to rounding, except at
        degenerate points such as theta_h = 0 where an azimuth is arbitrary). Tables without
        that metadata become a "pairs" geometry.
        """
        g = dict(table.meta.get("geometry") or {})
        kind = g.get("kind", "pairs")
        rotation = float(g.get("rotation", 0.0))
        params = g.get("params", {})
        wi = rotate_z(table.wi, rotation)
        wo = rotate_z(table.wo, rotation)
        if kind in ("rusinkiewicz", "merl"):
            names = ("theta_h", "phi_h", "theta_d", "phi_d")
            coords = dict(zip(names, directions_to_half_diff(wi, wo)))
        elif kind == "plane":
            coords = dict(zip(("theta_i", "theta_o"),
                              directions_to_plane(wi, wo, math.radians(params["azimuth"]),
                                                  atol=1e-5)))
        else:
            kind = kind if kind in ("full", "pairs") else "pairs"
            ti, pi_ = to_angles(wi)
            to, po = to_angles(wo)
            coords = {"theta_i": ti, "phi_i": pi_, "theta_o": to, "phi_o": po}
        index = None
        if kind == "merl":
            index = merl_index(coords["theta_h"], coords["theta_d"], coords["phi_d"])
        return cls(wi, wo, coords, kind=kind, params=params, rotation=rotation, index=index,
                   info={k: g[k] for k in ("n_layout", "dropped_below_horizon") if k in g})


def _fmt(x) -> str:
    """Format a degree value compactly: 10.0 -> '10', 2.5 -> '2.5'."""
    return f"{float(x):g}"
