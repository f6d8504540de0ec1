r"""Blender (4.x, 5.x): a ``.blend`` whose material ``bpy`` built, or the script that builds it.

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

``-o FILE.py`` writes the script: code for Blender, not data, which microcyl never reads back
(a FABRIC never names a .py). Run it as ``blender --background --python FILE`` (adds the
material to the open file), with ``-- --save OUT.blend`` to save the material on a sample
sphere (a sun at 45 degrees, an orthographic camera above it, a black world) or with
``-- --render OUT.png`` to render that sphere with Cycles; under a Python with the ``bpy``
module, ``python FILE --save OUT.blend`` does the same.

``-o FILE.blend`` runs that script with ``--save`` where ``bpy`` can be reached
(:func:`blender_command`: the Python named by ``MICROCYL_BLENDER_PYTHON``, ``bpy`` importable
in microcyl's own Python, or ``blender`` on the PATH) and writes the ``.blend`` it saved.
Without one, the export writes ``FILE.py`` instead and says so
(:func:`settle_blender_path`). PyPI's ``bpy`` is no extra of microcyl: its wheels for
Python 3.11 (up to 5.0.1) require numpy < 2, which microcyl's colour-science rules out;
those of ``bpy`` 5.1 and later (Python 3.13) take numpy 2, in a virtual environment of their
own (``MICROCYL_BLENDER_PYTHON=/that/venv/bin/python``).

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

import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from analysis.export.target import Target
from gonio.atomic import atomic_write

__all__ = ["blender_script", "blender_command", "settle_blender_path", "write_blend",
           "BLENDER", "BLENDER_PYTHON_ENV"]

#: The environment variable naming a Python with ``bpy`` (a venv of its own).
BLENDER_PYTHON_ENV = "MICROCYL_BLENDER_PYTHON"
#: Seconds a ``.blend`` may take to build (importing bpy takes about 4 s).
BLEND_TIMEOUT_S = 300

_SCRIPT = '''"""microcyl export: {label} as a Blender Principled BSDF (Zeltner microfiber sheen).

{doc}
Run: blender --background --python THIS_FILE [-- [--save OUT.blend] [--render OUT.png]]
(or: python THIS_FILE [--save OUT.blend] [--render OUT.png], under a Python with bpy).
Without arguments it adds the material to the open file; --save writes it on a sample
sphere (a sun at 45 degrees, an orthographic camera above, a black world), --render
renders that sphere with Cycles.
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


def build_scene(size=64, samples=64):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
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
    scene.world = world = bpy.data.worlds.new("black")
    world.color = (0.0, 0.0, 0.0)
    if world.node_tree is None:                 # Blender 4.x: nodes on demand
        world.use_nodes = True
    for node in world.node_tree.nodes:          # a new world's background is 0.05 grey
        if node.type == "BACKGROUND":
            node.inputs["Strength"].default_value = 0.0
    return scene


def save(out):
    build_scene()
    bpy.context.preferences.filepaths.save_version = 0      # no OUT.blend1 backup
    bpy.ops.wm.save_as_mainfile(filepath=out, check_existing=False)


def render(out):
    scene = build_scene()
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    if "--save" in args:
        save(args[args.index("--save") + 1])
    if "--render" in args:
        render(args[args.index("--render") + 1])
    if "--save" not in args and "--render" not in args:
        build_material()
'''


def blender_command() -> list[str] | None:
    """The command that runs a Python file with ``bpy`` (the file and its arguments follow),
    or None where none can be reached.

    In this order: the Python named by ``MICROCYL_BLENDER_PYTHON`` (a ValueError when it
    names no executable file), microcyl's own Python where ``bpy`` is importable in it,
    ``blender`` on the PATH (run ``--background --factory-startup``; the file's arguments go
    after ``--``).
    """
    named = os.environ.get(BLENDER_PYTHON_ENV)
    if named:
        if not (os.path.isfile(named) and os.access(named, os.X_OK)):
            raise ValueError(f"{BLENDER_PYTHON_ENV}={named!r}: not an executable file (a "
                             f"Python with bpy, e.g. /path/to/venv/bin/python)")
        return [named]
    if importlib.util.find_spec("bpy") is not None:
        return [sys.executable]
    blender = shutil.which("blender")
    if blender:
        return [blender, "--background", "--factory-startup", "--python"]
    return None


def _run_command(command: list[str], script: Path, args: list[str]) -> list[str]:
    if Path(command[0]).name.startswith("blender") and "--python" in command:
        return [*command, str(script), "--", *args]
    return [*command, str(script), *args]


def settle_blender_path(path) -> tuple[Path, str | None]:
    """Where a Blender export of ``path`` is written and what to say of it: ``path`` itself
    unless it is a ``.blend`` with no ``bpy`` in reach (:func:`blender_command`), then the
    script ``FILE.py`` beside it and a note saying so. A ValueError (before any work) when
    that ``.py`` exists already: it is not overwritten unasked.
    """
    path = Path(path)
    if path.suffix.lower() != ".blend" or blender_command() is not None:
        return path, None
    script = path.with_suffix(".py")
    if os.path.lexists(script):
        raise ValueError(f"-o {str(path)!r}: no Python with bpy here ({BLENDER_PYTHON_ENV} "
                         f"unset, bpy not importable, no blender on the PATH), so the export "
                         f"would write the script {str(script)!r} instead, which exists; "
                         f"remove it, or give -o {str(script)!r}")
    return script, (f"no Python with bpy here ({BLENDER_PYTHON_ENV} unset, bpy not "
                     f"importable, no blender on the PATH): wrote the script {script.name} "
                     f"instead of {path.name}; `blender --background --python {script.name} "
                     f"-- --save {path.name}` makes the .blend")


def write_blend(path, projection, label: str, *, timeout_s: float = BLEND_TIMEOUT_S) -> Path:
    """Build the material with ``bpy`` (:func:`blender_command`) and write the ``.blend``
    at ``path`` (atomically: Blender saves in a private temporary folder, the file is then
    copied into place). A RuntimeError naming the command and its last error line when
    Blender fails; a ValueError when no ``bpy`` is in reach."""
    command = blender_command()
    if command is None:
        raise ValueError(f"-o {str(path)!r}: no Python with bpy to build the .blend "
                         f"({BLENDER_PYTHON_ENV} unset, bpy not importable, no blender on "
                         f"the PATH)")
    with tempfile.TemporaryDirectory(prefix="microcyl-blend-") as tmp:
        script, blend = Path(tmp) / "material.py", Path(tmp) / "material.blend"
        script.write_text(blender_script(projection, label), encoding="utf-8")
        try:
            run = subprocess.run(_run_command(command, script, ["--save", str(blend)]),
                                 capture_output=True, text=True, timeout=timeout_s,
                                 stdin=subprocess.DEVNULL, cwd=tmp)
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"{command[0]}: building the .blend took over {timeout_s:g} "
                               f"s; nothing written") from None
        if run.returncode != 0 or not blend.is_file():
            last = (run.stderr.strip().splitlines() or ["no error output"])[-1][:300]
            raise RuntimeError(f"{command[0]} failed to build the .blend (exit "
                               f"{run.returncode}): {last}; nothing written")
        data = blend.read_bytes()
    with atomic_write(path, "wb") as fh:
        fh.write(data)
    return Path(path)


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
    if Path(path).suffix.lower() == ".blend":
        write_blend(path, projection, label)
        return
    with atomic_write(path, "w") as fh:
        fh.write(blender_script(projection, label))


BLENDER = Target("blender", (".py", ".blend"), "zeltner", _write, None,
                 "Blender Principled BSDF: Base Color, Sheen Weight 1, Sheen Tint, Sheen "
                 "Roughness (Cycles' microfiber sheen, Zeltner), Specular IOR Level 0",
                 settle_blender_path)
