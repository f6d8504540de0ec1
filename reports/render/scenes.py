"""Scene description for the cloth renderer: primitives, cameras, lights and named scenes.

The primitives (:mod:`reports.render.primitives`), cameras (:mod:`reports.render.cameras`) and lights
(:mod:`reports.render.lights`) are re-exported here. Every primitive answers two vectorized
questions: where does a batch of rays first hit it (:meth:`intersect`), and what is the
shading frame at given points on it (:meth:`frame`). The frame is the surface normal ``n``
and the warp tangent; the renderer completes it with ``y = n x warp`` so that local
coordinates are (x = warp, y = n x warp, z = n), the frame of :meth:`brdf.Fabric.eval`.

World axes: +y is up.  Lengths are in arbitrary scene units (metres, say); point-light
intensities in W/sr (any consistent radiometric unit), so that radiance comes out in
W / (m^2 sr).

Named scenes (:data:`SCENES`, built by :func:`make_scene`):

``curtain``
    A drape hung vertically: the surface ``z = a(y) sin(k x)`` over a rectangle of the
    x-y plane, the fold depth ``a(y)`` growing from top to bottom.  Warp tangent: the
    horizontal direction of the cloth, ``dP/dx`` normalized (it follows the width, across
    the folds); ``n x warp`` then points up the cloth, so the weft runs vertically.
    A grey floor and back wall give context.
``cylinder``
    An upright cylinder (axis +y) covered in fabric, standing on a grey floor.  Side: warp
    around the cylinder (the azimuthal direction), so ``n x warp`` runs along the axis.
    Caps: warp along +x everywhere (:attr:`Cylinder.cap_warp`), a field without the
    singular centre of a tangential warp, whose anisotropic highlight would show as
    pie-shaped wedges.

The curtain and the cylinder are also lit by a dim sky
(:class:`reports.render.envlight.EnvironmentLight`, sampled by MIS of a table of the fabric's
f_r cos and cosine directions), so their shadows are not black; the sphere and the patch have
the key light alone.

``sphere``
    The lit sphere of Disney's BRDF Explorer: a unit sphere on black, lit by one point
    light from the upper left front.  Warp along the lines of latitude (east, about the
    vertical +y axis); ``n x warp`` points north along the meridians.  At the poles the warp
    falls back to +x.
``patch``
    A flat square of cloth in the x-y plane (n = +z, warp = +x), filling the view of an
    orthographic camera, under a directional light: every pixel shows the same
    ``f_r(wi, wo) E cos(theta_i)``.  The test scene; its normal, warp, view and light
    directions can be changed.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from reports.render.cameras import OrthographicCamera, PinholeCamera
from reports.render.envlight import EnvironmentLight
from reports.render.lights import DirectionalLight, PointLight
from reports.render.primitives import Curtain, Cylinder, Plane, Rectangle, Sphere
from reports.render.vec3 import unit as _unit

__all__ = [
    "Rectangle", "Sphere", "Cylinder", "Curtain", "Plane",
    "PinholeCamera", "OrthographicCamera", "PointLight", "DirectionalLight", "EnvironmentLight",
    "Scene", "SCENES", "make_scene",
]


@dataclass(frozen=True)
class Scene:
    """Primitives, a camera and a light."""

    primitives: tuple
    camera: object
    light: object
    name: str = ""
    scale: float = 1.0  # typical size, sets ray epsilons
    environment: EnvironmentLight | None = None   # the sky; None: black (key light only)

    def replace(self, **changes):
        """A copy with some fields changed."""
        return dataclasses.replace(self, **changes)


def _curtain():
    return Scene(
        primitives=(Curtain(), Plane(axis=1, offset=0.0, albedo=0.18),
                    Plane(axis=2, offset=-0.8, albedo=0.18)),
        camera=PinholeCamera(position=(0.6, 1.4, 4.2), target=(0.0, 1.15, 0.0), fov=38.0),
        light=PointLight(position=(-1.8, 3.0, 2.6), intensity=24.0, target=(0.0, 1.0, 0.0)),
        name="curtain", scale=2.4, environment=EnvironmentLight())


def _cylinder():
    return Scene(
        primitives=(Cylinder(center=(0.0, 0.0, 0.0), radius=0.55, height=1.2),
                    Plane(axis=1, offset=0.0, albedo=0.18)),
        camera=PinholeCamera(position=(0.0, 1.7, 3.4), target=(0.0, 0.55, 0.0), fov=36.0),
        light=PointLight(position=(-1.6, 2.8, 2.2), intensity=14.0, target=(0.0, 0.6, 0.0)),
        name="cylinder", scale=1.2, environment=EnvironmentLight())


def _sphere():
    return Scene(
        primitives=(Sphere(center=(0.0, 0.0, 0.0), radius=1.0),),
        camera=PinholeCamera(position=(0.0, 0.0, 4.5), target=(0.0, 0.0, 0.0), fov=30.0),
        light=PointLight(position=(-2.0, 2.0, 5.0), intensity=30.0),
        name="sphere", scale=1.0)


def _patch(normal=(0.0, 0.0, 1.0), warp=(1.0, 0.0, 0.0), view=(0.0, 0.0, 1.0),
           light=(0.0, 0.0, 1.0), irradiance=1.0, half_size=50.0):
    """The flat-patch scene: a large cloth square, orthographic camera along ``-view``."""
    view = _unit(view)
    up = (0.0, 1.0, 0.0) if abs(view[1]) < 0.9 else (0.0, 0.0, 1.0)
    return Scene(
        primitives=(Rectangle(normal=normal, warp=warp, half_size=(half_size, half_size)),),
        camera=OrthographicCamera(position=tuple(3.0 * view), target=(0.0, 0.0, 0.0),
                                  up=up, extent=2.0),
        light=DirectionalLight(direction=light, irradiance=irradiance),
        name="patch", scale=1.0)


#: Scene name -> builder (no arguments).
SCENES = {"curtain": _curtain, "cylinder": _cylinder, "sphere": _sphere, "patch": _patch}


def make_scene(name: str, **kwargs) -> Scene:
    """Build a named scene.

    Parameters
    ----------
    name : str
        One of :data:`SCENES`: ``curtain``, ``cylinder``, ``sphere``, ``patch``.
    **kwargs
        Passed to the builder (only ``patch`` takes any: ``normal``, ``warp``, ``view``,
        ``light`` (toward the light), ``irradiance`` (W/m^2), ``half_size``).

    Raises
    ------
    ValueError
        For an unknown name.

    Examples
    --------
    >>> make_scene("cylinder").primitives[0].radius
    0.55
    >>> make_scene("teapot")
    Traceback (most recent call last):
    ...
    ValueError: scene 'teapot' is unknown; choose one of curtain, cylinder, sphere, patch
    """
    if name not in SCENES:
        raise ValueError(f"scene {name!r} is unknown; choose one of {', '.join(SCENES)}")
    return SCENES[name](**kwargs)
