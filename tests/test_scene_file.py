"""Tests of the scene file beside every render (reports.render.scenefile) and of
``microcyl render --scene``."""

import json
import subprocess
import sys

import numpy as np
import pytest

from reports.cli import main
from reports.render import imageio
from reports.render.scenefile import read_scene_file, scene_from_dict, scene_file_path

SMALL = ["--width", "32", "--height", "18", "--spp", "4", "--quiet"]


def _render(tmp_path, name, *argv):
    out = tmp_path / name
    assert main(["render", *argv, "-o", str(out)]) == 0
    return out


def test_render_writes_its_scene_and_renders_it_again_bit_for_bit(tmp_path):
    a = _render(tmp_path, "a.exr", "cylinder", "velvet", "--seed", "5", *SMALL)
    doc = json.loads(scene_file_path(a).read_text())
    assert doc["render"] == {"engine": "builtin", "integrator": "direct", "width": 32,
                             "height": 18, "spp": 4, "seed": 5, "variant": None,
                             "max_depth": None,
                             "exposure_stops": doc["render"]["exposure_stops"]}
    assert doc["fabric"]["fabric"] == "velvet" and "gamma_s1" in doc["fabric"]
    assert doc["geometry"][0]["type"] == "Cylinder" and doc["light"]["type"] == "PointLight"
    # as a user runs it: a new process, from the file alone
    b = tmp_path / "b.exr"
    subprocess.run([sys.executable, "-m", "reports", "render", "--scene",
                    str(scene_file_path(a)), "-q", "-o", str(b)], check=True)
    img_a, img_b = imageio.read_exr(a), imageio.read_exr(b)
    assert img_a.shape == (18, 32, 3) and img_a.max() > 0
    assert np.array_equal(img_a, img_b)
    assert json.loads(scene_file_path(b).read_text()) == doc


def test_another_seed_differs_within_monte_carlo_noise(tmp_path):
    a = _render(tmp_path, "a.exr", "curtain", "linen_plain", "--seed", "1", *SMALL)
    seeds = [imageio.read_exr(_render(tmp_path, f"s{s}.exr", "--scene",
                                      str(scene_file_path(a)), "--seed", str(s), "--quiet"))
             for s in (2, 3)]
    img = imageio.read_exr(a)
    assert not np.array_equal(img, seeds[0])
    # the mean over the image: its MC error, from two independent seeds, bounds the change
    sd = abs(seeds[0].mean() - seeds[1].mean())
    assert abs(img.mean() - seeds[0].mean()) < max(6 * sd, 0.02 * img.mean())


def test_a_fabric_given_replaces_the_files(tmp_path):
    a = _render(tmp_path, "a.exr", "cylinder", "velvet", *SMALL)
    b = _render(tmp_path, "b.exr", "--scene", str(scene_file_path(a)), "silk_shot",
                "--quiet")
    assert json.loads(scene_file_path(b).read_text())["fabric"]["fabric"] == "silk_shot"
    assert not np.array_equal(imageio.read_exr(a), imageio.read_exr(b))


@pytest.fixture(scope="module")
def one_doc(tmp_path_factory):
    a = _render(tmp_path_factory.mktemp("doc"), "a.png", "cylinder", "velvet", *SMALL)
    return scene_file_path(a).read_text()


@pytest.fixture
def doc(one_doc):
    return json.loads(one_doc)


@pytest.mark.parametrize("edit, match", [
    (lambda d: d.update(schema="other"), "not a microcyl scene file"),
    (lambda d: d.update(schema_version=9), "schema_version 9"),
    (lambda d: d.update(extra=1), "unknown field 'extra'"),
    (lambda d: d.update(geometry=[]), "geometry must be a list of 1 to 64"),
    (lambda d: d.update(geometry=[{"type": "Cylinder"}] * 65), "geometry must be a list"),
    (lambda d: d["geometry"][0].update(type="Teapot"), "geometry[0].type = 'Teapot'"),
    (lambda d: d["geometry"][0].update(radius=-1), "geometry[0].radius = '-1'"),
    (lambda d: d["geometry"][0].update(radius="big"), "geometry[0].radius = 'big'"),
    (lambda d: d["geometry"][0].update(center=[0, 0]), "geometry[0].center"),
    (lambda d: d["geometry"][0].update(center=[0, 0, float("nan")]), "center[2]"),
    (lambda d: d["geometry"][0].update(material="gold"), "material = 'gold'"),
    (lambda d: d["geometry"][0].update(colour=1), "unknown field 'colour'"),
    (lambda d: d["camera"].update(fov=200), "camera.fov = '200'"),
    (lambda d: d["light"].update(intensity=[1, 2]), "light.intensity"),
    (lambda d: d["light"].update(intensity=-3), "light.intensity = '-3'"),
    (lambda d: d.update(environment={"zenith": [1, 1, 1], "sun": 1}), "unknown field 'sun'"),
    (lambda d: d["render"].update(width=5000), "render.width = '5000'"),
    (lambda d: d["render"].update(width=2000), "width=2000 is beyond the limit"),
    (lambda d: d["render"].update(spp=True), "render.spp = 'True'"),
    (lambda d: d["render"].update(seed=-1), "render.seed = '-1'"),
    (lambda d: d["render"].update(engine="cycles"), "render.engine = 'cycles'"),
    (lambda d: d["render"].update(max_depth=3), "max_depth: must be null"),
    (lambda d: d["fabric"].update(kd1=7), "fabric: thread 1"),
    (lambda d: d["fabric"].update(kd9=0.1), "fabric: unknown microcylinder parameter"),
])
def test_every_field_is_checked_in_one_line(tmp_path, capsys, doc, edit, match):
    edit(doc)
    path = tmp_path / "bad.scene.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(ValueError) as exc:
        read_scene_file(path)
    msg = str(exc.value)
    assert match in msg and "\n" not in msg and str(path) in msg
    capsys.readouterr()
    assert main(["render", "--scene", str(path), "-q", "-o", str(tmp_path / "x.exr")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0]
    assert not (tmp_path / "x.exr").exists()


def test_not_json_and_too_big_are_one_line(tmp_path):
    bad = tmp_path / "a.scene.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match="not a scene file"):
        read_scene_file(bad)
    bad.write_text(" " * (1 << 19))
    with pytest.raises(ValueError, match="more than"):
        read_scene_file(bad)
    with pytest.raises(ValueError, match="scene file: not a microcyl scene file"):
        scene_from_dict([1, 2])


def test_scene_name_and_scene_file_together_are_refused(tmp_path, capsys, doc):
    path = tmp_path / "s.scene.json"
    path.write_text(json.dumps(doc))
    assert main(["render", "cylinder", "velvet", "--scene", str(path), "-q",
                 "-o", str(tmp_path / "x.exr")]) == 1
    assert "give no scene name with --scene" in capsys.readouterr().err
