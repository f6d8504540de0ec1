"""The "renders" section: the curtain and the cylinder, masking on and off, exposed for the cloth.

The renders are Mitsuba 3's (:func:`reports.mitsuba.render.render_mitsuba`: path tracing, 8
bounces) where Mitsuba is installed with a usable LLVM (``llvm_ad_rgb``) and the fabric is a
:class:`brdf.Fabric`, else the built-in renderer's (:func:`reports.render.engine.render`: direct
light); each caption names its engine. The quality's ``render`` sets the built-in size and
spp, ``render_mitsuba`` Mitsuba's (None: the built-in renderer unless ``mitsuba`` is asked
for, at the built-in size); ``render_engine`` (``auto``, ``builtin``, ``mitsuba``) in the
quality dictionary overrides the choice. The built-in renderer samples the sky on
:data:`SKY_SPP` of each pixel's samples on cloth (every sample on the backdrop). Each scene is
exposed automatically for its cloth (:func:`reports.render.exposure.auto_exposure`: the 99th
percentile of the metered cloth's pixels shown at 0.9, the cylinder's side and not its cap,
the mask traced once per scene and size by :func:`reports.render.engine.cloth_coverage`); the
cylinder without masking takes the exposure of the cylinder with masking, so that the two
compare.
"""

from __future__ import annotations

import dataclasses
import functools
import io
from typing import Any

import matplotlib.image as mimage
import numpy as np

import brdf
from reports.mitsuba import render as mitsuba_render
from reports.colour import luminance, to_srgb
from reports.render.exposure import TARGET, auto_exposure
from reports.mitsuba.render import render_mitsuba
from reports.render.engine import cloth_coverage, render
from reports.report.folder import write_file
from reports.report.markup import join
from reports.report.page import Page, figure_html
from reports.report.sec_figures import can_unmask
from reports.report.settings import Section

__all__ = ["RendersData", "RENDERS", "ENGINES", "section_renders", "render_engine", "png_bytes",
           "check_engine"]

#: Renders in the report: (file stem, scene, masking, caption).
RENDERS = (("curtain", "curtain", True, "curtain"),
           ("cylinder", "cylinder", True, "cylinder, masking on"),
           ("cylinder_nomask", "cylinder", False, "cylinder, masking off"))
#: The report's render engines and how each caption names them.
ENGINES = {"builtin": "built-in renderer (direct light, MIS sky)",
           "mitsuba": "Mitsuba 3 llvm_ad_rgb (path tracing, 8 bounces)"}
#: What a scene's exposure meters, where not all its cloth (reports.render.pixelsamples.metered).
METERED = {"cylinder": "cylinder's side (not its cap, seen edge-on)"}
#: Sky samples a pixel on cloth in the built-in renderer's renders (at most spp).
SKY_SPP = 4


@dataclasses.dataclass(frozen=True)
class RendersData:
    """The renders of one fabric.

    Attributes
    ----------
    exposure_reference : float
        The first render's exposure reference: the 99th percentile of max(R, G, B) over its
        cloth's pixels, shown at 0.9.
    thumbnail : ndarray or None
        The first render's linear image (the overview's card).
    renders : dict
        File stem -> scene, masking, engine, width, height, spp, sky_spp (built-in),
        exposure (stops), exposure_reference, mean_luminance.
    """

    exposure_reference: float
    renders: dict
    #: The first render's linear RGB (height, width, 3) float32, for the overview's card
    #: (re-exposed there with the other fabrics' at one exposure); not in the summary.
    thumbnail: Any = dataclasses.field(default=None, compare=False, repr=False)

    def summary(self) -> dict[str, Any]:
        """``renders``: the exposure reference and each render's settings."""
        return {"renders": {"exposure_reference": self.exposure_reference, **self.renders}}


@functools.lru_cache(maxsize=8)
def _cloth_mask(scene: str, width: int, height: int) -> np.ndarray:
    """The cloth's coverage of a scene at a size: the same for every fabric."""
    return cloth_coverage(scene, width, height)


def png_bytes(img: np.ndarray, exposure: float) -> bytes:
    """An sRGB PNG of a linear RGB image at ``exposure`` stops (colour-science's sRGB)."""
    return _png(img, exposure)


def _png(img: np.ndarray, exposure: float) -> bytes:
    png = (to_srgb(img, exposure=exposure) * 255.0 + 0.5).astype(np.uint8)
    buf = io.BytesIO()
    mimage.imsave(buf, png, format="png")
    return buf.getvalue()


def check_engine(choice: str) -> None:
    """Refuse an unknown engine, or ``mitsuba`` where Mitsuba cannot run llvm_ad_rgb
    (ValueError, before any render)."""
    if choice not in ("auto", *ENGINES):
        raise ValueError(f"render engine {choice!r} is unknown; choose auto, "
                         f"{', '.join(ENGINES)}")
    if choice == "mitsuba" and not _mitsuba_usable():
        raise ValueError("render engine mitsuba needs mitsuba with a usable LLVM "
                         "(llvm_ad_rgb)")


def _mitsuba_usable() -> bool:
    return mitsuba_render.have_mitsuba() and mitsuba_render.variant_works("llvm_ad_rgb")[0]


def render_engine(fabric, choice: str = "auto") -> str:
    """The engine of a fabric's renders: ``choice``, or for ``auto`` Mitsuba where it is
    installed, llvm_ad_rgb runs and ``fabric`` is a :class:`brdf.Fabric`, else the built-in.

    Raises
    ------
    ValueError
        An unknown choice (:func:`check_engine`), or ``mitsuba`` where it cannot render this
        fabric.
    """
    check_engine(choice)
    is_fabric = isinstance(fabric, brdf.Fabric)
    if choice == "mitsuba" and not is_fabric:
        raise ValueError("render engine mitsuba renders a brdf.Fabric only")
    if choice == "auto":
        return mitsuba_render.auto_engine(fabric)
    return choice


def _render(engine, scene, fab, width, height, spp):
    if engine == "mitsuba":
        img = render_mitsuba(scene, fab, width=width, height=height, spp=spp,
                             variant="llvm_ad_rgb", progress=False)
    else:
        img = render(scene, fab, width=width, height=height, spp=spp, progress=False,
                     sky_spp=min(spp, SKY_SPP))
    return np.asarray(img, dtype=np.float64)


def section_renders(p: Page) -> Section:
    """Each of :data:`RENDERS` (the no-masking one only for a BRDF that can unmask) as PNG."""
    choice = p.q.get("render_engine", "auto")
    if choice == "auto" and p.q.get("render_mitsuba") is None:
        choice = "builtin"
    engine = render_engine(p.fabric, choice)
    width, height, spp = p.q.get("render_mitsuba" if engine == "mitsuba" else "render") \
        or p.q["render"]
    out, stats, per_scene, thumb = [], {}, {}, None
    for stem, scene, masking, caption in RENDERS:
        fab = p.fabric
        if not masking:
            if not can_unmask(fab):
                continue
            fab = fab.replace(masking=False)
        img = _render(engine, scene, fab, width, height, spp)
        if thumb is None:
            thumb = img.astype(np.float32)
        if scene not in per_scene:  # one exposure per scene: masking on and off compare
            per_scene[scene] = auto_exposure(img, _cloth_mask(scene, width, height))
        expo = per_scene[scene]
        write_file(p.path(f"render_{stem}.png"), _png(img, expo.stops))
        sky = f" (sky: {min(spp, SKY_SPP)} on cloth)" if engine == "builtin" else ""
        metered = METERED.get(scene, "cloth")
        out.append(figure_html(
            p.rel(f"render_{stem}.png"),
            f"{caption}, {ENGINES[engine]}, {width} × {height}, {spp} spp{sky}, exposure "
            f"{expo.stops:+.1f} stops ({_exposure_words(expo, metered)}; sRGB via "
            f"colour-science)"))
        stats[stem] = {"scene": scene, "masking": masking, "engine": engine,
                       "width": width, "height": height, "spp": spp,
                       "sky_spp": min(spp, SKY_SPP) if engine == "builtin" else None,
                       "exposure": expo.stops, "exposure_reference": expo.reference,
                       "mean_luminance": float(luminance(img).mean())}
    first = next(iter(per_scene.values()), None)
    return Section(join(out), RendersData(first.reference if first else 1.0, stats, thumb))


def _exposure_words(expo, metered="cloth") -> str:
    """How the exposure was chosen, as the caption says it; ``metered``: what it metered."""
    if expo.cloth:
        return f"automatic: the 99th percentile of the {metered} shown at {TARGET:g}"
    return f"automatic: the image's 99th percentile shown at {TARGET:g}, no cloth in view"
