"""A render that describes itself: the scene file ``IMAGE.scene.json`` beside each image.

``microcyl render`` writes, beside ``out.exr`` (or ``out.png``), ``out.scene.json``: everything
needed to render the same image again (schema ``microcyl-scene``, version
:data:`SCHEMA_VERSION`)::

    {"schema": "microcyl-scene", "schema_version": 1, "name": "cylinder", "scale": 1.2,
     "geometry": [{"type": "Cylinder", "center": [0, 0, 0], "radius": 0.55, ...}, ...],
     "camera": {"type": "PinholeCamera", "position": [...], "target": [...], "up": [...],
                "fov": 36.0},
     "light": {"type": "PointLight", "position": [...], "intensity": 14.0, "radius": 0.0,
               "target": [...]},
     "environment": {"zenith": [r, g, b], "horizon": [r, g, b]} or null,
     "render": {"engine": "builtin", "integrator": "direct", "width": 128, "height": 72,
                "spp": 16, "seed": 0, "variant": null, "max_depth": null,
                "exposure_stops": 2.1},
     "fabric": {the microcylinder plugin's dictionary, every parameter spelled out}
               or null (a measured table: give the fabric again)}

Lengths in scene units, intensities in W/sr, irradiances in W/m^2, angles in degrees (``fov``),
the fabric as :func:`analysis.fabricfile.plugin_dict` writes it. ``integrator`` is ``direct``
(the built-in engine: the key light and the sky, no bounces) or ``path`` (Mitsuba's path tracer,
``max_depth`` long). A scene file comes from others: :func:`read_scene_file` reads at most
:data:`MAX_BYTES`, and every field is checked (its type, range and size) before any work, with
one line naming the file, the field, the value and what is allowed.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import brdf
from analysis.fabricfile import fabric_from_dict, plugin_dict
from gonio.atomic import atomic_write
from gonio.jsonplain import plain
from gonio.safeopen import read_text
from gonio.statefields import loads_json
from reports.render.cameras import OrthographicCamera, PinholeCamera
from reports.render.checks import check_size
from reports.render.envlight import EnvironmentLight
from reports.render.lights import DirectionalLight, PointLight
from reports.render.primitives import Curtain, Cylinder, Plane, Rectangle, Sphere
from reports.render.scenes import Scene

__all__ = ["SceneFile", "scene_file_path", "scene_dict", "scene_from_dict", "write_scene_file",
           "read_scene_file", "SCHEMA", "SCHEMA_VERSION", "MAX_BYTES", "MAX_PRIMITIVES"]

SCHEMA = "microcyl-scene"
SCHEMA_VERSION = 1
#: Largest scene file read (bytes); one of a named scene is about 3 KB.
MAX_BYTES = 1 << 18
#: Most primitives a scene file may hold.
MAX_PRIMITIVES = 64
#: Largest magnitude of any number in a scene file.
MAX_MAGNITUDE = 1e6
#: The types each part of a scene may name.
PRIMITIVES = {c.__name__: c for c in (Rectangle, Plane, Sphere, Cylinder, Curtain)}
CAMERAS = {c.__name__: c for c in (PinholeCamera, OrthographicCamera)}
LIGHTS = {c.__name__: c for c in (PointLight, DirectionalLight)}
ENGINES = ("builtin", "mitsuba")
#: Field -> (lowest, highest) where a field's range is narrower than any finite number.
RANGES = {"radius": (0.0, MAX_MAGNITUDE), "height": (1e-9, MAX_MAGNITUDE),
          "half_size": (1e-9, MAX_MAGNITUDE), "width": (1e-9, MAX_MAGNITUDE),
          "extent": (1e-9, MAX_MAGNITUDE), "fov": (1e-3, 179.0), "albedo": (0.0, 1.0),
          "intensity": (0.0, MAX_MAGNITUDE), "irradiance": (0.0, MAX_MAGNITUDE),
          "zenith": (0.0, MAX_MAGNITUDE), "horizon": (0.0, MAX_MAGNITUDE),
          "axis": (0, 2), "sign": (-1.0, 1.0), "metered_parts": (0, 8), "folds": (0.0, 1e3),
          "top": (0.0, 1.0), "scale": (1e-6, MAX_MAGNITUDE)}
MATERIALS = ("cloth", "diffuse")


@dataclasses.dataclass(frozen=True)
class SceneFile:
    """A scene file read: the scene, the fabric (None for a measured table) and the render's
    settings (``engine``, ``width``, ``height``, ``spp``, ``seed``, ``variant``,
    ``max_depth``, ``exposure_stops``)."""

    scene: Scene
    fabric: brdf.Fabric | None
    settings: dict


def scene_file_path(image) -> Path:
    """``out.scene.json`` for ``out.exr`` or ``out.png``.

    Examples
    --------
    >>> scene_file_path("renders/cyl.exr").as_posix()
    'renders/cyl.scene.json'
    """
    image = Path(image)
    return image.with_name(image.stem + ".scene.json")


def _part(obj) -> dict:
    return {"type": type(obj).__name__, **plain(dataclasses.asdict(obj))}


def scene_dict(scene: Scene, fabric, *, engine: str, width: int, height: int, spp: int,
               seed: int, exposure_stops: float | None, variant=None, max_depth=None) -> dict:
    """The scene file's document (module notes) of a render.

    Examples
    --------
    >>> from reports.render.scenes import make_scene
    >>> d = scene_dict(make_scene("cylinder"), brdf.fabric("velvet"), engine="builtin",
    ...                width=64, height=36, spp=4, seed=1, exposure_stops=0.5)
    >>> d["geometry"][0]["type"], d["camera"]["fov"], d["fabric"]["fabric"]
    ('Cylinder', 36.0, 'velvet')
    >>> scene_from_dict(d).scene == make_scene("cylinder")
    True
    """
    env = scene.environment
    return {
        "schema": SCHEMA, "schema_version": SCHEMA_VERSION, "name": scene.name,
        "scale": float(scene.scale), "geometry": [_part(p) for p in scene.primitives],
        "camera": _part(scene.camera), "light": _part(scene.light),
        "environment": None if env is None else plain(dataclasses.asdict(env)),
        "render": {"engine": engine, "integrator": "path" if engine == "mitsuba" else "direct",
                   "width": int(width), "height": int(height), "spp": int(spp),
                   "seed": int(seed), "variant": variant, "max_depth": max_depth,
                   "exposure_stops": None if exposure_stops is None else float(exposure_stops)},
        "fabric": plugin_dict(fabric) if isinstance(fabric, brdf.Fabric) else None}


def write_scene_file(image, scene, fabric, **settings) -> Path:
    """Write :func:`scene_dict` beside ``image`` (atomically); return its path."""
    path = scene_file_path(image)
    with atomic_write(path, "w") as fh:
        json.dump(scene_dict(scene, fabric, **settings), fh, indent=1)
        fh.write("\n")
    return path


# ---------------------------------------------------------------------------- reading
def _number(where, value, lo=-MAX_MAGNITUDE, hi=MAX_MAGNITUDE, integer=False):
    kind = "an integer" if integer else "a number"
    ok = (not isinstance(value, bool) and isinstance(value, int if integer else (int, float))
          and math.isfinite(value) and lo <= value <= hi)
    if not ok:
        raise ValueError(f"{where} = {str(value)[:60]!r}: must be {kind} from {lo:g} to {hi:g}")
    return int(value) if integer else float(value)


def _value(where, key, value, default):
    """``value`` checked against the type (and length) of the field's ``default``."""
    lo, hi = RANGES.get(key, (-MAX_MAGNITUDE, MAX_MAGNITUDE))
    if isinstance(default, str):
        if key != "material" or value not in MATERIALS:
            raise ValueError(f"{where} = {str(value)[:60]!r}: must be one of "
                             f"{', '.join(MATERIALS)}")
        return value
    if isinstance(default, tuple) or (key == "intensity" and isinstance(value, list)):
        size = len(default) if isinstance(default, tuple) else 3
        if not isinstance(value, list) or len(value) not in ((size,) if key != "metered_parts"
                                                             else range(0, 9)):
            raise ValueError(f"{where} = {str(value)[:60]!r}: must be a list of {size} numbers")
        integer = key == "metered_parts"
        return tuple(_number(f"{where}[{i}]", v, lo, hi, integer) for i, v in enumerate(value))
    return _number(where, value, lo, hi, integer=isinstance(default, int))


def _dataclass(where, doc, types):
    """An instance of the type ``doc["type"]`` names (one of ``types``), fields checked."""
    if not isinstance(doc, dict):
        raise ValueError(f"{where}: must be an object with a \"type\" of {', '.join(types)}")
    cls = types.get(doc.get("type")) if isinstance(doc.get("type"), str) else None
    if cls is None:
        raise ValueError(f"{where}.type = {str(doc.get('type'))[:60]!r}: must be one of "
                         f"{', '.join(types)}")
    return _fields(where, {k: v for k, v in doc.items() if k != "type"}, cls)


def _fields(where, doc, cls):
    if not isinstance(doc, dict):
        raise ValueError(f"{where}: must be an object")
    fields = {f.name: f.default for f in dataclasses.fields(cls)}
    unknown = sorted(set(doc) - set(fields))
    if unknown:
        raise ValueError(f"{where}: unknown field {unknown[0][:60]!r}; a {cls.__name__} has "
                         f"{', '.join(fields)}")
    obj = cls(**{k: _value(f"{where}.{k}", k, v, fields[k]) for k, v in doc.items()})
    if isinstance(obj, Curtain) and not obj.y1 > obj.y0:
        raise ValueError(f"{where}: y1 = {obj.y1:g} must be above y0 = {obj.y0:g}")
    return obj


def _settings(where, doc) -> dict:
    keys = ("engine", "integrator", "width", "height", "spp", "seed", "variant", "max_depth",
            "exposure_stops")
    if not isinstance(doc, dict) or sorted(set(doc) - set(keys)):
        raise ValueError(f"{where}: must be an object of the fields {', '.join(keys)}")
    out = {"engine": doc.get("engine", "builtin")}
    if out["engine"] not in ENGINES:
        raise ValueError(f"{where}.engine = {str(out['engine'])[:60]!r}: must be one of "
                         f"{', '.join(ENGINES)}")
    for key in ("width", "height", "spp"):
        out[key] = _number(f"{where}.{key}", doc.get(key), 1, 4096, integer=True)
    try:
        check_size(out["width"], out["height"], out["spp"])
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    out["seed"] = _number(f"{where}.seed", doc.get("seed", 0), 0, 2 ** 63 - 1, integer=True)
    variant = doc.get("variant")
    if variant is not None and not (isinstance(variant, str) and len(variant) <= 40
                                    and out["engine"] == "mitsuba"):
        raise ValueError(f"{where}.variant = {str(variant)[:60]!r}: must be null, or a "
                         f"Mitsuba variant name with engine mitsuba")
    out["variant"] = variant
    depth = doc.get("max_depth")
    if depth is not None and out["engine"] == "builtin":
        raise ValueError(f"{where}.max_depth: must be null with engine builtin")
    out["max_depth"] = None if depth is None else _number(f"{where}.max_depth", depth, -1,
                                                          1024, integer=True)
    stops = doc.get("exposure_stops")
    out["exposure_stops"] = None if stops is None else _number(f"{where}.exposure_stops",
                                                               stops, -64, 64)
    return out


def scene_from_dict(doc, where: str = "scene file") -> SceneFile:
    """The :class:`SceneFile` of a scene file's document, every field checked.

    Raises
    ------
    ValueError
        One line naming ``where``, the field, its value and what is allowed.

    Examples
    --------
    >>> scene_from_dict({"schema": "microcyl-scene", "schema_version": 1, "geometry": []})
    Traceback (most recent call last):
    ...
    ValueError: scene file: geometry must be a list of 1 to 64 primitives
    """
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
        raise ValueError(f"{where}: not a microcyl scene file (no \"schema\": \"{SCHEMA}\")")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise ValueError(f"{where}: schema_version {str(doc.get('schema_version'))[:20]} "
                         f"is not {SCHEMA_VERSION}, the version this microcyl reads")
    known = {"schema", "schema_version", "name", "scale", "geometry", "camera", "light",
             "environment", "render", "fabric"}
    extra = sorted(set(doc) - known)
    if extra:
        raise ValueError(f"{where}: unknown field {extra[0][:60]!r}; valid: {', '.join(known)}")
    geometry = doc.get("geometry")
    if not isinstance(geometry, list) or not 1 <= len(geometry) <= MAX_PRIMITIVES:
        raise ValueError(f"{where}: geometry must be a list of 1 to {MAX_PRIMITIVES} primitives")
    prims = tuple(_dataclass(f"{where}: geometry[{i}]", p, PRIMITIVES)
                  for i, p in enumerate(geometry))
    name = doc.get("name", "")
    if not isinstance(name, str) or len(name) > 64:
        raise ValueError(f"{where}: name must be a string of at most 64 characters")
    env = doc.get("environment")
    scene = Scene(primitives=prims, camera=_dataclass(f"{where}: camera", doc.get("camera"),
                                                      CAMERAS),
                  light=_dataclass(f"{where}: light", doc.get("light"), LIGHTS), name=name,
                  scale=_number(f"{where}: scale", doc.get("scale", 1.0), *RANGES["scale"]),
                  environment=None if env is None else _fields(f"{where}: environment", env,
                                                               EnvironmentLight))
    fabric = doc.get("fabric")
    if fabric is not None:
        if not isinstance(fabric, dict):
            raise ValueError(f"{where}: fabric must be the microcylinder's dictionary or null")
        try:
            fabric = fabric_from_dict(fabric)
        except (ValueError, TypeError) as exc:
            raise ValueError(f"{where}: fabric: {exc}") from None
    return SceneFile(scene, fabric, _settings(f"{where}: render", doc.get("render")))


def read_scene_file(path) -> SceneFile:
    """Read and check a scene file (at most :data:`MAX_BYTES`, through :mod:`gonio.safeopen`)."""
    text = read_text(path, max_bytes=MAX_BYTES, what="scene file")
    return scene_from_dict(loads_json(text, path, "scene file"), where=str(path))
