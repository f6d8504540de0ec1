"""A render's arguments checked before any work: image size, samples, scene, fabric, workers.

Shared by the built-in renderer (:func:`reports.render.engine.render`) and the Mitsuba one
(:func:`reports.mitsuba.render.render_mitsuba`); cheap to import (no colour-science).
"""

from __future__ import annotations

import os

import numpy as np

import brdf
from brdf.protocols import BRDF
from reports.render.scenes import Scene, make_scene

__all__ = ["MAX_WIDTH", "MAX_HEIGHT", "MAX_SPP", "check_size", "resolve_fabric", "scene_of",
           "check_workers", "probe"]

#: Largest image the renderer accepts, pixels.
MAX_WIDTH, MAX_HEIGHT = 1280, 720
#: Most samples per pixel accepted.
MAX_SPP = 4096


def check_size(width, height, spp=16):
    """Raise ValueError unless ``0 < width <= 1280``, ``0 < height <= 720`` and
    ``0 < spp <= 4096`` (all integers).

    Examples
    --------
    >>> check_size(1280, 720, 16)
    >>> check_size(1920, 1080)
    Traceback (most recent call last):
    ...
    ValueError: width=1920 is beyond the limit: images are at most 1280 x 720 pixels
    """
    for name, value, top in (("width", width, MAX_WIDTH), ("height", height, MAX_HEIGHT)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise ValueError(f"{name}={value!r} must be an integer number of pixels")
        if value < 1:
            raise ValueError(f"{name}={value} must be at least 1 pixel")
        if value > top:
            raise ValueError(f"{name}={value} is beyond the limit: images are at most "
                             f"{MAX_WIDTH} x {MAX_HEIGHT} pixels")
    if isinstance(spp, bool) or not isinstance(spp, (int, np.integer)) or not 1 <= spp <= MAX_SPP:
        raise ValueError(f"spp={spp!r} must be an integer from 1 to {MAX_SPP}")


def resolve_fabric(fabric, **options):
    """A BRDF object from a preset name (through ``brdf.fabric``) or any object with ``.eval``.

    Parameters
    ----------
    fabric : str or object
        A name in ``brdf.PRESETS`` or an object whose ``eval(wi, wo)`` returns (..., 3) f_r.
    **options
        Passed to ``brdf.fabric`` with a name, or to ``fabric.replace`` with an object.

    Raises
    ------
    ValueError
        For an unknown name or an object without ``eval``.
    """
    if isinstance(fabric, str):
        return brdf.fabric(brdf.check_preset(fabric), **options)
    if not isinstance(fabric, BRDF):
        raise ValueError(f"fabric={fabric!r} must be a preset name or have an eval(wi, wo) method")
    if options:
        return fabric.replace(**options)
    return fabric


def scene_of(scene, light, camera) -> Scene:
    """The Scene to render: ``scene`` (a name or a Scene) with ``light``/``camera`` replaced."""
    if not isinstance(scene, Scene):
        if not isinstance(scene, str):
            raise ValueError(f"scene={scene!r} must be a scene name or a Scene")
        scene = make_scene(scene)
    if light is not None:
        scene = scene.replace(light=light)
    if camera is not None:
        scene = scene.replace(camera=camera)
    return scene


def check_workers(tile, workers) -> int:
    """Check ``tile``; return ``workers`` (default: the usable cores), checked."""
    if isinstance(tile, bool) or not isinstance(tile, (int, np.integer)) or tile < 1:
        raise ValueError(f"tile={tile!r} must be a positive integer")
    if workers is None:
        try:
            workers = len(os.sched_getaffinity(0))
        except AttributeError:  # pragma: no cover
            workers = os.cpu_count() or 1
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ValueError(f"workers={workers!r} must be a positive integer")
    return workers


def probe(fabric) -> None:
    """One tiny evaluation: a broken BRDF fails now, not after the pool starts."""
    z = np.array([[0.0, 0.0, 1.0]])
    probe = np.asarray(fabric.eval(z, z))
    if probe.shape != (1, 3):
        raise ValueError(f"fabric.eval returned shape {probe.shape} for one pair; (1, 3) expected")
