r"""glTF 2.0 (.gltf, .glb): a sphere with KHR_materials_sheen (Charlie) over a diffuse base.

The material (glTF 2.0 metallic-roughness, KhronosGroup/glTF specification 2.0, and the
extension KHR_materials_sheen, extensions/2.0/Khronos/KHR_materials_sheen/README.md):

- ``pbrMetallicRoughness.baseColorFactor`` = (base, 1): linear RGB, as glTF's factors are;
  ``metallicFactor`` 0 and ``roughnessFactor`` 1;
- ``KHR_materials_specular.specularFactor`` 0: the dielectric's specular lobe switched off, so
  the base is the Lambertian diffuse that :class:`brdf.baselines.Charlie` has;
- ``KHR_materials_sheen``: ``sheenColorFactor`` = sheen, ``sheenRoughnessFactor`` = roughness
  (the Charlie lobe, alpha = roughness^2, layered by the extension's albedo scaling
  1 - max(sheenColor) E).

The scene is one UV sphere (radius 1, :data:`SPHERE` rings and segments, positions, normals
and 16-bit indices in one buffer: a base64 data URI in a .gltf, the binary chunk of a .glb).
The projection's 95% intervals go in the material's ``extras``. :func:`read_gltf` reads the
first material back as a :class:`brdf.baselines.Charlie` (through
:func:`gonio.safeopen.read_bytes`); a material with textures, metalness, a specular lobe or
another extension that changes its reflection is refused.

Examples
--------
>>> from analysis.export.projection import Projection
>>> p = Projection("charlie", {"base": [0.1, 0.2, 0.3], "sheen": [0.5, 0.4, 0.3],
...                            "roughness": 0.6})
>>> doc, binary = gltf_document(p, "velvet")
>>> m = model_from_gltf(doc)
>>> m.name, m.roughness, tuple(m.sheen), tuple(m.base)
('charlie', 0.6, (0.5, 0.4, 0.3), (0.1, 0.2, 0.3))
>>> m2 = model_from_glb(glb_bytes(*gltf_document(p, "velvet", embed=False)))
>>> bool(m2.roughness == 0.6)
True
"""

from __future__ import annotations

import base64
import json
import math
import struct

import numpy as np

from analysis.export.target import Target
from brdf.baselines import Charlie
from gonio.atomic import atomic_write
from gonio.safeopen import read_bytes
from gonio.statefields import loads_json

__all__ = ["gltf_document", "glb_bytes", "model_from_gltf", "model_from_glb", "read_gltf",
           "GLTF", "SPHERE"]

#: The sample sphere's rings (latitude) and segments (longitude).
SPHERE = (24, 48)
#: Largest glTF read back (bytes).
MAX_GLTF_BYTES = 8 << 20
#: Extensions a read-back accepts (the others may change what the material reflects).
_ACCEPTED = {"KHR_materials_sheen", "KHR_materials_specular"}


def _sphere():
    rings, segs = SPHERE
    th = np.linspace(0.0, math.pi, rings + 1)
    ph = np.linspace(0.0, 2.0 * math.pi, segs + 1)
    T, P = np.meshgrid(th, ph, indexing="ij")
    pos = np.stack([np.sin(T) * np.cos(P), np.cos(T), -np.sin(T) * np.sin(P)], -1)
    pos = pos.reshape(-1, 3).astype(np.float32)
    idx = []
    for r in range(rings):
        for s in range(segs):
            a, b = r * (segs + 1) + s, (r + 1) * (segs + 1) + s
            if r > 0:
                idx.append((a, b, a + 1))
            if r < rings - 1:
                idx.append((a + 1, b, b + 1))
    return pos, np.array(idx, dtype=np.uint16).ravel()


def _material(projection, label: str) -> dict:
    v = projection.values
    mat = {"name": label,
           "pbrMetallicRoughness": {"baseColorFactor": [float(c) for c in v["base"]] + [1.0],
                                    "metallicFactor": 0.0, "roughnessFactor": 1.0},
           "extensions": {"KHR_materials_sheen": {
               "sheenColorFactor": [float(c) for c in v["sheen"]],
               "sheenRoughnessFactor": float(v["roughness"])},
               "KHR_materials_specular": {"specularFactor": 0.0}},
           "extras": {"microcyl": {"model": "charlie", "draws": projection.draws,
                                   "intervals_95": projection.intervals}}}
    return mat


def gltf_document(projection, label: str, embed: bool = True) -> tuple[dict, bytes]:
    """The glTF JSON document and its buffer's bytes for ``projection`` (a Charlie one);
    with ``embed`` the buffer is also in the document as a data URI (.gltf)."""
    pos, idx = _sphere()
    nrm = pos.copy()
    ibytes = idx.tobytes()
    ibytes += b"\0" * (-len(ibytes) % 4)
    data = pos.tobytes() + nrm.tobytes() + ibytes
    n = len(pos)
    buffer = {"byteLength": len(data)}
    if embed:
        buffer["uri"] = ("data:application/octet-stream;base64,"
                         + base64.b64encode(data).decode("ascii"))
    doc = {
        "asset": {"version": "2.0", "generator": "microcyl export"},
        "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_specular"],
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": label}],
        "meshes": [{"name": "sphere", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "materials": [_material(projection, label)],
        "buffers": [buffer],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": n * 12, "target": 34962},
            {"buffer": 0, "byteOffset": n * 12, "byteLength": n * 12, "target": 34962},
            {"buffer": 0, "byteOffset": n * 24, "byteLength": idx.size * 2, "target": 34963}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": int(idx.size),
             "type": "SCALAR"}],
    }
    return doc, data


def glb_bytes(doc: dict, data: bytes) -> bytes:
    """The binary glTF (.glb) of a document without a buffer URI and its buffer."""
    js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    js += b" " * (-len(js) % 4)
    data = data + b"\0" * (-len(data) % 4)
    total = 12 + 8 + len(js) + 8 + len(data)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(js), b"JSON")
            + js + struct.pack("<I4s", len(data), b"BIN\0") + data)


def _factor(value, key: str, n: int) -> list:
    if (not isinstance(value, list) or len(value) != n
            or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                       and math.isfinite(x) for x in value)):
        raise ValueError(f"{key}: {n} finite numbers expected; got {value!r:.60}")
    return [float(x) for x in value]


def _number(value, key: str) -> float:
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise ValueError(f"{key}: a finite number expected; got {value!r:.60}")
    return float(value)


def model_from_gltf(doc) -> Charlie:
    """The :class:`brdf.baselines.Charlie` of a glTF document's first material.

    Raises
    ------
    ValueError
        No material, a texture, metalness, a specular lobe (specularFactor not 0), another
        extension on the material, or values out of range (one line naming the field).
    """
    if not isinstance(doc, dict) or not isinstance(doc.get("materials"), list) \
            or not doc["materials"] or not isinstance(doc["materials"][0], dict):
        raise ValueError("materials: a list with at least one material expected")
    mat = doc["materials"][0]
    pbr = mat.get("pbrMetallicRoughness", {})
    ext = mat.get("extensions", {})
    if not isinstance(pbr, dict) or not isinstance(ext, dict):
        raise ValueError("materials[0]: pbrMetallicRoughness and extensions must be objects")
    other = sorted(set(ext) - _ACCEPTED)
    if other:
        raise ValueError(f"materials[0].extensions: {', '.join(map(ascii, other))[:80]} not "
                         f"read back (only {', '.join(sorted(_ACCEPTED))})")
    textures = [k for k in list(pbr) + list(ext.get("KHR_materials_sheen", {}))
                if k.endswith("Texture")]
    if textures:
        raise ValueError(f"materials[0]: textures ({', '.join(textures)[:60]}) are not read "
                         f"back: microcyl reads one uniform material")
    metal = _number(pbr.get("metallicFactor", 1.0), "materials[0].metallicFactor")
    spec = _number(ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0),
                   "KHR_materials_specular.specularFactor")
    if metal != 0.0 or spec != 0.0:
        raise ValueError(f"materials[0]: metallicFactor {metal:g} and specularFactor "
                         f"{spec:g}: microcyl reads back a diffuse base only (both 0)")
    base = _factor(pbr.get("baseColorFactor", [1.0, 1.0, 1.0, 1.0]), "baseColorFactor", 4)
    sheen = ext.get("KHR_materials_sheen", {})
    colour = _factor(sheen.get("sheenColorFactor", [0.0, 0.0, 0.0]), "sheenColorFactor", 3)
    rough = _number(sheen.get("sheenRoughnessFactor", 0.0), "sheenRoughnessFactor")
    return Charlie(base=tuple(base[:3]), sheen=tuple(colour), roughness=rough)


def model_from_glb(data: bytes) -> Charlie:
    """:func:`model_from_gltf` of a .glb's JSON chunk."""
    if len(data) < 20 or data[:4] != b"glTF":
        raise ValueError("not a binary glTF (no 'glTF' header)")
    version, total = struct.unpack_from("<II", data, 4)
    length, kind = struct.unpack_from("<I4s", data, 12)
    if version != 2 or kind != b"JSON" or 20 + length > len(data):
        raise ValueError(f"binary glTF version {version} with a first chunk {kind!r} of "
                         f"{length} bytes: a version 2 JSON chunk expected")
    try:
        text = data[20:20 + length].decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError("the JSON chunk is not UTF-8") from None
    return model_from_gltf(loads_json(text, "glb", "glTF JSON"))


def read_gltf(path):
    """The Charlie model of a .gltf or .glb file; one ValueError line naming the file."""
    data = read_bytes(path, max_bytes=MAX_GLTF_BYTES, what="a glTF file")
    try:
        if str(path).lower().endswith(".glb"):
            return model_from_glb(data)
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            raise ValueError("not UTF-8 text") from None
        return model_from_gltf(loads_json(text, path, "glTF JSON"))
    except ValueError as exc:
        raise ValueError(f"{path}: {str(exc).removeprefix(f'{path}: ')}") from None


def write_gltf(path, projection, label: str) -> None:
    """Write ``projection`` as .gltf (embedded buffer) or .glb (by the suffix), atomically."""
    glb = str(path).lower().endswith(".glb")
    doc, data = gltf_document(projection, label, embed=not glb)
    with atomic_write(path, "wb") as fh:
        fh.write(glb_bytes(doc, data) if glb
                 else (json.dumps(doc, indent=1) + "\n").encode("utf-8"))


GLTF = Target("gltf", (".gltf", ".glb"), "charlie", write_gltf, read_gltf,
              "glTF 2.0 KHR_materials_sheen: sheenColorFactor, sheenRoughnessFactor (Charlie) "
              "over baseColorFactor (linear), metallicFactor 0, KHR_materials_specular "
              "specularFactor 0")
