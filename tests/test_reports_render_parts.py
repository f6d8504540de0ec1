"""The built-in renderer's small parts, each against an answer worked out by hand: vec3's
bases, the cameras' rays, the lights' irradiance (inverse square, the disc's mean), the
pixel samples' strata, a worker that dies with its parent; and a render written as files."""

import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import brdf
from reports.render import (cameras, files, imageio, lights, pixelsamples, scenes, vec3,
                            workerexit)

REPO = Path(__file__).resolve().parents[1]


def test_basis_is_right_handed_orthonormal_and_looks_at_the_target():
    f, r, u = vec3.basis((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    np.testing.assert_allclose(f, [0, 0, -1])          # toward the target
    np.testing.assert_allclose(r, [1, 0, 0])           # x to the right of a view down -z
    np.testing.assert_allclose(u, [0, 1, 0])
    f, r, u = vec3.basis((0.0, 5.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))   # up along f
    m = np.stack([f, r, u])
    np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(vec3.dot(vec3.unit([[3.0, 4.0, 0.0]]), [[1.0, 0, 0]]), [0.6])


def test_pinhole_rays_span_the_field_of_view():
    cam = cameras.PinholeCamera(position=(0.0, 0.0, 4.0), fov=90.0)
    o, d = cam.rays(np.array([50.0, 50.0, 0.0]), np.array([50.0, 0.0, 50.0]), 100, 100)
    np.testing.assert_allclose(o, [[0, 0, 4]] * 3)
    np.testing.assert_allclose(d[0], [0, 0, -1])                          # the centre
    s = 1 / math.sqrt(2)                                                  # tan(45 deg) = 1
    np.testing.assert_allclose(d[1], [0, s, -s], atol=1e-12)              # the top edge
    np.testing.assert_allclose(d[2], [-s, 0, -s], atol=1e-12)             # the left edge


def test_orthographic_rays_are_parallel_over_the_extent():
    cam = cameras.OrthographicCamera(position=(0.0, 0.0, 4.0), extent=2.0)
    o, d = cam.rays(np.array([0.0, 200.0]), np.array([0.0, 100.0]), 200, 100)
    np.testing.assert_allclose(d, [[0, 0, -1]] * 2)
    np.testing.assert_allclose(o, [[-2, 1, 4], [2, -1, 4]])   # width 2 x aspect 2 = 4


def test_point_light_inverse_square_and_disc_mean_irradiance():
    rng = np.random.default_rng(0)
    light = lights.PointLight(position=(0.0, 0.0, 2.0), intensity=8.0)
    wi, dist, E = light.sample(np.zeros((1, 3)), rng)
    np.testing.assert_allclose(wi, [[0, 0, 1]])
    np.testing.assert_allclose(dist, [2.0])
    np.testing.assert_allclose(E, [[2.0, 2.0, 2.0]])                   # 8 / 2^2
    disc = lights.PointLight(position=(0.0, 0.0, 1.0), intensity=1.0, radius=1.0)
    wi, _, E = disc.sample(np.zeros((200000, 3)), rng)
    # E is normal to each sample's direction: times cos theta_r (wi_z) its mean is the
    # irradiance of a Lambertian disc of radiance 1/pi at height h = R = 1 on its axis,
    # R^2 / (R^2 + h^2) = 1/2
    assert abs((E[:, 0] * wi[:, 2]).mean() - 0.5) < 0.005


def test_directional_light_is_at_infinity_with_constant_irradiance():
    light = lights.DirectionalLight(direction=(0.0, 3.0, 4.0), irradiance=(1.0, 2.0, 3.0))
    wi, dist, E = light.sample(np.zeros((4, 3)), np.random.default_rng(0))
    np.testing.assert_allclose(wi, [[0, 0.6, 0.8]] * 4)
    assert np.all(dist == vec3.INF)
    np.testing.assert_allclose(E, [[1, 2, 3]] * 4)


def test_pixel_samples_are_stratified():
    rng = np.random.default_rng(1)
    jx, jy = pixelsamples.sample_offsets(rng, 5, 8)
    for j in (jx, jy):          # n-rooks: one sample in each eighth of [0, 1), per pixel
        assert sorted(np.floor(j * 8).astype(int)[2].tolist()) == list(range(8))
    u = pixelsamples.lhs(rng, 3, 4, dims=2)
    assert u.shape == (3, 4, 2)
    assert all(sorted(np.floor(u[p, :, k] * 4).astype(int).tolist()) == [0, 1, 2, 3]
               for p in range(3) for k in range(2))
    weight, u_diffuse, u_cloth = pixelsamples.sky_plan(rng, 2, 8, 2)
    assert weight.reshape(2, 8).sum(axis=1).tolist() == [8.0, 8.0]    # spp / sky_spp each
    assert u_diffuse.shape == (16, 2) and u_cloth.shape == (16, 4)


def test_a_worker_dies_with_its_killed_parent(tmp_path):
    """A parent starts a child that calls exit_with_parent, then is SIGKILLed: the child
    is gone within a few seconds (it would sleep 60)."""
    pidfile = tmp_path / "child.pid"
    child = ("import os, time; from reports.render.workerexit import exit_with_parent; "
             f"exit_with_parent(os.getppid()); "
             f"open({str(pidfile)!r}, 'w').write(str(os.getpid())); time.sleep(60)")
    parent = ("import subprocess, sys, time; "
              f"subprocess.Popen([sys.executable, '-c', {child!r}]); time.sleep(60)")
    env = dict(os.environ, PYTHONPATH=str(REPO))
    p = subprocess.Popen([sys.executable, "-c", parent], env=env)
    try:
        for _ in range(200):
            if pidfile.exists() and pidfile.read_text():
                break
            time.sleep(0.05)
        pid = int(pidfile.read_text())
        p.kill()
        p.wait()
        for _ in range(100):
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                break
            if Path(f"/proc/{pid}/stat").is_file() and \
                    Path(f"/proc/{pid}/stat").read_text().split()[2] == "Z":
                break                      # a zombie: dead, waiting for init to reap it
            time.sleep(0.05)
        else:
            os.kill(pid, 9)
            raise AssertionError("the worker outlived its killed parent")
    finally:
        if p.poll() is None:
            p.kill()
    assert callable(workerexit.exit_with_parent)


def test_render_to_files_writes_the_exr_and_its_png_with_the_exposure(tmp_path):
    """reports.render.files: a tiny built-in render of the patch; out.exr is linear with the
    PNG's exposure in its header, out.png and out.scene.json beside it; a given exposure is
    kept, else it is automatic; ``out.png`` alone is written without an EXR."""
    fab = brdf.fabric("velvet")
    scene = scenes.make_scene("patch")
    expo, written = files.render_to_files(scene, fab, tmp_path / "a.exr", stops=1.5, width=32,
                                          height=18, spp=1, workers=1)
    assert [p.name for p in written] == ["a.exr", "a.png", "a.scene.json"]
    assert expo.stops == 1.5
    assert imageio.read_exr_attributes(tmp_path / "a.exr")["microcyl_exposure_stops"] == 1.5
    linear = imageio.read_exr(tmp_path / "a.exr")
    assert linear.shape == (18, 32, 3) and linear.max() > 0
    auto, written = files.render_to_files(scene, fab, tmp_path / "b.png", width=32, height=18,
                                          spp=1, workers=1)
    assert [p.name for p in written] == ["b.png", "b.scene.json"]
    assert not (tmp_path / "b.exr").exists()
    assert auto.mode == "auto" and auto.stops != 1.5
