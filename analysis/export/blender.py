r"""Blender (4.x, 5.x): a Python script that builds the material with ``bpy``.

The Principled BSDF (Blender manual, render/shader_nodes/shader/principled.html) with
``Base Color`` the projected base, ``Diffuse Roughness`` 0 (Lambert), ``Specular IOR Level`` 0
(no dielectric specular), ``Metallic`` 0, ``Sheen Weight`` 1, ``Sheen Tint`` the sheen colour
and ``Sheen Roughness`` the roughness. Cycles' sheen is the microfiber sheen of Zeltner, Burley
and Chiang (2022), layered over the base by albedo scaling, the model of
:class:`brdf.baselines.Zeltner`, whose projection this target takes. Reading: Cycles scales
the layers under a closure by one minus its albedo's largest channel (weight x tint x R), where
MaterialX's ``sheen_bsdf`` uses the colourless 1 - weight R; the two agree for a sheen tint
whose largest channel is 1 and differ otherwise by (1 - max(tint)) R of the base (the fidelity
file measures microcyl's Zeltner model, not Cycles).

The file is code for Blender, not data: microcyl never runs or reads it back (a FABRIC never
names a .py). Run it as ``blender --background --python FILE`` (adds the material to the open
file) or, with ``-- --render OUT.png``, to render a small Cycles sphere under a sun at 45
degrees; under a Python with the ``bpy`` module, ``python FILE --render OUT.png`` does the
same. (The ``bpy`` wheel on PyPI, 5.0.1, requires numpy < 2 and cannot share microcyl's
environment; it is no extra of microcyl.)

Examples
--------
>>> from analysis.export.projection import Projection
>>> p = Projection("zeltner", {"base": [0.1, 0.2, 0.3], "sheen": [0.5, 0.4, 0.3],
...                            "roughness": 0.6})
>>> text = blender_script(p, "velvet")
>>> compile(text, "velvet.py", "exec") is not None, "'Sheen Roughness': 0.6" in text
(True, True)
"""

from __future__ import annotations

import re

from analysis.export.target import Target
from gonio.atomic import atomic_write

__all__ = ["blender_script", "BLENDER"]

_SCRIPT = '''"""microcyl export: {label} as a Blender Principled BSDF (Zeltner microfiber sheen).

{doc}
Run: blender --background --python THIS_FILE [-- --render OUT.png]
"""
import sys

import bpy

NAME = {name!r}
INPUTS = {inputs!r}


def build_material():
    mat = bpy.data.materials.get(NAME) or bpy.data.materials.new(NAME)
    mat.use_nodes = True
    node = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    for key, value in INPUTS.items():
        node.inputs[key].default_value = value
    return mat


def render(out, size=64, samples=64):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.view_settings.view_transform = "Standard"
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(build_material())
    bpy.ops.object.light_add(type="SUN", rotation=(0.0, 0.785398, 0.0))
    bpy.context.object.data.energy = 3.0
    bpy.ops.object.camera_add(location=(0.0, 0.0, 4.0), rotation=(0.0, 0.0, 0.0))
    scene.camera = bpy.context.object
    scene.camera.data.type = "ORTHO"
    scene.camera.data.ortho_scale = 2.2
    scene.world = bpy.data.worlds.new("black")
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    if "--render" in args:
        render(args[args.index("--render") + 1])
    else:
        build_material()
'''


def blender_script(projection, label: str) -> str:
    """The script's text for ``projection`` (a Zeltner one) named after ``label``."""
    v = projection.values
    name = "microcyl_" + re.sub(r"[^A-Za-z0-9_]", "_", label or "fabric")[:60]
    inputs = {"Base Color": tuple(float(c) for c in v["base"]) + (1.0,),
              "Metallic": 0.0, "Diffuse Roughness": 0.0, "Specular IOR Level": 0.0,
              "Sheen Weight": 1.0, "Sheen Tint": tuple(float(c) for c in v["sheen"]) + (1.0,),
              "Sheen Roughness": float(v["roughness"])}
    if projection.intervals:
        doc = (f"Medians of {projection.draws} projected posterior draws; 95% intervals: "
               f"{projection.intervals!r}")
    else:
        doc = "A projection of the source (no posterior draws)."
    return _SCRIPT.format(label=re.sub(r"[^A-Za-z0-9_ .-]", "_", label)[:60], doc=doc,
                          name=name, inputs=inputs)


def _write(path, projection, label):
    with atomic_write(path, "w") as fh:
        fh.write(blender_script(projection, label))


BLENDER = Target("blender", (".py",), "zeltner", _write, None,
                 "Blender Principled BSDF: Base Color, Sheen Weight 1, Sheen Tint, Sheen "
                 "Roughness (Cycles' microfiber sheen, Zeltner), Specular IOR Level 0")
