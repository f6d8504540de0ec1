"""Images of a known fabric, for checking ``microcyl fit-images`` against the truth.

:func:`write_truth_images` renders a fabric in the ``cylinder`` and ``curtain`` scenes, each
lit from three directions (the scene's key light moved; no sky, so that every pixel's light is
the key light's), writes each image's scene file, adds camera noise (Gaussian of variance
``shot * value + read^2``, seeded) to the EXR, and returns the image paths. The scene files
record the renders' seeds; a fit renders with others.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from reports.render.files import render_image
from reports.render.imageio import write_exr
from reports.render.scenefile import write_scene_file
from reports.render.scenes import make_scene

__all__ = ["write_truth_images", "LIGHTS"]

#: The key light's three positions (scene units): the scene's own, high at the left front;
#: high at the right front; low at the right (grazing the cloth).
LIGHTS = ((-1.6, 2.8, 2.2), (1.9, 2.4, 2.0), (2.6, 0.9, 0.9))


def write_truth_images(out_dir, fabric, *, width: int = 128, height: int = 72, spp: int = 16,
                       shot: float = 1e-4, read: float = 0.002, seed: int = 0,
                       scenes=("cylinder", "curtain"), engine: str = "builtin",
                       variant: str | None = None) -> list[Path]:
    """Render, add noise, write ``<scene><k>.exr`` and ``.scene.json``; return the EXR paths.

    ``engine="mitsuba"`` renders in Mitsuba 3's ``variant`` with paths of 2 vertices (direct
    light alone, as the built-in engine).

    Examples
    --------
    >>> import tempfile, brdf
    >>> paths = write_truth_images(tempfile.mkdtemp(), brdf.fabric("velvet"), width=8,
    ...                            height=6, spp=1, scenes=("cylinder",))
    >>> [p.name for p in paths]
    ['cylinder0.exr', 'cylinder1.exr', 'cylinder2.exr']
    """
    out_dir = Path(out_dir)
    rng = np.random.default_rng(seed)
    paths = []
    for name in scenes:
        base = make_scene(name).replace(environment=None)
        for k, pos in enumerate(LIGHTS):
            scene = base.replace(light=dataclasses.replace(base.light, position=pos))
            s = seed + k
            depth = 2 if engine == "mitsuba" else None
            img = render_image(scene, fabric, engine=engine, width=width, height=height,
                               spp=spp, seed=s, workers=1, variant=variant,
                               max_depth=depth).astype(float)
            img = img + rng.normal(0.0, np.sqrt(shot * np.maximum(img, 0.0) + read ** 2))
            path = out_dir / f"{name}{k}.exr"
            write_exr(path, img)
            write_scene_file(path, scene, fabric, engine=engine, width=width,
                             height=height, spp=spp, seed=s, exposure_stops=None,
                             variant=variant, max_depth=depth)
            paths.append(path)
    return paths
