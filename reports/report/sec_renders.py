"""The "renders" section: the curtain and the cylinder, masking on and off, one exposure."""

from __future__ import annotations

import dataclasses
import io
from typing import Any

import matplotlib.image as mimage
import numpy as np

from reports.colour import luminance, to_srgb
from reports.render import render
from reports.report.folder import write_file
from reports.report.page import Page, figure_html
from reports.report.sec_figures import can_unmask
from reports.report.settings import Section

__all__ = ["RendersData", "RENDERS", "section_renders"]

#: Renders in the report: (file stem, scene, masking, caption).
RENDERS = (("curtain", "curtain", True, "curtain"),
           ("cylinder", "cylinder", True, "cylinder, masking on"),
           ("cylinder_nomask", "cylinder", False, "cylinder, masking off"))


@dataclasses.dataclass(frozen=True)
class RendersData:
    """The renders of one fabric.

    Attributes
    ----------
    exposure_reference : float
        The 99th percentile of the first render's non-zero luminance; every render of the
        fabric is exposed so that it shows at 0.8.
    renders : dict
        File stem -> scene, masking, width, height, spp, exposure (stops), mean_luminance.
    """

    exposure_reference: float
    renders: dict

    def summary(self) -> dict[str, Any]:
        """``renders``: the exposure reference and each render's settings."""
        return {"renders": {"exposure_reference": self.exposure_reference, **self.renders}}


def _exposure_reference(img: np.ndarray) -> float:
    y = luminance(img)
    return float(np.percentile(y[y > 0], 99)) if np.any(y > 0) else 1.0


def _png(img: np.ndarray, exposure: float) -> bytes:
    png = (to_srgb(img, exposure=exposure) * 255.0 + 0.5).astype(np.uint8)
    buf = io.BytesIO()
    mimage.imsave(buf, png, format="png")
    return buf.getvalue()


def section_renders(p: Page) -> Section:
    """Each of :data:`RENDERS` (the no-masking one only for a BRDF that can unmask) as PNG."""
    width, height, spp = p.q["render"]
    out, stats, ref = [], {}, None
    for stem, scene, masking, caption in RENDERS:
        fab = p.fabric
        if not masking:
            if not can_unmask(fab):
                continue
            fab = fab.replace(masking=False)
        img = np.asarray(render(scene, fab, width=width, height=height, spp=spp,
                                progress=False), dtype=np.float64)
        if ref is None:  # one exposure for all renders of a fabric
            ref = _exposure_reference(img)
        exposure = float(np.log2(0.8 / ref))
        write_file(p.path(f"render_{stem}.png"), _png(img, exposure))
        out.append(figure_html(p.rel(f"render_{stem}.png"),
                               f"{caption}, {width} × {height}, {spp} spp, exposure "
                               f"{exposure:+.1f} stops (sRGB via colour-science)"))
        stats[stem] = {"scene": scene, "masking": masking, "width": width, "height": height,
                       "spp": spp, "exposure": exposure,
                       "mean_luminance": float(luminance(img).mean())}
    return Section("".join(out), RendersData(ref, stats))
