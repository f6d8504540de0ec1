"""Exports for renderers (analysis/export): the projection, the fidelity, the files and their
read-back, checked against independent references and the targets' own tools (MaterialX's
Python package, the Khronos glTF validator, Blender's bpy where present)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import brdf
from analysis import sources
from analysis.export import TARGETS, HemisphereGrid, fidelity, project, target_for
from analysis.export.blender import blender_script
from analysis.export.gltf import read_gltf
from analysis.export.mtlx import mtlx_text, read_mtlx
from analysis.export.projection import Projection
from analysis.export.workflow import export_fabric, fidelity_path
from analysis.fit.medians import median_fabric
from brdf.baselines import Charlie, Lambert, Zeltner

GRID = HemisphereGrid(3, 6)
NODE = Path(__file__).parent / "node"


class Scaled:
    """A BRDF times a constant."""

    def __init__(self, inner, k):
        self.inner, self.k = inner, k

    def eval(self, wi, wo):
        return self.k * np.asarray(self.inner.eval(wi, wo))


def _direct_rel_l2(source, target, n_theta=3, n_phi=6):
    """Relative L2 error of f_r cos cos by explicit loops over the cells (no export code)."""
    dirs, dws = [], []
    for a in range(n_theta):
        t0, t1 = a * np.pi / 2 / n_theta, (a + 1) * np.pi / 2 / n_theta
        for b in range(n_phi):
            t, p = 0.5 * (t0 + t1), (b + 0.5) * 2 * np.pi / n_phi
            dirs.append([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])
            dws.append((np.cos(t0) - np.cos(t1)) * 2 * np.pi / n_phi)
    num = np.zeros(4)
    den = np.zeros(4)
    y = np.array([0.2126, 0.7152, 0.0722])
    for di, wgi in zip(dirs, dws):
        wi = np.repeat([di], len(dirs), 0)
        wo = np.array(dirs)
        c = (wi[:, 2] * wo[:, 2])[:, None]
        s = np.asarray(source.eval(wi, wo)) * c
        t = np.asarray(target.eval(wi, wo)) * c
        s = np.column_stack([s, s @ y])
        t = np.column_stack([t, t @ y])
        w = (wgi * np.array(dws))[:, None]
        num += np.sum(w * (t - s) ** 2, 0)
        den += np.sum(w * s ** 2, 0)
    return np.sqrt(num / den)


def test_projection_recovers_a_model_of_its_own_family():
    """A Charlie source projected onto Charlie, a Zeltner onto Zeltner: their parameters."""
    for cls in (Charlie, Zeltner):
        truth = cls(base=(0.3, 0.2, 0.1), sheen=(0.2, 0.6, 0.9), roughness=0.5)
        p = project(truth, cls.name, GRID)
        assert np.allclose(p.values["base"], truth.base, atol=2e-3), cls.name
        assert np.allclose(p.values["sheen"], truth.sheen, atol=2e-3), cls.name
        assert abs(p.values["roughness"] - 0.5) < 2e-3, cls.name


def test_fidelity_of_a_scaled_source_is_the_scale():
    """Half the source: relative L2 error 0.5 in every channel and the luminance; a
    Lambertian base 0.5: albedo 0.5 at every incidence (analytic)."""
    fab = brdf.fabric("linen_plain")
    fid = fidelity(fab, Scaled(fab, 0.5), GRID)
    assert all(abs(v - 0.5) < 1e-12 for v in fid["relative_l2"].values())
    lam = fidelity(Lambert(base=0.5), Lambert(base=0.5), GRID)
    for a in lam["albedo"]["source"].values():
        assert np.allclose(a["rgb"], 0.5, atol=1e-12)
    assert lam["cannot_follow"] == [] and lam["delta_e2000"]["max"] == 0.0
    retro = lam["limits"]["retroreflection"]["source_back_over_lambertian_60deg"]
    assert abs(retro - 1.0) < 1e-9                   # a Lambertian is its own reference


def test_fidelity_matches_a_direct_evaluation():
    fab = brdf.fabric("velvet")
    p = project(fab, "zeltner", GRID)
    fid = fidelity(fab, p.brdf(), GRID)
    ref = _direct_rel_l2(fab, p.brdf())
    got = [fid["relative_l2"][k] for k in ("R", "G", "B", "luminance")]
    assert np.allclose(got, ref, rtol=1e-9)


def test_limits_flag_what_the_targets_cannot_follow():
    """Shot silk (warp and weft of different colours, anisotropic) is flagged for anisotropy
    and colour shift, velvet's back-scatter peak for retroreflection; a Zeltner source
    exported as Zeltner for nothing."""
    silk = brdf.fabric("silk_shot")
    fid = fidelity(silk, project(silk, "zeltner", GRID).brdf(), GRID)
    assert fid["limits"]["anisotropy"]["cannot_follow"]
    assert fid["limits"]["colour_shift"]["cannot_follow"]
    velvet = brdf.fabric("velvet")
    fid = fidelity(velvet, project(velvet, "zeltner", GRID).brdf(), GRID)
    assert fid["limits"]["retroreflection"]["cannot_follow"]
    z = Zeltner(base=0.3, sheen=0.7, roughness=0.4)
    assert fidelity(z, project(z, "zeltner", GRID).brdf(), GRID)["cannot_follow"] == []


@pytest.mark.parametrize("target,suffix", [("openpbr", ".mtlx"), ("materialx", ".mtlx"),
                                           ("gltf", ".gltf"), ("gltf", ".glb")])
def test_round_trip_reads_back_the_projection(tmp_path, target, suffix):
    """Each export read back as a FABRIC is the projected model, and the fidelity file's
    error is that model's, evaluated independently."""
    fab = brdf.fabric("velvet")
    out = tmp_path / f"v{suffix}"
    res = export_fabric(sources.resolve("velvet"), target, out, grid=GRID)
    doc = json.loads(fidelity_path(out).read_text())
    back = sources.resolve(str(out))
    assert back.kind == suffix[1:] and back.model == TARGETS[target].model
    v = doc["projection"]["values"]
    cls = {"zeltner": Zeltner, "charlie": Charlie}[back.model]
    ref = cls(base=tuple(v["base"]), sheen=tuple(v["sheen"]), roughness=v["roughness"])
    wi, wo = GRID.wi[::7], GRID.wo[::7]
    assert np.allclose(back.brdf.eval(wi, wo), ref.eval(wi, wo), rtol=1e-12, atol=0)
    ref_l2 = _direct_rel_l2(fab, back.brdf)
    assert abs(doc["fidelity"]["relative_l2"]["luminance"] - ref_l2[3]) < 1e-9
    assert res.fidelity["relative_l2"]["luminance"] == doc["fidelity"]["relative_l2"][
        "luminance"]


def test_fit_folder_projects_posterior_draws(fit_folder, tmp_path):
    folder, _ = fit_folder
    out = tmp_path / "fit.glb"
    res = export_fabric(sources.resolve(folder), "gltf", out, grid=GRID, draws=6)
    p = res.projection
    assert p.draws == 6
    lo, hi = p.intervals["roughness"]
    assert lo <= p.values["roughness"] <= hi
    for k in range(3):
        assert p.intervals["sheen"][k][0] <= p.values["sheen"][k] <= p.intervals["sheen"][k][1]
    assert "intervals_95" in json.loads(fidelity_path(out).read_text())["projection"]
    assert median_fabric(folder).free == ("gamma_s1", "kd1")


def test_mitsuba_target_is_exact_and_refuses_a_baseline(tmp_path):
    res = export_fabric(sources.resolve("velvet"), "mitsuba", tmp_path / "v.json", grid=GRID)
    assert res.fidelity["relative_l2"]["luminance"] == 0.0 and res.projection is None
    assert sources.resolve(str(tmp_path / "v.json")).fabric.threads == \
        brdf.fabric("velvet").threads
    (tmp_path / "z.mtlx").write_text(mtlx_text(Projection(
        "zeltner", {"base": [0.2] * 3, "sheen": [0.5] * 3, "roughness": 0.5}), "openpbr", "z"))
    with pytest.raises(ValueError, match="is a .mtlx export read back as model zeltner"):
        export_fabric(sources.resolve(str(tmp_path / "z.mtlx")), "mitsuba",
                      tmp_path / "z.json", grid=GRID)
    assert not (tmp_path / "z.json").exists()
    assert target_for("a.glb").name == "gltf" and target_for("a.py").name == "blender"


def test_hostile_exports_are_refused_in_one_line(tmp_path):
    """Entities, a link, metalness, a conty_kulla sheen, a texture: one line naming the
    file, nothing expanded or followed."""
    secret = tmp_path / "secret.txt"
    secret.write_text("0.25, 0.25, 0.25")
    bomb = ('<?xml version="1.0"?><!DOCTYPE m [<!ENTITY x SYSTEM "file://' + str(secret)
            + '">]><materialx><open_pbr_surface name="s" type="surfaceshader"><input '
            'name="base_color" type="color3" value="&x;"/></open_pbr_surface></materialx>')
    cases = {"bomb.mtlx": bomb}
    good = mtlx_text(Projection("zeltner", {"base": [0.2] * 3, "sheen": [0.5] * 3,
                                            "roughness": 0.5}), "materialx", "m")
    cases["kulla.mtlx"] = good.replace("zeltner", "conty_kulla")
    gl = {"materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1]},
                         "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}]}
    cases["metal.gltf"] = json.dumps(gl)
    gl2 = {"materials": [{"pbrMetallicRoughness": {"metallicFactor": 0,
                                                   "baseColorTexture": {"index": 0}},
                          "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}]}
    cases["texture.gltf"] = json.dumps(gl2)
    for name, text in cases.items():
        (tmp_path / name).write_text(text)
    (tmp_path / "link.gltf").symlink_to(tmp_path / "metal.gltf")
    want = {"bomb.mtlx": "document type", "kulla.mtlx": "mode 'conty_kulla'",
            "metal.gltf": "metallicFactor 1", "texture.gltf": "textures",
            "link.gltf": "symbolic link"}
    for name, words in want.items():
        with pytest.raises(ValueError) as exc:
            sources.resolve(str(tmp_path / name))
        msg = str(exc.value)
        assert "\n" not in msg and name in msg and words in msg, msg
        assert "0.25" not in msg


def test_mtlx_validates_and_generates_shader_code(tmp_path):
    mx = pytest.importorskip("MaterialX", reason="MaterialX is not installed (pip install "
                                                 "'microcyl[export]')")
    gs = pytest.importorskip("MaterialX.PyMaterialXGenShader")
    glsl = pytest.importorskip("MaterialX.PyMaterialXGenGlsl")
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    p = Projection("zeltner", {"base": [0.1, 0.2, 0.3], "sheen": [0.6, 0.5, 0.4],
                               "roughness": 0.45},
                   {"base": [[0.0, 0.2]] * 3, "sheen": [[0.5, 0.7]] * 3, "roughness": [0.4, 0.5]},
                   10)
    for flavour, node in (("openpbr", "open_pbr_surface"), ("materialx", "sheen_bsdf")):
        out = tmp_path / f"{flavour}.mtlx"
        TARGETS[flavour].write(out, p, "velvet 1")
        doc = mx.createDocument()
        mx.readFromXmlFile(doc, str(out))
        doc.setDataLibrary(lib)
        ok, message = doc.validate()
        assert ok, message
        gen = glsl.GlslShaderGenerator.create()
        ctx = gs.GenContext(gen)
        ctx.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
        shader = gen.generate("fabric", doc.getMaterialNodes()[0], ctx)
        code = shader.getSourceCode(gs.PIXEL_STAGE)
        assert "mx_" in code and len(code) > 1000
        assert doc.getChildren()[0].getCategory() in (node, "oren_nayar_diffuse_bsdf")
        assert read_mtlx(out).roughness == 0.45


def test_gltf_passes_the_khronos_validator(tmp_path):
    if shutil.which("node") is None:
        pytest.skip("node is not installed (the Khronos glTF validator runs on Node.js)")
    if not (NODE / "node_modules" / "gltf-validator").is_dir():
        pytest.skip("the Khronos validator is not installed: npm install --prefix tests/node "
                    "(.ci/run does)")
    p = Projection("charlie", {"base": [0.1, 0.2, 0.3], "sheen": [0.6, 0.5, 0.4],
                               "roughness": 0.45})
    files = []
    for suffix in (".gltf", ".glb"):
        files.append(tmp_path / f"s{suffix}")
        TARGETS["gltf"].write(files[-1], p, "velvet")
        assert read_gltf(files[-1]).roughness == 0.45
    run = subprocess.run(["node", str(NODE / "validate_gltf.js"), *map(str, files)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    reports = [json.loads(line) for line in run.stdout.splitlines()]
    assert len(reports) == 2
    for r in reports:
        assert r["errors"] == 0 and r["warnings"] == 0, r


def test_blender_script(tmp_path):
    """The script compiles and sets the Principled BSDF's sheen; where a Python with bpy is
    named by MICROCYL_BLENDER_PYTHON it builds the material and renders a Cycles sphere."""
    p = Projection("zeltner", {"base": [0.1, 0.2, 0.3], "sheen": [0.6, 0.5, 0.4],
                               "roughness": 0.45})
    text = blender_script(p, "velvet")
    compile(text, "velvet.py", "exec")
    assert "'Sheen Roughness': 0.45" in text and "'Specular IOR Level': 0.0" in text
    python = os.environ.get("MICROCYL_BLENDER_PYTHON")
    if not python:
        pytest.skip("no Python with bpy (MICROCYL_BLENDER_PYTHON unset): PyPI's bpy for "
                    "Python 3.11 requires numpy < 2 and cannot share microcyl's environment; "
                    "bpy >= 5.1 on Python 3.13 takes numpy 2, in a venv of its own")
    script = tmp_path / "velvet.py"
    script.write_text(text)
    png = tmp_path / "sphere.png"
    run = subprocess.run([python, str(script), "--render", str(png)], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    from PIL import Image
    img = np.asarray(Image.open(png).convert("RGB"), dtype=float) / 255.0
    assert img.shape[:2] == (64, 64)
    c = img[30:35, 30:35].reshape(-1, 3).mean(0)             # the sphere's top, normal +z
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    # microcyl's Zeltner lobe with Cycles' layering (the base scaled by 1 - max(tint) R),
    # lit by the script's sun (3 W/m^2 from 45 degrees), seen from the normal
    from brdf.baselines.zeltner import dir_albedo
    s = np.sqrt(0.5)
    wi, wo = np.array([s, 0.0, s]), np.array([0.0, 0.0, 1.0])
    lobe = Zeltner(base=0.0, sheen=(0.6, 0.5, 0.4), roughness=0.45).eval(wi, wo)
    base = (1 - 0.6 * dir_albedo(1.0, 0.45)) * np.array([0.1, 0.2, 0.3]) / np.pi
    expected = (lobe + base) * s * 3.0
    assert np.allclose(linear, expected, rtol=0.15), (linear, expected)
