r"""MaterialX documents (.mtlx): OpenPBR's fuzz and MaterialX's ``sheen_bsdf``, both Zeltner.

Two targets write a MaterialX 1.39 document with one ``surfacematerial`` named after the
fabric:

- ``openpbr``: an ``open_pbr_surface`` (OpenPBR Surface 1.1; MaterialX's bxdf library
  ``open_pbr_surface.mtlx``): ``base_color`` the projected base, ``base_diffuse_roughness`` 0
  (Lambert), ``specular_weight`` 0 (no dielectric specular: the models' base is Lambertian),
  ``fuzz_weight`` 1, ``fuzz_color`` the sheen colour, ``fuzz_roughness`` the roughness.
  OpenPBR's fuzz is the Zeltner et al. LTC sheen layered over the base by albedo scaling
  (MaterialX implements it as ``sheen_bsdf`` mode zeltner with weight ``fuzz_weight``).
- ``materialx``: ``sheen_bsdf`` (pbrlib, ``mode`` ``zeltner``, ``weight`` 1, ``color``,
  ``roughness``) ``layer``-ed over ``oren_nayar_diffuse_bsdf`` (``roughness`` 0: Lambert)
  into a ``surface`` shader: the layer scales the base by the sheen's throughput
  1 - weight R(cos_o, roughness).

Either is what :class:`brdf.baselines.Zeltner` evaluates (its notes give MaterialX's source).
The 95% intervals of a fit's projection go in the material's ``doc`` attribute. Read back
(:func:`read_mtlx`): the first ``open_pbr_surface`` or ``sheen_bsdf`` + diffuse pair, through
:mod:`analysis.export.xmlsafe`; an OpenPBR surface with weights other than those written
(fuzz_weight 1, specular_weight 0, base_weight 1, no metalness, coat, transmission...) is
refused, since microcyl's Zeltner model would not be what the renderer shows.

Examples
--------
>>> from analysis.export.projection import Projection
>>> p = Projection("zeltner", {"base": [0.1, 0.2, 0.3], "sheen": [0.5, 0.4, 0.3],
...                            "roughness": 0.6})
>>> m = model_from_mtlx(mtlx_text(p, "openpbr", "velvet"))
>>> m.name, m.roughness, tuple(m.sheen)
('zeltner', 0.6, (0.5, 0.4, 0.3))
>>> model_from_mtlx(mtlx_text(p, "materialx", "velvet")).base
(0.1, 0.2, 0.3)
"""

from __future__ import annotations

import re
from xml.sax.saxutils import quoteattr

from analysis.export.target import Target
from analysis.export.xmlsafe import MAX_XML_BYTES, parse_xml
from brdf.baselines import Zeltner
from gonio.atomic import atomic_write
from gonio.safeopen import read_text

__all__ = ["mtlx_text", "model_from_mtlx", "read_mtlx", "OPENPBR", "MATERIALX"]

#: The OpenPBR inputs a read-back accepts, with the only value each may take where fixed.
_OPENPBR_FIXED = {"base_weight": 1.0, "base_diffuse_roughness": 0.0, "base_metalness": 0.0,
                  "specular_weight": 0.0, "fuzz_weight": 1.0, "coat_weight": 0.0,
                  "transmission_weight": 0.0, "subsurface_weight": 0.0,
                  "thin_film_weight": 0.0, "emission_luminance": 0.0}


def _c3(v) -> str:
    return ", ".join(repr(float(x)) for x in v)


def _doc(projection) -> str:
    iv = projection.intervals
    if not iv:
        return "microcyl export: a projection of the source (no posterior draws)"
    return (f"microcyl export: medians of {projection.draws} projected posterior draws; 95% "
            f"intervals base {iv['base']}, sheen {iv['sheen']}, roughness "
            f"{iv['roughness']}")


def mtlx_text(projection, flavour: str, label: str) -> str:
    """The .mtlx document of ``projection`` (a Zeltner projection) for ``flavour``
    (``openpbr`` or ``materialx``)."""
    v = projection.values
    name = re.sub(r"[^A-Za-z0-9_]", "_", label or "fabric")[:60]
    if not name[:1].isalpha():
        name = "M_" + name
    inp = '    <input name="{}" type="{}" value="{}"/>'.format
    if flavour == "openpbr":
        body = [f'  <open_pbr_surface name="SR_{name}" type="surfaceshader">',
                inp("base_weight", "float", "1.0"),
                inp("base_color", "color3", _c3(v["base"])),
                inp("base_diffuse_roughness", "float", "0.0"),
                inp("specular_weight", "float", "0.0"),
                inp("fuzz_weight", "float", "1.0"),
                inp("fuzz_color", "color3", _c3(v["sheen"])),
                inp("fuzz_roughness", "float", repr(float(v["roughness"]))),
                "  </open_pbr_surface>"]
    elif flavour == "materialx":
        body = [f'  <oren_nayar_diffuse_bsdf name="base_{name}" type="BSDF">',
                inp("color", "color3", _c3(v["base"])), inp("roughness", "float", "0.0"),
                "  </oren_nayar_diffuse_bsdf>",
                f'  <sheen_bsdf name="sheen_{name}" type="BSDF">',
                inp("weight", "float", "1.0"), inp("color", "color3", _c3(v["sheen"])),
                inp("roughness", "float", repr(float(v["roughness"]))),
                inp("mode", "string", "zeltner"), "  </sheen_bsdf>",
                f'  <layer name="layer_{name}" type="BSDF">',
                f'    <input name="top" type="BSDF" nodename="sheen_{name}"/>',
                f'    <input name="base" type="BSDF" nodename="base_{name}"/>',
                "  </layer>",
                f'  <surface name="SR_{name}" type="surfaceshader">',
                f'    <input name="bsdf" type="BSDF" nodename="layer_{name}"/>',
                "  </surface>"]
    else:
        raise ValueError(f"MaterialX flavour {flavour!r}: must be openpbr or materialx")
    return "\n".join(['<?xml version="1.0"?>', '<materialx version="1.39">', *body,
                      f'  <surfacematerial name="{name}" type="material" '
                      f'doc={quoteattr(_doc(projection))}>',
                      f'    <input name="surfaceshader" type="surfaceshader" '
                      f'nodename="SR_{name}"/>', "  </surfacematerial>", "</materialx>"]) + "\n"


def _inputs(node) -> dict:
    out = {}
    for child in node:
        if child.tag != "input" or child.get("name") is None:
            continue
        name, value = child.get("name"), child.get("value")
        if value is None:
            if child.get("nodename") is not None:
                out[name] = ("node", child.get("nodename"))
                continue
            raise ValueError(f"input {name!r:.40} of <{node.tag}>: a value or a node expected "
                             f"(textures and node graphs are not read back)")
        if child.get("type") == "string":
            out[name] = value
            continue
        try:
            nums = [float(x) for x in value.replace(",", " ").split()]
        except ValueError:
            raise ValueError(f"input {name!r:.40}: numbers expected; got {value!r:.40}") \
                from None
        out[name] = nums[0] if len(nums) == 1 else nums
    return out


def _colour(inputs: dict, key: str, default) -> tuple:
    v = inputs.get(key, default)
    v = [v] * 3 if isinstance(v, float) else v
    if not isinstance(v, list) or len(v) != 3:
        raise ValueError(f"input {key!r}: a color3 expected; got {v!r:.40}")
    return tuple(v)


def model_from_mtlx(text: str):
    """The :class:`brdf.baselines.Zeltner` model of a .mtlx document's first
    ``open_pbr_surface``, or of its ``sheen_bsdf`` over an ``oren_nayar_diffuse_bsdf``.

    Raises
    ------
    ValueError
        A declaration, malformed XML, neither shader, an input other than those written
        with another value, a mode other than zeltner, or values out of range.
    """
    root = parse_xml(text)
    pbr = next(root.iter("open_pbr_surface"), None)
    if pbr is not None:
        ins = _inputs(pbr)
        for key, want in _OPENPBR_FIXED.items():
            if key in ins and ins[key] != want:
                raise ValueError(f"open_pbr_surface input {key} = {ins[key]!r:.40}: microcyl "
                                 f"reads back only {want:g} (its export's value)")
        return Zeltner(base=_colour(ins, "base_color", 0.8), sheen=_colour(ins, "fuzz_color",
                                                                        1.0),
                       roughness=float(ins.get("fuzz_roughness", 0.5)))
    sheen = next(root.iter("sheen_bsdf"), None)
    diffuse = next(root.iter("oren_nayar_diffuse_bsdf"), None)
    if sheen is None or diffuse is None:
        raise ValueError("no open_pbr_surface and no sheen_bsdf over an "
                         "oren_nayar_diffuse_bsdf")
    s, d = _inputs(sheen), _inputs(diffuse)
    if s.get("mode", "conty_kulla") != "zeltner":
        raise ValueError(f"sheen_bsdf mode {s.get('mode', 'conty_kulla')!r:.40}: microcyl reads "
                         f"back zeltner only")
    for key, ins, want in (("weight", s, 1.0), ("roughness", d, 0.0)):
        if ins.get(key, want) != want:
            raise ValueError(f"input {key} = {ins[key]!r:.40}: microcyl reads back only "
                             f"{want:g}")
    return Zeltner(base=_colour(d, "color", 0.18), sheen=_colour(s, "color", 1.0),
                   roughness=float(s.get("roughness", 0.3)))


def read_mtlx(path):
    """:func:`model_from_mtlx` of a file (read through :mod:`analysis.export.xmlsafe`);
    one ValueError line naming the file."""
    try:
        return model_from_mtlx(read_text(path, max_bytes=MAX_XML_BYTES,
                                         what="a MaterialX document"))
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def _writer(flavour):
    def write(path, projection, label):
        with atomic_write(path, "w") as fh:
            fh.write(mtlx_text(projection, flavour, label))
    return write


OPENPBR = Target("openpbr", (".mtlx",), "zeltner", _writer("openpbr"), read_mtlx,
                 "OpenPBR open_pbr_surface: base_color, fuzz_weight 1, fuzz_color, "
                 "fuzz_roughness (Zeltner LTC fuzz over a Lambertian base, specular_weight 0)")
MATERIALX = Target("materialx", (".mtlx",), "zeltner", _writer("materialx"), read_mtlx,
                   "MaterialX sheen_bsdf (mode zeltner, weight 1, color, roughness) layered "
                   "over oren_nayar_diffuse_bsdf (roughness 0)")
