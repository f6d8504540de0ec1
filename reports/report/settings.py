"""What a report holds: its sections in page order, their titles, the resolutions per quality,
and the two small types every section shares (:class:`Section`, :class:`Unavailable`)."""

from __future__ import annotations

import dataclasses
from typing import Any, Protocol, runtime_checkable

import numpy as np

from reports.safehtml import Markup, text

__all__ = ["SECTIONS", "TITLES", "QUALITIES", "Section", "SectionData", "Unavailable"]

#: Per-fabric sections in page order.
SECTIONS = ("parameters", "lobes", "slices", "hemisphere", "masking", "energy", "reciprocity",
            "sanity", "renders", "fit")

TITLES = {
    "parameters": "Parameters", "lobes": "Lobes in the planes of incidence",
    "slices": "Slices (BRDF Explorer)", "hemisphere": "Hemisphere and 3-D lobe",
    "masking": "Shadowing and masking", "energy": "Energy: directional albedo",
    "reciprocity": "Reciprocity", "sanity": "Sanity: finite, non-negative f_r at the edges",
    "renders": "Renders", "fit": "Fitting results",
}

#: Resolutions per quality. "default" keeps plotting near 5 s a preset on 2 cores and renders
#: 448 x 252 at 16 samples a pixel (the sky on 4 of them on cloth: about the cost of 640 x
#: 360 at 4 spp with the sky on each); "high" is for publication (1280 x 720, 16 spp, finer
#: curves and images; several times slower); "fast" is for tests
#: and previews. Angles in degrees; render = (width, height, spp) of the built-in renderer,
#: render_mitsuba the same for Mitsuba (reports.report.sec_renders; its path tracing is
#: noisier per sample than the built-in's direct light, and a sample costs less once
#: LLVM has compiled the kernel, about 20-45 s per fabric, scene and size the first time, then
#: cached by Dr.Jit in ~/.drjit; None: the built-in renderer unless Mitsuba is asked for by
#: name, as "fast" does, where a compile would cost more than the renders); dpi of the PNG
#: figures.
#: The albedo angles end at 89° (as `microcyl energy`'s do): the reflectance of some presets
#: exceeds 1 only near grazing incidence; "default" samples both albedos every 7.5° and at 85°,
#: 87° and 89° (30 points in all: the cost of the one albedo every 3° before).
QUALITIES = {
    "default": dict(lobe=181, hemi=101, image=90, recip=45, lobe3d=(30, 60),
                    albedo_theta=np.r_[np.arange(0.0, 85.0, 7.5), 85.0, 87.0, 89.0],
                    render=(448, 252, 16),
                    render_mitsuba=(640, 360, 16), dpi=200),
    "high": dict(lobe=361, hemi=201, image=180, recip=90, lobe3d=(45, 90),
                 albedo_theta=np.r_[np.arange(0.0, 90.0, 1.5), 89.0], render=(1280, 720, 16),
                 render_mitsuba=(1280, 720, 16), dpi=200),
    "fast": dict(lobe=37, hemi=21, image=12, recip=8, lobe3d=(6, 10),
                 albedo_theta=np.array([0.0, 45.0, 85.0, 89.0]), render=(32, 18, 1),
                 render_mitsuba=None, dpi=50),
}


class Unavailable(Exception):
    """A section cannot be shown for this fabric (no fit results, no masking to switch off);
    the message says why and the page says "Not available"."""


@runtime_checkable
class SectionData(Protocol):
    """A section's data: what it adds to the fabric's entry of ``summary.json``."""

    def summary(self) -> dict[str, Any]:
        """Keys and plain values for the fabric's entry of ``summary.json``."""


@dataclasses.dataclass(frozen=True)
class Section:
    """What a section builder returns: its HTML fragment and its data (None: figures only).

    ``html`` is Markup (:mod:`reports.safehtml`); a plain ``str`` is taken as text and
    escaped, so a section can never put unescaped text on its page.

    Examples
    --------
    >>> Section(Markup("<p>hi</p>")).data is None
    True
    >>> Section("<p>hi</p>").html
    Markup('&lt;p&gt;hi&lt;/p&gt;')
    """

    html: Markup
    data: SectionData | None = None

    def __post_init__(self):
        object.__setattr__(self, "html", text(self.html))
