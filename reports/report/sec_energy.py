"""The "energy" section: the directional albedo of :func:`analysis.energy_report`."""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from analysis import albedo_curve, energy_report
from reports.colour import line_colour
from reports.plot_albedo import plot_albedo
from reports.report.markup import html, join
from reports.report.page import Page, new_figure
from reports.report.settings import Section

__all__ = ["EnergyData", "ALBEDO_PHI", "section_energy"]

#: Azimuths of the albedo curves: wo along the warp and the weft, degrees.
ALBEDO_PHI = (0.0, 90.0)
#: Quadrature settings of :func:`analysis.albedo` (its defaults), for every fabric alike.
_TOL, _MIN_LEVEL = 5e-4, 0


@dataclasses.dataclass(frozen=True)
class EnergyData:
    """The furnace albedo rho(wo) = integral of f_r cos(theta_i) dwi of one fabric.

    Attributes
    ----------
    theta_deg, phi_deg : numpy.ndarray
        Polar angles (T,) and azimuths (P,) of wo, degrees.
    value, error : numpy.ndarray
        Albedo and its error bound, (T, P, 3), dimensionless.
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

    @property
    def _argmax(self):
        return np.unravel_index(int(np.argmax(self.value)), self.value.shape)

    @property
    def max(self) -> float:
        """The largest albedo over directions and channels."""
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
        """Whether the largest albedo exceeds 1 by more than its error."""
        return bool(self.max - self.max_error > 1.0)

    def summary(self) -> dict[str, Any]:
        """``energy``: the maximum and where it is, and the curves."""
        theta, phi, channel = self.max_where
        return {"energy": {
            "max": self.max, "max_error": self.max_error, "max_theta_deg": theta,
            "max_phi_deg": phi, "max_channel": channel, "exceeds_one": self.exceeds_one,
            "seconds": self.seconds, "theta_deg": self.theta_deg,
            "phi_deg": list(self.phi_deg), "value": self.value, "error": self.error,
            "colour": self.colour}}


def _albedo(p: Page, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """value, error (T, P, 3): from :func:`analysis.energy_report` for a preset, else (a
    BRDF that is no preset) from :func:`analysis.albedo_curve` with the same quadrature."""
    if p.preset is not None:
        rep = energy_report([p.preset], ["default"], theta_deg=theta, phi_deg=ALBEDO_PHI,
                            modes=("furnace",), tol=_TOL, min_level=_MIN_LEVEL,
                            hemispherical=False, furnace=False)
        curve = rep.curves[0]
    else:
        res = albedo_curve(p.fabric, theta, np.array(ALBEDO_PHI), tol=_TOL,
                           min_level=_MIN_LEVEL)
        curve = {"value": res.value, "error": res.error}
    return np.asarray(curve["value"], dtype=np.float64), np.asarray(curve["error"],
                                                                    dtype=np.float64)


def _verdict(e: EnergyData) -> str:
    if e.exceeds_one:
        return "exceeds 1 (energy is created)"
    return "stays at or below 1 within the error" if e.max - e.max_error <= 1.0 \
        else "is uncertain"


def section_energy(p: Page) -> Section:
    """Albedo curves for wo along the warp and the weft, albedo.csv and the largest value."""
    theta = np.asarray(p.q["albedo_theta"], dtype=np.float64)
    t0 = time.perf_counter()
    value, error = _albedo(p, theta)
    e = EnergyData(theta, np.array(ALBEDO_PHI), value, error, time.perf_counter() - t0,
                   line_colour(p.fabric))
    fig, axes = new_figure(2, 1, figsize=(10.0, 3.8))
    for ax, j, phi in zip(axes, range(2), ALBEDO_PHI):
        plot_albedo(theta, value[:, j], error[:, j], ax=ax,
                    title=f"albedo ρ(wo) = ∫ f_r cos θi dwi, wo at φ = {phi:g}°")
    out = [p.figure(fig, "albedo.png", "Directional albedo per channel (red, green, blue) "
                    "against θo, with the provider's error bounds, for wo along the warp "
                    "(φ = 0) and the weft (φ = 90°); the dotted line is 1.")]
    rows = [[t, phi] + list(value[i, j]) + list(error[i, j])
            for i, t in enumerate(theta) for j, phi in enumerate(ALBEDO_PHI)]
    link = p.csv("albedo.csv", ["theta_deg", "phi_deg", "albedo_r", "albedo_g", "albedo_b",
                                "error_r", "error_g", "error_b"], rows)
    th, ph, ch = e.max_where
    out.append(html("<p>Largest albedo {:.4f} ± {:.1e} ({} channel, θ = {:g}°, φ = {:g}°): "
                    "it {}. Data: {}</p>", e.max, e.max_error, ch, th, ph, _verdict(e), link))
    return Section(join(out), e)
