"""`microcyl export --to blender -o FILE.blend` run as a user runs it: the .blend built by bpy
where a Python with bpy is named (MICROCYL_BLENDER_PYTHON), its Cycles sphere against
microcyl's own renders of the projection and of the source; the script instead, said so,
where no bpy can be reached; refusals in one line, nothing left half written."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
ENV.pop("MICROCYL_BLENDER_PYTHON", None)
#: A PATH with microcyl's Python and no blender on it.
BARE_PATH = os.path.dirname(sys.executable)

#: Run under the Python with bpy: open the .blend, render its own scene with Cycles (its
#: sphere, sun and camera), save linear RGB as .npy, rows from the top.
CYCLES = """
import sys
import numpy as np
import bpy
blend, out = sys.argv[1], sys.argv[2]
bpy.ops.wm.open_mainfile(filepath=blend)
scene = bpy.context.scene
scene.cycles.samples = 256
scene.cycles.seed = 1
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.filepath = out + ".exr"
bpy.ops.render.render(write_still=True)
size = scene.render.resolution_x
img = bpy.data.images.load(out + ".exr")
px = np.array(img.pixels[:], dtype=np.float64).reshape(size, size, 4)[::-1, :, :3]
np.save(out, px)
"""


def microcyl(*args, cwd, env=None):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)],
                          env=env or ENV, cwd=cwd, capture_output=True, text=True, timeout=600)


def _blender_python() -> str:
    python = os.environ.get("MICROCYL_BLENDER_PYTHON")
    if not python:
        pytest.skip("no Python with bpy: set MICROCYL_BLENDER_PYTHON to one (PyPI's bpy for "
                    "Python 3.11 requires numpy < 2 and cannot share microcyl's environment; "
                    "bpy >= 5.1 on Python 3.13 takes numpy 2: `python3.13 -m venv B && "
                    "B/bin/pip install bpy`)")
    return python


def _microcyl_sphere(brdf_obj, size):
    """microcyl's render of the export's scene: a unit sphere seen from +z by an orthographic
    camera 2.2 wide, a sun of 3 W/m^2 from 45 degrees toward +x, nothing else."""
    from reports.render.engine import render
    from reports.render.scenes import (DirectionalLight, OrthographicCamera, Scene, Sphere)
    s = np.sqrt(0.5)
    scene = Scene(primitives=(Sphere(center=(0.0, 0.0, 0.0), radius=1.0),),
                  camera=OrthographicCamera(position=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0),
                                            up=(0.0, 1.0, 0.0), extent=2.2),
                  light=DirectionalLight(direction=(s, 0.0, s), irradiance=3.0), name="blend")
    return np.asarray(render(scene, brdf_obj, width=size, height=size, spp=16, workers=1,
                             progress=False))


def _compare(cycles, ours):
    """Mean CIEDE2000 over the lit disc (clear of its rim) of the two images, each relative to
    a white Lambertian facing the sun (E / pi), and their mean luminances' ratio."""
    from analysis.colour import albedo_delta_e, luminance
    size = cycles.shape[0]
    y, x = (np.mgrid[0:size, 0:size] + 0.5) / size * 2.2 - 1.1
    lit = (x ** 2 + y ** 2 < 0.9 ** 2) & (cycles.sum(-1) > 0)
    white = 3.0 / np.pi
    de = [albedo_delta_e(a / white, b / white) for a, b in zip(ours[lit], cycles[lit])]
    return float(np.mean(de)), float(luminance(ours[lit]).mean() / luminance(cycles[lit]).mean())


def test_blend_renders_in_cycles_as_microcyl_renders_the_export(tmp_path):
    """The .blend holds the projected material on the sample sphere; Cycles renders it as
    microcyl renders the projection (microcyl's Zeltner model, no code shared), and it departs
    from microcyl's render of the source (velvet) by no more than the fidelity file says the
    export departs from the source (its largest CIEDE2000 of a lit patch)."""
    python = _blender_python()
    from brdf.baselines import Zeltner
    env = {**ENV, "MICROCYL_BLENDER_PYTHON": python}
    r = microcyl("export", "velvet", "-o", "velvet.blend", "--grid", "5x8", cwd=tmp_path,
                 env=env)
    assert r.returncode == 0, r.stderr
    assert "blender (zeltner projection) -> velvet.blend" in r.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["velvet.blend",
                                                          "velvet.blend.fidelity.json"]
    head = (tmp_path / "velvet.blend").read_bytes()[:7]
    assert head == b"BLENDER" or head.startswith(b"\x28\xb5\x2f\xfd")   # plain, or zstd
    doc = json.loads((tmp_path / "velvet.blend.fidelity.json").read_text())
    (tmp_path / "render_blend.py").write_text(CYCLES)   # not cycles.py: the add-on's name
    run = subprocess.run([python, "render_blend.py", "velvet.blend", "cycles.npy"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    cycles = np.load(tmp_path / "cycles.npy", allow_pickle=False)
    v = doc["projection"]["values"]
    projected = Zeltner(base=tuple(v["base"]), sheen=tuple(v["sheen"]),
                        roughness=v["roughness"])
    de_proj, ratio_proj = _compare(cycles, _microcyl_sphere(projected, cycles.shape[0]))
    assert de_proj < 1.5 and abs(ratio_proj - 1.0) < 0.05, (de_proj, ratio_proj)
    import brdf
    de_src, ratio_src = _compare(cycles, _microcyl_sphere(brdf.fabric("velvet"),
                                                          cycles.shape[0]))
    print(f"Cycles vs microcyl: projection mean CIEDE2000 {de_proj:.2f} (luminance ratio "
          f"{ratio_proj:.3f}); source velvet {de_src:.2f} (ratio {ratio_src:.2f})")
    assert de_proj < de_src <= doc["fidelity"]["delta_e2000"]["max"], (de_src, doc)


def test_blend_without_bpy_writes_the_script_and_says_so(tmp_path):
    """No MICROCYL_BLENDER_PYTHON, no bpy in microcyl's Python, no blender on the PATH: the
    script FILE.py and its fidelity, and a note naming both files and the command to run."""
    import importlib.util
    if importlib.util.find_spec("bpy") is not None:
        pytest.skip("bpy imports in microcyl's Python here: the .blend is built")
    env = {**ENV, "PATH": BARE_PATH}
    r = microcyl("export", "velvet", "-o", "velvet.blend", "--grid", "3x6", cwd=tmp_path,
                 env=env)
    assert r.returncode == 0, r.stderr
    assert "wrote the script velvet.py instead of velvet.blend" in r.stdout
    assert "blender --background --python velvet.py -- --save velvet.blend" in r.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["velvet.py",
                                                          "velvet.py.fidelity.json"]
    doc = json.loads((tmp_path / "velvet.py.fidelity.json").read_text())
    assert doc["file"] == "velvet.py" and any("instead of velvet.blend" in n
                                              for n in doc["notes"])
    compile((tmp_path / "velvet.py").read_text(), "velvet.py", "exec")
    again = microcyl("export", "velvet", "-o", "velvet.blend", "--grid", "3x6", cwd=tmp_path,
                     env=env)                       # the script is there: not overwritten
    assert again.returncode != 0 and "which exists" in again.stderr
    assert len(again.stderr.strip().splitlines()) == 1, again.stderr


def test_a_broken_blender_python_is_one_line_and_writes_nothing(tmp_path):
    """A MICROCYL_BLENDER_PYTHON that names no file is refused before any work; one that
    fails (here `false`) leaves no .blend and no fidelity file behind."""
    missing = microcyl("export", "velvet", "-o", "v.blend", cwd=tmp_path,
                       env={**ENV, "MICROCYL_BLENDER_PYTHON": str(tmp_path / "nope")})
    assert missing.returncode != 0 and "MICROCYL_BLENDER_PYTHON=" in missing.stderr
    assert "not an executable file" in missing.stderr
    failing = microcyl("export", "velvet", "-o", "v.blend", "--grid", "3x6", cwd=tmp_path,
                       env={**ENV, "MICROCYL_BLENDER_PYTHON": "/bin/false"})
    assert failing.returncode != 0 and "failed to build the .blend" in failing.stderr
    for r in (missing, failing):
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert list(tmp_path.iterdir()) == []
