"""A render written as image files: what ``microcyl render`` does once its arguments are
checked. The built-in engine (:func:`reports.render.engine.render`) or Mitsuba 3
(:func:`reports.mitsuba.render.render_mitsuba`) renders the scene with the cloth's coverage;
the PNG's exposure is automatic from the cloth's pixels (:func:`reports.render.exposure.
auto_exposure`) or given in stops; ``out.exr`` gets the linear float32 image with the exposure
in its header and an sRGB PNG beside it, ``out.png`` the PNG alone (each written atomically),
and beside either the scene file ``out.scene.json`` that renders it again
(:mod:`reports.render.scenefile`).
"""

from __future__ import annotations

from pathlib import Path

from reports.mitsuba.render import render_mitsuba
from reports.render.engine import render
from reports.render.exposure import Exposure, auto_exposure, exr_attributes
from reports.render.imageio import write_exr, write_png
from reports.render.scenefile import write_scene_file

__all__ = ["render_to_files", "render_image"]


def render_image(scene, fabric, *, engine: str = "builtin", width: int, height: int, spp: int,
                 seed: int = 0, workers=None, progress=False, variant=None, max_depth=None,
                 mask=False):
    """The linear RGB image (H, W, 3) of ``scene`` with cloth of ``fabric`` in ``engine``
    (and the cloth's coverage with ``mask=True``); the arguments as :func:`render_to_files`.
    """
    if engine == "mitsuba":
        return render_mitsuba(scene, fabric, width=width, height=height, spp=spp, seed=seed,
                              max_depth=max_depth, variant=variant, workers=workers,
                              progress=progress, mask=mask)
    return render(scene, fabric, width=width, height=height, spp=spp, seed=seed,
                  progress=progress, workers=workers, mask=mask)


def render_to_files(scene, fabric, out, *, stops=None, engine: str = "builtin", width: int,
                    height: int, spp: int, seed: int = 0, workers=None, progress=False,
                    variant=None, max_depth=None, scene_file=True) -> tuple[Exposure, list[Path]]:
    """Render ``scene`` with cloth of ``fabric`` and write the images (module notes).

    Parameters
    ----------
    scene : reports.render.scenes.Scene
    fabric : brdf.Fabric or any BRDF (the built-in engine)
    out : path
        ``*.exr`` (and the PNG beside it) or ``*.png``.
    stops : float, optional
        The PNG's exposure in stops; automatic when None.
    engine : {"builtin", "mitsuba"}
        Checked by the caller (``microcyl render --engine``).
    width, height, spp, seed, workers, progress
        As the engine takes them (pixels, samples per pixel).
    variant, max_depth
        Mitsuba's variant and longest path (``engine="mitsuba"`` only).
    scene_file : bool
        Also write ``out.scene.json`` (:func:`reports.render.scenefile.write_scene_file`).

    Returns
    -------
    (Exposure, list of Path)
        The PNG's exposure and the files written.
    """
    image, cloth = render_image(scene, fabric, engine=engine, width=width, height=height,
                                spp=spp, seed=seed, workers=workers, progress=progress,
                                variant=variant, max_depth=max_depth, mask=True)
    expo = auto_exposure(image, cloth) if stops is None else Exposure(stops)
    out = Path(out)
    if out.suffix.lower() == ".exr":
        written = [write_exr(out, image, exr_attributes(expo)),
                   write_png(out.with_suffix(".png"), image, expo.stops)]
    else:
        written = [write_png(out, image, expo.stops)]
    if scene_file:
        written.append(write_scene_file(
            out, scene, fabric, engine=engine, width=width, height=height, spp=spp, seed=seed,
            exposure_stops=expo.stops, variant=variant, max_depth=max_depth))
    return expo, written
