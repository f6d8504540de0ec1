"""The "energy" section: both directional albedos of :func:`analysis.energy_report` (the
furnace albedo rho(wo) and the directional reflectance rho'(wi)) and what they say."""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from analysis import albedo_curve, energy_report
from reports.colour import line_colour
from reports.plots.albedo import plot_albedo
from reports.prose import ALBEDO_KINDS, albedo_exceeds, albedo_sentence, energy_verdict
from reports.report.markup import html, join
from reports.report.page import Page, new_figure
from reports.report.settings import Section

__all__ = ["EnergyData", "ALBEDO_PHI", "section_energy"]

#: Azimuths of the albedo curves: the fixed direction along the warp and the weft, degrees.
ALBEDO_PHI = (0.0, 90.0)
#: Quadrature settings of :func:`analysis.albedo` (its defaults), for every fabric alike.
_TOL, _MIN_LEVEL = 5e-4, 0
#: The albedos computed, in page order (:data:`reports.prose.ALBEDO_KINDS`).
MODES = ("furnace", "reflectance")


@dataclasses.dataclass(frozen=True)
class EnergyData:
    """The two directional albedos of one fabric.

    Attributes
    ----------
    theta_deg, phi_deg : numpy.ndarray
        Polar angles (T,) and azimuths (P,) of the fixed direction (wo for the furnace
        albedo, wi for the reflectance), degrees.
    value, error : numpy.ndarray
        The furnace albedo rho(wo) = integral of f_r cos(theta_i) dwi and its error bound,
        (T, P, 3), dimensionless.
    reflectance, reflectance_error : numpy.ndarray
        The directional reflectance rho'(wi) = integral of f_r cos(theta_o) dwo, (T, P, 3).
    seconds : float
        Wall time of the computation.
    colour : tuple
        The fabric's line colour (RGB in [0, 1]).
    """

    theta_deg: np.ndarray
    phi_deg: np.ndarray
    value: np.ndarray
    error: np.ndarray
    seconds: float
    colour: tuple
    reflectance: np.ndarray | None = None
    reflectance_error: np.ndarray | None = None

    @property
    def _argmax(self):
        return np.unravel_index(int(np.argmax(self.value)), self.value.shape)

    @property
    def max(self) -> float:
        """The largest furnace albedo over directions and channels."""
        return float(self.value[self._argmax])

    @property
    def max_error(self) -> float:
        """The error bound of :attr:`max`."""
        return float(self.error[self._argmax])

    @property
    def max_where(self) -> tuple[float, float, str]:
        """theta (deg), phi (deg) and channel ("R", "G" or "B") of :attr:`max`."""
        i, j, c = self._argmax
        return float(self.theta_deg[i]), float(self.phi_deg[j]), "RGB"[c]

    @property
    def exceeds_one(self) -> bool:
        """Whether the largest furnace albedo exceeds 1 by more than its error."""
        return bool(self.max - self.max_error > 1.0)

    def curves(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Mode -> (value, error) of each albedo computed."""
        out = {"furnace": (self.value, self.error)}
        if self.reflectance is not None:
            out["reflectance"] = (self.reflectance, self.reflectance_error)
        return out

    def findings(self) -> dict[str, dict]:
        """Mode -> :func:`reports.prose.albedo_exceeds` of each albedo computed."""
        return {m: albedo_exceeds(self.theta_deg, v, e) for m, (v, e) in self.curves().items()}

    def verdict(self) -> str:
        """:func:`reports.prose.energy_verdict` of the albedos."""
        f = self.findings()
        return energy_verdict(f["furnace"], f.get("reflectance"))

    def summary(self) -> dict[str, Any]:
        """``energy``: the furnace albedo's maximum and where it is, its curves, and the
        reflectance's findings and curves."""
        theta, phi, channel = self.max_where
        out = {"max": self.max, "max_error": self.max_error, "max_theta_deg": theta,
               "max_phi_deg": phi, "max_channel": channel, "exceeds_one": self.exceeds_one,
               "seconds": self.seconds, "theta_deg": self.theta_deg,
               "phi_deg": list(self.phi_deg), "value": self.value, "error": self.error,
               "colour": self.colour, "verdict": self.verdict()}
        if self.reflectance is not None:
            d = self.findings()["reflectance"]
            out["reflectance"] = {
                "max": d["max"], "max_error": d["max_error"], "max_theta_deg": d["max_theta"],
                "exceeds_one": d["exceeds"], "first_theta_above_one_deg": d["first"],
                "value": self.reflectance, "error": self.reflectance_error}
        return {"energy": out}


def _albedos(p: Page, theta: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Mode -> (value, error), each (T, P, 3): from :func:`analysis.energy_report` for a
    preset, else (a BRDF that is no preset) from :func:`analysis.albedo_curve` with the same
    quadrature."""
    out = {}
    if p.preset is not None:
        rep = energy_report([p.preset], ["default"], theta_deg=theta, phi_deg=ALBEDO_PHI,
                            modes=MODES, tol=_TOL, min_level=_MIN_LEVEL,
                            hemispherical=False, furnace=False)
        for c in rep.curves:
            out[c.get("mode", "furnace")] = (c["value"], c["error"])
    else:
        for m in MODES:
            res = albedo_curve(p.fabric, theta, np.array(ALBEDO_PHI), tol=_TOL,
                               min_level=_MIN_LEVEL, swap=m == "reflectance")
            out[m] = (res.value, res.error)
    return {m: (np.asarray(v, dtype=np.float64), np.asarray(e, dtype=np.float64))
            for m, (v, e) in out.items()}


def _figure(p: Page, e: EnergyData):
    curves = e.curves()
    fig, axes = new_figure(2, len(curves), figsize=(11.0, 3.6 * len(curves)))
    for row, (m, (value, error)) in enumerate(curves.items()):
        name, symbol, angle = ALBEDO_KINDS[m]
        for k, (j, phi) in enumerate(zip(range(2), ALBEDO_PHI)):
            ax = axes[2 * row + k]
            plot_albedo(e.theta_deg, value[:, j], error[:, j], ax=ax, legend=k == 1,
                        title=f"{name} {symbol}, φ = {phi:g}°")
            ax.set_xlabel(f"{angle} (degrees)")
            ax.set_ylabel(f"{name} (unitless)")
    return p.figure(fig, "albedo.png", "Both directional albedos per channel (red, green, "
                    "blue) with the provider's error bounds, the fixed direction along the warp "
                    "(φ = 0, left) and the weft (φ = 90°, right); the dotted line is 1. Top: "
                    "the furnace albedo ρ(wo), the light reflected toward wo under uniform "
                    "white light; bottom: the directional reflectance ρ'(wi), the fraction of "
                    "light from wi reflected into the hemisphere, which energy conservation "
                    "bounds by 1.")


def section_energy(p: Page) -> Section:
    """Both albedo curves for the fixed direction along the warp and the weft, albedo.csv,
    and a sentence per albedo on whether it exceeds 1 (:func:`reports.prose.albedo_sentence`)."""
    theta = np.asarray(p.q["albedo_theta"], dtype=np.float64)
    t0 = time.perf_counter()
    curves = _albedos(p, theta)
    value, error = curves["furnace"]
    refl = curves.get("reflectance", (None, None))
    e = EnergyData(theta, np.array(ALBEDO_PHI), value, error, time.perf_counter() - t0,
                   line_colour(p.fabric), refl[0], refl[1])
    out = [html("<p>{}</p>", " ".join(albedo_sentence(m, theta, v, err)
                                      for m, (v, err) in e.curves().items())),
           _figure(p, e)]
    header, rows = ["theta_deg", "phi_deg"], [[t, phi] for t in theta for phi in ALBEDO_PHI]
    for m, (v, err) in e.curves().items():
        header += [f"{m}_{c}" for c in "rgb"] + [f"{m}_error_{c}" for c in "rgb"]
        rows = [r + list(v[divmod(i, len(ALBEDO_PHI))]) + list(err[divmod(i, len(ALBEDO_PHI))])
                for i, r in enumerate(rows)]
    link = p.csv("albedo.csv", header, rows)
    out.append(html("<p>Data (albedos unitless, angles in degrees): {}</p>", link))
    return Section(join(out), e)
