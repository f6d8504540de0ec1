"""A measured table against models in a plane of incidence, as data: which rows lie in the
plane, the panels (incidence and the side the light was on), and each panel's measured
points, every model at those points' own directions and every model's curve through the
plane; each evaluated once, for the figure and the CSV of ``microcyl plot table`` alike.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis import colour
from analysis.views.common import check_quantity, eval_brdf, reduce_quantity
from analysis.views.lobes import plane_directions
from gonio.atomic import atomic_write
from gonio.csvcells import text_cell

__all__ = ["plane_points", "plane_lights", "plane_incidences", "table_panels", "table_points",
           "plane_data", "reduce_sigma", "TablePanelView", "compute_table_panel",
           "FitOverlayView", "compute_fit_overlay", "write_table_data", "DATA_COLUMNS"]


def _signed(theta, phi, phi_plane, tol):
    """Signed angle (radians) of directions in the plane at phi_plane, NaN off the plane."""
    d = np.angle(np.exp(1j * (phi - phi_plane)))
    fwd = np.abs(d) <= tol
    back = np.abs(np.abs(d) - np.pi) <= tol
    near_pole = theta <= tol
    s = np.full(theta.shape, np.nan)
    s[fwd | near_pole] = theta[fwd | near_pole]
    s[back & ~near_pole] = -theta[back & ~near_pole]
    return s


def plane_points(table, phi_deg=0.0, tol_deg=2.0):
    """Rows of a table that lie in the plane of incidence at azimuth ``phi_deg``.

    Parameters
    ----------
    table : gonio.Table
    phi_deg : float
        Azimuth of the plane in degrees.
    tol_deg : float
        Azimuth tolerance in degrees (directions within tol of the pole always count).

    Returns
    -------
    index : numpy.ndarray of int
        Rows in the plane.
    theta_i_deg : numpy.ndarray
        Incidence angle (unsigned) of each row, degrees.
    theta_o_deg : numpy.ndarray
        Signed viewing angle of each row, degrees, positive away from the light (toward
        azimuth phi when the light is at phi + 180, toward phi + 180 when it is at phi):
        the light always on the negative side. Which side the light was really on is
        :func:`plane_lights`'s; a model drawn over these points must be evaluated with
        the light there (a fabric need not be symmetric under the half turn).
    """
    idx, ti, so, _ = _plane_rows(table, phi_deg, tol_deg)
    return idx, ti, so


def plane_lights(table, phi_deg=0.0, tol_deg=2.0) -> np.ndarray:
    """The light's azimuth (degrees: ``phi_deg`` or ``phi_deg + 180``, the latter for a
    light within the tolerance of the pole) of each row :func:`plane_points` returns, in
    its order."""
    _, _, _, flip = _plane_rows(table, phi_deg, tol_deg)
    return np.where(flip, float(phi_deg), float(phi_deg) + 180.0)


def _plane_rows(table, phi_deg, tol_deg):
    """index, theta_i (deg), signed theta_o (deg, + away from the light) and whether the
    light is at phi (True) rather than phi + 180, of the rows in the plane."""
    ang = np.asarray(table.angles)
    tol = np.radians(tol_deg)
    phi = np.radians(phi_deg)
    si = _signed(ang[:, 0], ang[:, 1], phi, tol)
    so = _signed(ang[:, 2], ang[:, 3], phi, tol)
    # Light on the positive side: the signed angles measured from the other end of the
    # plane, so that the light is on the negative side (the model is evaluated there).
    flip = si > tol
    si = np.where(flip, -si, si)
    so = np.where(flip, -so, so)
    keep = np.isfinite(si) & np.isfinite(so)
    idx = np.nonzero(keep)[0]
    return idx, np.degrees(np.abs(si[idx])), np.degrees(so[idx]), flip[idx]


def plane_incidences(table, phi_deg=0.0, tol_deg=2.0) -> np.ndarray:
    """The distinct incidence angles (degrees, to 0.5 degree) of a table's valid points in
    the plane ``phi_deg``; raises ``ValueError`` when the plane holds none."""
    ti = plane_data(table, phi_deg, tol_deg)[0]
    return np.unique(np.round(ti * 2.0) / 2.0)


def table_panels(table, theta_i_deg=None, phi_deg=0.0, tol_deg=2.0) -> list:
    """The panels of a table against models in the plane ``phi_deg``: a ``(theta_i, light)``
    pair (degrees; ``light`` the light's azimuth, ``phi_deg`` or ``phi_deg + 180``) for each
    incidence of ``theta_i_deg`` (default every incidence in the plane) and each side the
    light was measured from; a ValueError names an incidence the plane does not hold."""
    ti, _, _, _, light, _ = plane_data(table, phi_deg, tol_deg)
    have = np.unique(np.round(ti * 2.0) / 2.0)
    wanted = have if theta_i_deg is None else np.atleast_1d(theta_i_deg)
    out = []
    for t in wanted:
        sel = np.abs(ti - float(t)) <= 0.5
        if not sel.any():
            raise ValueError(f"theta_i must be one of the table's incidences in the plane "
                             f"phi = {phi_deg:g} degrees ({', '.join(f'{h:g}' for h in have)})"
                             f"; got {float(t):g}")
        out += [(float(t), float(lt)) for lt in np.unique(light[sel])[::-1]]
    return out


def table_points(table, models, theta_i_deg, phi_deg=0.0, light_deg=None, *,
                 quantity="luminance", tol_deg=2.0):
    """The measured points of one panel and every model at each point's own directions.

    Parameters
    ----------
    table : gonio.Table
    models : mapping of str to BRDF
        Label -> object with ``.eval``.
    theta_i_deg, phi_deg : float
        Incidence (matched within 0.5 degree) and plane azimuth, degrees.
    light_deg : float, optional
        The light's azimuth (``phi_deg`` or ``phi_deg + 180``, degrees); default the side
        that holds points (``phi_deg + 180`` when both do).
    quantity : {"luminance", "r", "g", "b"}

    Returns
    -------
    dict
        ``rows`` (table rows, by signed theta_o), ``x`` (signed theta_o, degrees, + away from
        the light), ``theta_i`` (mean incidence, degrees), ``light`` (degrees), ``measured``
        (f_r, 1/sr), ``sigma`` (1/sr or None) and ``models`` (label -> f_r at the rows, 1/sr:
        the model evaluated at the measured wi and wo, nothing turned or mirrored).
    """
    check_quantity(quantity)
    if quantity == "rgb":
        raise ValueError("quantity must be 'luminance', 'r', 'g' or 'b' to compare models; "
                         "got 'rgb'")
    ti, to, values, sigma, light, idx = plane_data(table, phi_deg, tol_deg)
    sel = np.abs(ti - float(theta_i_deg)) <= 0.5
    if not sel.any():
        have = ", ".join(f"{t:g}" for t in np.unique(np.round(ti * 2.0) / 2.0))
        raise ValueError(f"theta_i must be one of the table's incidences in the plane "
                         f"phi = {phi_deg:g} degrees ({have}); got {float(theta_i_deg):g}")
    if light_deg is None:
        light_deg = float(np.max(light[sel]))
    sel &= np.isclose(light, float(light_deg))
    if not sel.any():
        raise ValueError(f"no point of theta_i = {float(theta_i_deg):g} degrees has the light "
                         f"at phi = {float(light_deg):g} degrees")
    order = np.argsort(to[sel])
    rows = idx[sel][order]
    wi, wo = np.asarray(table.wi)[rows], np.asarray(table.wo)[rows]
    return {"rows": rows, "x": to[sel][order], "theta_i": float(np.mean(ti[sel])),
            "light": float(light_deg),
            "measured": reduce_quantity(values[sel][order], quantity),
            "sigma": None if sigma is None else reduce_sigma(sigma[sel][order], quantity),
            "models": {name: reduce_quantity(eval_brdf(m, wi, wo), quantity)
                       for name, m in dict(models).items()}}


def plane_data(table, phi_deg, tol_deg):
    """The valid table points in the plane ``phi_deg``: (theta_i, signed theta_o (degrees),
    f_r, sigma or None, the light's azimuth (degrees), their rows in the table)."""
    idx, ti, to, flip = _plane_rows(table, phi_deg, tol_deg)
    values = np.asarray(table.values, dtype=np.float64)[idx]
    valid = np.asarray(table.valid)[idx].all(axis=1)
    idx, ti, to, values, flip = idx[valid], ti[valid], to[valid], values[valid], flip[valid]
    if idx.size == 0:
        raise ValueError(f"table has no valid points in the plane phi = {phi_deg:g} degrees "
                         f"(tolerance {tol_deg:g} degrees)")
    sigma = None if table.sigma is None else np.asarray(table.sigma, float)[idx]
    light = np.where(flip, float(phi_deg), float(phi_deg) + 180.0)
    return ti, to, values, sigma, light, idx


def reduce_sigma(sigma, quantity):
    """sigma (n, 3) of f_r reduced to ``quantity``; luminance with independent channels."""
    if quantity == "luminance":
        return np.sqrt((sigma ** 2) @ (colour.LUMINANCE_WEIGHTS ** 2))
    return reduce_quantity(sigma, quantity)


@dataclass(frozen=True, eq=False)
class TablePanelView:
    """One panel of a table against models: the measured points at one incidence with the
    light on one side of the plane, every model at those points and along the plane.

    Attributes
    ----------
    phi_deg, theta_i_deg : float
        Azimuth of the plane and the incidence asked for, degrees.
    tol_deg : float
        Azimuth tolerance of the points in the plane, degrees.
    quantity : str
        "luminance", "r", "g" or "b".
    points : dict
        :func:`table_points` of the panel (``rows``, ``x``, ``theta_i``, ``light``,
        ``measured``, ``sigma``, ``models``): f_r in 1/sr, angles in degrees.
    x_model : numpy.ndarray, shape (n,) or None
        Signed theta_o of the curves, degrees (+ away from the light); None without curves.
    curves : dict
        Model label -> its f_r (1/sr) along ``x_model``, evaluated with the light where it
        was measured; empty without curves.
    """

    phi_deg: float
    theta_i_deg: float
    tol_deg: float
    quantity: str
    points: dict
    x_model: np.ndarray | None
    curves: dict

    unit = "1/sr"

    def rows(self, angles_deg) -> list:
        """``(curve, theta_i, phi_i, theta_o, phi_o, f_r)`` per point and curve ("measured"
        or a model's label), the point's angles from ``angles_deg`` (the table's, degrees)."""
        pts = self.points
        out = []
        for name, values in {"measured": pts["measured"], **pts["models"]}.items():
            for row, value in zip(pts["rows"], values):
                out.append((name, *angles_deg[row].tolist(), float(value)))
        return out


def compute_table_panel(table, models, theta_i_deg, phi_deg=0.0, light_deg=None, *,
                        quantity="luminance", tol_deg=2.0, resolution=181) -> TablePanelView:
    """The measured points of one panel and every model at them (:func:`table_points`), and
    each model's curve over ``resolution`` signed angles from -90 to 90 degrees with the
    light where it was measured (no curves when ``resolution`` is None)."""
    pts = table_points(table, models, theta_i_deg, phi_deg, light_deg, quantity=quantity,
                       tol_deg=tol_deg)
    if resolution is None:
        return TablePanelView(float(phi_deg), float(theta_i_deg), float(tol_deg), quantity,
                              pts, None, {})
    x_model = np.linspace(-90.0, 90.0, int(resolution))
    # the light where it was measured: wi at azimuth light, the curve away from it
    wi, wo = plane_directions(pts["theta_i"], x_model, pts["light"] + 180.0)
    curves = {name: reduce_quantity(eval_brdf(m, wi, wo), quantity)
              for name, m in dict(models).items()}
    return TablePanelView(float(phi_deg), float(theta_i_deg), float(tol_deg), quantity, pts,
                          x_model, curves)


@dataclass(frozen=True, eq=False)
class FitOverlayView:
    """One model over a table's points in a plane at several incidences.

    Attributes
    ----------
    phi_deg : float
        Azimuth of the plane, degrees.
    quantity : str
        "rgb", "luminance", "r", "g" or "b".
    x_model : numpy.ndarray, shape (n,)
        Signed theta_o of the model's curves, degrees (+ away from the light).
    groups : tuple of dict
        Per incidence and side of the light: ``theta_i`` (the incidence asked for, degrees),
        ``light`` (the light's azimuth, degrees), ``model`` (f_r along ``x_model``, 1/sr,
        evaluated once with the light there), ``x`` (the points' signed theta_o, degrees),
        ``measured`` and ``sigma`` (1/sr; sigma None without one).
    """

    phi_deg: float
    quantity: str
    x_model: np.ndarray
    groups: tuple

    @property
    def both_sides(self) -> bool:
        """Whether the points hold the light on both sides of the plane."""
        return len({g["light"] for g in self.groups}) > 1


def compute_fit_overlay(table, brdf, phi_deg=0.0, theta_i_deg=None, *, quantity="rgb",
                        tol_deg=2.0, resolution=181, max_incidences=4) -> FitOverlayView:
    """The points of ``table`` in the plane ``phi_deg`` at ``theta_i_deg`` (default the first
    ``max_incidences`` distinct incidences there, within 0.5 degree) and the model's curve
    for each incidence and side of the light; a ValueError when the plane holds no point."""
    check_quantity(quantity)
    ti, to, values, sigma, light, _ = plane_data(table, phi_deg, tol_deg)
    distinct = np.unique(np.round(ti * 2.0) / 2.0)
    wanted = distinct[:max_incidences] if theta_i_deg is None else np.atleast_1d(theta_i_deg)
    x_model = np.linspace(-90.0, 90.0, int(resolution))
    groups = []
    for t, lt in [(t, lt) for t in wanted for lt in np.unique(light[np.abs(ti - t) <= 0.5])]:
        sel = (np.abs(ti - t) <= 0.5) & (light == lt)
        # the light where it was: the curve runs through the plane away from it
        wi, wo = plane_directions(float(np.mean(ti[sel])), x_model, lt + 180.0)
        groups.append({"theta_i": t, "light": lt,
                       "model": reduce_quantity(eval_brdf(brdf, wi, wo), quantity),
                       "x": to[sel], "measured": reduce_quantity(values[sel], quantity),
                       "sigma": None if sigma is None else reduce_sigma(sigma[sel], quantity)})
    return FitOverlayView(float(phi_deg), quantity, x_model, tuple(groups))


#: The columns of ``microcyl plot table --data`` (:func:`write_table_data`).
DATA_COLUMNS = ("curve", "theta_i", "phi_i", "theta_o", "phi_o", "f_r")


def write_table_data(path, rows) -> Path:
    """Write rows ``(curve, theta_i, phi_i, theta_o, phi_o, f_r)`` (what a table's figure drew
    at the measured points: angles in degrees, f_r in 1/sr) as CSV, a header of
    :data:`DATA_COLUMNS`, numbers with 17 significant digits, atomically; returns the path.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     out = write_table_data(Path(tmp) / "d.csv", [("measured", 30, 0, 45, 180, 0.1)])
    ...     print(out.read_text(), end="")
    curve,theta_i,phi_i,theta_o,phi_o,f_r
    measured,30.0,0.0,45.0,180.0,0.1
    """
    path = Path(path)
    with atomic_write(path, "w") as fh:
        out = csv.writer(fh, lineterminator="\n")
        out.writerow(DATA_COLUMNS)
        for name, *numbers in rows:
            out.writerow([text_cell(name), *(repr(float(v)) for v in numbers)])
    return path
