"""A measured table against models at every point, as data: for tables whose pairs are
scattered over the hemisphere (a ``microcyl plan`` design) rather than laid out in a plane
of incidence, and what a plane's view of a table leaves out (:func:`table_coverage`).

:func:`is_scattered` says which view a table gets; :func:`compute_table_scatter` evaluates
every model once at every valid point (measured against model, with sigma, and the
residuals over the half-vector disk), for the figure and the CSV of ``microcyl plot
table`` alike.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.views.common import check_quantity, eval_brdf, reduce_quantity
from analysis.views.table import plane_data, reduce_sigma

__all__ = ["TableScatterView", "compute_table_scatter", "is_scattered", "TableCoverage",
           "table_coverage", "MIN_PANEL_POINTS"]

#: A plane's panel (one incidence, one side of the light) needs this many points to show a
#: lobe; a table none of whose panels has as many is scattered.
MIN_PANEL_POINTS = 3


def is_scattered(table, phi_deg=0.0, tol_deg=2.0) -> bool:
    """Whether no incidence in the plane ``phi_deg`` holds :data:`MIN_PANEL_POINTS` valid
    points with the light on one side (none at all included): the table's pairs are
    scattered, and a plane's view of it would show next to nothing.

    Examples
    --------
    >>> import gonio, brdf
    >>> t = gonio.measure(brdf.fabric("velvet"), "plane:warp:10", progress=False)
    >>> is_scattered(t)
    False
    """
    try:
        ti, _, _, _, light, _ = plane_data(table, phi_deg, tol_deg)
    except ValueError:
        return True
    key = np.stack([np.round(ti * 2.0) / 2.0, light], axis=1)
    _, counts = np.unique(key, axis=0, return_counts=True)
    return bool(counts.max() < MIN_PANEL_POINTS)


@dataclass(frozen=True)
class TableCoverage:
    """What a view of a table drew and left out (counts of table rows).

    Attributes
    ----------
    rows, valid, drawn : int
        The table's rows, those valid (finite, non-negative values in every channel), and
        those the view drew.
    off_plane : int
        Valid rows off the plane (and its tolerance); 0 for a scattered view.
    other_incidences : tuple of float
        Incidences in the plane (degrees) the view did not draw (``--theta-i``).
    at_other_incidences : int
        Valid rows in the plane at those incidences.
    phi_deg, tol_deg : float or None
        The plane and its tolerance (degrees); None for a scattered view.
    """

    rows: int
    valid: int
    drawn: int
    off_plane: int = 0
    other_incidences: tuple = ()
    at_other_incidences: int = 0
    phi_deg: float | None = None
    tol_deg: float | None = None

    @property
    def invalid(self) -> int:
        """Rows with a NaN or negative value (never drawn)."""
        return self.rows - self.valid

    @property
    def complete(self) -> bool:
        """Whether every row was drawn."""
        return self.drawn == self.rows


def table_coverage(table, drawn_rows, phi_deg=None, tol_deg=2.0) -> TableCoverage:
    """The :class:`TableCoverage` of a view that drew ``drawn_rows`` (table rows) of
    ``table``, in the plane ``phi_deg`` (None: a scattered view of every valid point).

    Examples
    --------
    >>> import gonio, brdf
    >>> t = gonio.measure(brdf.fabric("velvet"), "plane:warp:10", progress=False)
    >>> c = table_coverage(t, [0, 1, 2], 0.0)
    >>> c.drawn, c.off_plane, c.valid == len(t)
    (3, 0, True)
    """
    valid_mask = np.asarray(table.valid).all(axis=1)
    drawn = np.zeros(len(table), bool)
    drawn[np.asarray(drawn_rows, dtype=np.int64)] = True
    common = dict(rows=len(table), valid=int(valid_mask.sum()), drawn=int(drawn.sum()))
    if phi_deg is None:
        return TableCoverage(**common)
    try:
        ti, _, _, _, _, idx = plane_data(table, phi_deg, tol_deg)
    except ValueError:
        ti, idx = np.empty(0), np.empty(0, np.int64)
    in_plane = np.zeros(len(table), bool)
    in_plane[idx] = True
    left = ~drawn[idx]
    other = tuple(float(t) for t in np.unique(np.round(ti[left] * 2.0) / 2.0))
    return TableCoverage(**common, off_plane=int(np.sum(valid_mask & ~in_plane)),
                         other_incidences=other, at_other_incidences=int(left.sum()),
                         phi_deg=float(phi_deg), tol_deg=float(tol_deg))


@dataclass(frozen=True, eq=False)
class TableScatterView:
    """Every valid point of a table and every model at it.

    Attributes
    ----------
    quantity : str
        "luminance", "r", "g" or "b".
    rows : numpy.ndarray of int, shape (n,)
        The valid table rows, in the table's order.
    angles_deg : numpy.ndarray, shape (n, 4)
        theta_i, phi_i, theta_o, phi_o of each, degrees.
    half : numpy.ndarray, shape (n, 2)
        (h_x, h_y) of the unit half vector of each (unitless): where it sits on the disk.
    measured, sigma : numpy.ndarray, shape (n,)
        f_r and its sigma (1/sr; sigma None when the table has none).
    models : dict
        Model label -> f_r at each point's own wi and wo (1/sr).
    """

    quantity: str
    rows: np.ndarray
    angles_deg: np.ndarray
    half: np.ndarray
    measured: np.ndarray
    sigma: np.ndarray | None
    models: dict

    unit = "1/sr"

    def residuals(self, name: str) -> tuple[np.ndarray, str]:
        """Model ``name``'s residuals at every point and what they are: (measured - model)
        / sigma with a sigma ("normalized residual"), else log10(measured / model)
        ("log10 ratio"; NaN where either is not positive)."""
        model = self.models[name]
        if self.sigma is not None and np.all(self.sigma > 0):
            return (self.measured - model) / self.sigma, "normalized residual (measured − model) / σ"
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where((self.measured > 0) & (model > 0),
                         np.log10(self.measured / model), np.nan)
        return r, "log10(measured / model)"

    def data_rows(self) -> list:
        """``(curve, theta_i, phi_i, theta_o, phi_o, f_r)`` per point and curve ("measured"
        or a model's label): every point, angles in degrees, f_r in 1/sr."""
        out = []
        for name, values in {"measured": self.measured, **self.models}.items():
            for a, v in zip(self.angles_deg, values):
                out.append((name, *a.tolist(), float(v)))
        return out


def compute_table_scatter(table, models, *, quantity="luminance") -> TableScatterView:
    """Every valid point of ``table`` (finite, non-negative in every channel) and every model
    of ``models`` (label -> BRDF) at its own directions, reduced to ``quantity``; a
    ValueError when the table has no valid point."""
    check_quantity(quantity)
    if quantity == "rgb":
        raise ValueError("quantity must be 'luminance', 'r', 'g' or 'b' to compare models; "
                         "got 'rgb'")
    rows = np.flatnonzero(np.asarray(table.valid).all(axis=1))
    if rows.size == 0:
        raise ValueError("table has no valid point (every value NaN or negative)")
    wi, wo = np.asarray(table.wi)[rows], np.asarray(table.wo)[rows]
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    values = np.asarray(table.values, dtype=np.float64)[rows]
    sigma = None if table.sigma is None else reduce_sigma(
        np.asarray(table.sigma, dtype=np.float64)[rows], quantity)
    return TableScatterView(
        quantity, rows, np.degrees(np.asarray(table.angles))[rows], h[:, :2],
        reduce_quantity(values, quantity), sigma,
        {name: reduce_quantity(eval_brdf(m, wi, wo), quantity)
         for name, m in dict(models).items()})
