"""Tests of the ``microcyl render`` verb (reports.cli.render)."""

import time

import numpy as np
import pytest
from PIL import Image

from reports.render import imageio
from reports.cli import main


def _has_presets():
    try:
        import brdf
    except ImportError:  # pragma: no cover
        return False
    return hasattr(brdf, "fabric") and "velvet" in getattr(brdf, "PRESETS", ())


needs_brdf = pytest.mark.skipif(not _has_presets(), reason="brdf presets not available yet")

SMALL = ["--width", "16", "--height", "9", "--spp", "1", "--quiet"]


def _one_line_error(capsys, status, expected_status=1):
    err = capsys.readouterr().err
    assert status == expected_status
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("microcyl render: error:")
    return lines[0]


@pytest.mark.parametrize("argv, match", [
    (["teapot", "velvet"], "scene 'teapot' is unknown"),
    (["cylinder", "tweed"], "FABRIC 'tweed': not a preset"),
    (["cylinder", "velvet", "--width", "1920"], "width=1920 is beyond the limit"),
    (["cylinder", "velvet", "--height", "1080"], "height=1080 is beyond the limit"),
    (["cylinder", "velvet", "--spp", "0"], "spp=0"),
])
def test_bad_input_is_one_line_at_once(tmp_path, capsys, argv, match):
    out = tmp_path / "x.exr"
    t0 = time.perf_counter()
    status = main(["render", *argv, "-o", str(out)])
    line = _one_line_error(capsys, status)
    assert match in line
    assert time.perf_counter() - t0 < 5
    assert list(tmp_path.iterdir()) == []


def test_bad_variant_flag_is_a_usage_error(tmp_path, capsys):
    """The variant flags are every verb's (reports.cli.options.add_fabric_options): a bad value is
    argparse's one-line usage error, status 2."""
    status = main_status(["render", "cylinder", "velvet", "--masking", "maybe",
                          "-o", str(tmp_path / "x.exr")])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err and "--masking: expected on or off" in err
    assert list(tmp_path.iterdir()) == []


def main_status(argv):
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def test_unwritable_or_missing_folder(tmp_path, capsys):
    status = main(["render", "cylinder", "velvet", *SMALL, "-o", str(tmp_path / "no" / "x.exr")])
    assert "does not exist" in _one_line_error(capsys, status)
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    import os
    if os.access(locked, os.W_OK):  # running as root: permissions are not enforced
        pytest.skip("cannot make an unwritable folder as this user")
    status = main(["render", "cylinder", "velvet", *SMALL, "-o", str(locked / "x.exr")])
    assert "not writable" in _one_line_error(capsys, status)


def test_bad_output_suffix(tmp_path, capsys):
    status = main(["render", "cylinder", "velvet", *SMALL, "-o", str(tmp_path / "x.jpg")])
    assert "must end in .exr or .png" in _one_line_error(capsys, status)


@needs_brdf
def test_render_writes_exr_and_png(tmp_path):
    out = tmp_path / "c.exr"
    assert main(["render", "cylinder", "velvet", "--masking", "off", "--tangent-samples", "4",
                 *SMALL, "-o", str(out)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.exr", "c.png", "c.scene.json"]
    img = imageio.read_exr(out)
    assert img.shape == (9, 16, 3) and img.dtype == np.float32 and img.max() > 0
    assert np.asarray(Image.open(tmp_path / "c.png")).shape == (9, 16, 3)


@needs_brdf
def test_masking_toggle_changes_the_render(tmp_path):
    import brdf
    from reports.render.engine import render
    on = brdf.fabric("velvet", tangent_samples=4)
    kw = dict(width=16, height=9, spp=1, progress=False)
    a = render("cylinder", on, **kw)
    b = render("cylinder", on.replace(masking=False), **kw)
    assert not np.allclose(a, b)
    assert main(["render", "cylinder", "velvet", "--masking", "off", "--tangent-samples", "4",
                 *SMALL, "-o", str(tmp_path / "m.png")]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.png", "m.scene.json"]


class _Interrupting:
    """A BRDF whose batched evaluations raise KeyboardInterrupt (as Ctrl-C would)."""

    def eval(self, wi, wo):
        if np.shape(wi)[0] > 1:
            raise KeyboardInterrupt
        return np.zeros(np.broadcast_shapes(np.shape(wi), np.shape(wo)))

    def replace(self, **changes):
        return self


@pytest.mark.parametrize("workers", ["1", "2"])
def test_interrupt_leaves_no_file(tmp_path, capsys, monkeypatch, workers):
    import reports.render.engine
    monkeypatch.setattr(reports.render.engine, "resolve_fabric", lambda name, **kw: _Interrupting())
    status = main(["render", "cylinder", "velvet", "--width", "200", "--height", "100",
                   "--spp", "1", "--quiet", "--workers", workers, "-o", str(tmp_path / "x.exr")])
    assert status == 130
    assert "interrupted" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


# -- --engine mitsuba ----------------------------------------------------------------------
@pytest.mark.parametrize("argv, match", [
    (["--engine", "povray"], "--engine 'povray': must be one of auto, builtin, mitsuba"),
    (["--variant", "scalar_rgb"], "--variant: only with --engine mitsuba"),
    (["--max-depth", "3"], "--max-depth: only with --engine mitsuba"),
    (["--engine", "mitsuba", "--max-depth", "0"], "--max-depth 0: must be -1"),
])
def test_engine_options_are_checked_at_once(tmp_path, capsys, argv, match):
    status = main(["render", "cylinder", "velvet", *SMALL, *argv, "-o", str(tmp_path / "x.exr")])
    assert match in _one_line_error(capsys, status)
    assert list(tmp_path.iterdir()) == []


def test_engine_mitsuba_without_mitsuba_is_one_line(tmp_path, capsys, monkeypatch):
    from reports.mitsuba import render as mitsuba_render
    monkeypatch.setattr(mitsuba_render, "have_mitsuba", lambda: False)
    status = main(["render", "cylinder", "velvet", *SMALL, "--engine", "mitsuba",
                   "-o", str(tmp_path / "x.exr")])
    line = _one_line_error(capsys, status)
    assert line.endswith("--engine mitsuba needs mitsuba (pip install mitsuba)")
    assert list(tmp_path.iterdir()) == []


def _mitsuba_llvm():
    from reports.mitsuba import render as mitsuba_render
    if not mitsuba_render.have_mitsuba():
        pytest.skip("mitsuba is not installed")
    ok, why = mitsuba_render.variant_works("llvm_ad_rgb")
    if not ok:
        pytest.skip(f"no usable LLVM for Dr.Jit ({why}); set DRJIT_LIBLLVM_PATH to libLLVM-19")


def test_engine_mitsuba_end_to_end(tmp_path):
    """`microcyl render cylinder velvet --engine mitsuba` as a user runs it (llvm_ad_rgb, 8
    bounces): EXR and PNG, finite and lit, the mean luminance of the built-in render of the
    same scene within the noise plus 5 % (direct light agrees within noise plus 1 %,
    tests/test_reports_mitsuba_render.py; the bounces add light: on this dim-sky scene, with a
    0.4 floor, about 1 %), and the cylinder's shadow on the floor lit by the sky."""
    import os
    import subprocess
    import sys
    _mitsuba_llvm()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, PYTHONPATH=root)
    from reports.render.engine import render
    from reports.render.scenes import make_scene
    from test_reports_mitsuba_render import agree, shadow_mask
    out = tmp_path / "c.exr"
    p = subprocess.run([sys.executable, "-m", "reports", "render", "cylinder", "velvet",
                        "--engine", "mitsuba", "--width", "64", "--height", "36", "--spp", "4",
                        "-o", str(out)], capture_output=True, text=True, timeout=600, env=env)
    assert p.returncode == 0, p.stderr
    assert "mitsuba llvm_ad_rgb" in p.stderr and "wrote" in p.stderr
    assert sorted(f.name for f in tmp_path.iterdir()) == ["c.exr", "c.png", "c.scene.json"]
    img = imageio.read_exr(out)
    assert img.shape == (36, 64, 3) and np.all(np.isfinite(img)) and img.max() > 0
    png = np.asarray(Image.open(tmp_path / "c.png"))
    assert png.shape == (36, 64, 3) and png.max() > 0
    ref = render("cylinder", "velvet", width=64, height=36, spp=4, progress=False, workers=1)
    assert agree(img, ref, extra=0.05) > -0.05
    from reports.colour import luminance
    shadow = shadow_mask(make_scene("cylinder"), 64, 36)
    assert luminance(img)[shadow].mean() > 0.5 * luminance(ref)[shadow].mean() > 0


def _cli(*argv, cwd):
    import os
    import subprocess
    import sys
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return subprocess.run([sys.executable, "-m", "reports", *argv], cwd=cwd, timeout=300,
                          env=dict(os.environ, PYTHONPATH=root), capture_output=True, text=True)


@needs_brdf
def test_render_a_fit_folder_and_its_export(fit_folder, tmp_path):
    """`microcyl render sphere FIT_DIR` (progress bar on) renders the fit's median fabric: the
    image of velvet with the fit's options and the medians of FitResult.summary put in here,
    by hand; `microcyl export`'s JSON renders the same image, and a variant flag given on the
    command line applies on top of the fit's options (its masking is off)."""
    import brdf
    from reports.render.engine import render
    folder, res = fit_folder
    gs, kd = (res.summary[k]["median"] for k in ("gamma_s1", "kd1"))
    base = brdf.fabric("velvet", masking=False, rotation=0.25)
    t1, t2 = base.threads
    want = base.replace(threads=[t1.replace(gamma_s=gs, kd=kd), t2.replace(kd=kd)])
    size = ["--width", "48", "--height", "27", "--spp", "2", "--workers", "1"]
    kw = dict(width=48, height=27, spp=2, progress=False, workers=1)
    p = _cli("render", "sphere", str(folder), *size, "-o", "fit.exr", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "wrote" in p.stderr and "%" in p.stderr           # the progress bar and the files
    got = imageio.read_exr(tmp_path / "fit.exr")
    ref = render("sphere", want, **kw)
    assert got.max() > 0 and np.array_equal(got, ref.astype(np.float32))
    assert not np.array_equal(got, render("sphere", base, **kw).astype(np.float32))
    assert _cli("export", str(folder), "-o", "fabric.json", cwd=tmp_path).returncode == 0
    p = _cli("render", "sphere", "fabric.json", *size, "--quiet", "-o", "json.exr", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert np.array_equal(imageio.read_exr(tmp_path / "json.exr"), got)
    p = _cli("render", "sphere", str(folder), *size, "--quiet", "--masking", "on", "-o",
             "masked.exr", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    masked = render("sphere", want.replace(masking=True), **kw).astype(np.float32)
    assert np.array_equal(imageio.read_exr(tmp_path / "masked.exr"), masked)
    assert not np.array_equal(masked, got)


@pytest.mark.parametrize("content, match", [
    (None, "not a fit folder"),                       # a folder without results.json
    ("[1, 2]", "must hold a microcylinder plugin dictionary"),
    ('{"type": "diffuse"}', "got 'diffuse'"),
    ('{"fabric": "velvet", "eta1": "glass"}', "eta1 must be a number; got 'glass'"),
    ('{"fabric": "velvet", "eta2": 0.5}', "thread 2: eta must be"),
    ("{nope", "unreadable JSON"),
])
def test_a_bad_fit_folder_or_dictionary_is_one_line(tmp_path, capsys, content, match):
    source = tmp_path / "src"
    if content is None:
        source.mkdir()
    else:
        source = tmp_path / "fabric.json"
        source.write_text(content)
    status = main(["render", "patch", str(source), *SMALL, "-o", str(tmp_path / "x.png")])
    line = _one_line_error(capsys, status)
    assert match in line and str(source) in line
    assert not (tmp_path / "x.png").exists()


# -- exposure ------------------------------------------------------------------------------
def _interior_cloth(scene_name, width, height, parts=None, centres=False):
    """Pixels whose four corners' camera rays all hit the cloth first (independent of the
    renderer's coverage mask); ``parts``: on those parts of it alone; ``centres``: pixels
    whose centre's ray does instead."""
    from reports.render.scenes import make_scene
    from reports.render.tracing import intersect
    scene = make_scene(scene_name)
    ys, xs = np.mgrid[0:height + 1, 0:width + 1] + (0.5 if centres else 0.0)
    o, d = scene.camera.rays(xs.ravel().astype(float), ys.ravel().astype(float), width, height)
    t, pid, part = intersect(scene.primitives, np.ascontiguousarray(o),
                             np.ascontiguousarray(d), 1e-9)
    cloth = np.array([p.material == "cloth" for p in scene.primitives])
    c = np.isfinite(t) & cloth[np.maximum(pid, 0)]
    if parts is not None:
        c &= np.isin(part, parts)
    c = c.reshape(height + 1, width + 1)
    if centres:
        return c[:-1, :-1]
    return c[:-1, :-1] & c[1:, :-1] & c[:-1, 1:] & c[1:, 1:]


def _png_linear(path):
    import colour
    return colour.cctf_decoding(np.asarray(Image.open(path)) / 255.0, function="sRGB")


def test_exposure_is_automatic_from_the_cloth(tmp_path):
    """By default the 99th percentile of max(R, G, B) over the cloth's pixels shows at 0.9 in
    the PNG (velvet: brightened more than 2 stops), on the cylinder its side's (part 0), not its
    cap's, seen edge-on, where velvet glows; the EXR stays linear and records the stops."""
    out = tmp_path / "c.exr"
    assert main(["render", "cylinder", "velvet", "--width", "96", "--height", "54",
                 "--spp", "2", "--quiet", "-o", str(out)]) == 0
    img = imageio.read_exr(out)
    attrs = imageio.read_exr_attributes(out)
    assert attrs["microcyl_exposure_mode"] == "auto"
    stops = attrs["microcyl_exposure_stops"]
    assert attrs["microcyl_exposure_scale"] == pytest.approx(2.0 ** stops)
    inside = _interior_cloth("cylinder", 96, 54, parts=[0], centres=True)
    assert inside.sum() > 300
    cap = _interior_cloth("cylinder", 96, 54, parts=[1])
    assert np.median(img[cap].max(axis=1)) * 2.0 ** stops > 1      # velvet's cap clips
    p99 = np.percentile(img[inside].max(axis=1), 99)
    assert p99 * 2.0 ** stops == pytest.approx(0.9, rel=0.03)
    png = _png_linear(out.with_suffix(".png"))
    assert np.percentile(png[inside].max(axis=1), 99) == pytest.approx(0.9, abs=0.03)
    assert stops > 2                     # velvet is dark: the PNG brightens it


@pytest.mark.parametrize("given, stops", [("1.5", 1.5), ("4x", 2.0), ("-1", -1.0)])
def test_exposure_override(tmp_path, given, stops):
    out = tmp_path / "s.exr"
    assert main(["render", "sphere", "linen_plain", *SMALL, "--exposure", given,
                 "-o", str(out)]) == 0
    attrs = imageio.read_exr_attributes(out)
    assert attrs["microcyl_exposure_mode"] == "manual"
    assert attrs["microcyl_exposure_stops"] == pytest.approx(stops)
    img = imageio.read_exr(out)
    expect = np.round(imageio.encode_srgb(img * 2.0 ** stops) * 255)
    assert np.array_equal(np.asarray(Image.open(out.with_suffix(".png"))), expect)


@pytest.mark.parametrize("given", ["bright", "0x", "-2x", "65", "nan"])
def test_bad_exposure_is_one_line(tmp_path, capsys, given):
    status = main(["render", "sphere", "velvet", *SMALL, f"--exposure={given}",
                   "-o", str(tmp_path / "x.exr")])
    assert "--exposure" in _one_line_error(capsys, status)
    assert list(tmp_path.iterdir()) == []


# -- one option name, one default: --engine (render and report) ---------------------------
def _parsed(argv):
    import argparse

    from reports.cli import model as model_cli, render as render_cli
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers()
    render_cli.register(sub)
    model_cli.register(sub)
    return parser, parser.parse_args(argv)


def test_render_and_report_name_the_engine_alike_with_one_default(capsys):
    from reports.cli.options import DEFAULT_ENGINE
    _, r = _parsed(["render", "cylinder", "velvet", "-o", "x.png"])
    _, q = _parsed(["report"])
    assert r.engine == q.engine == DEFAULT_ENGINE
    _, q = _parsed(["report", "--engine", "mitsuba"])
    assert q.engine == "mitsuba"


def test_report_render_engine_is_a_hidden_deprecated_alias(capsys):
    parser, q = _parsed(["report", "--render-engine", "builtin"])
    assert q.engine == "builtin"
    assert "--render-engine is deprecated; use --engine" in capsys.readouterr().err
    sub = next(a for a in parser._actions if a.choices and "report" in a.choices)
    text = sub.choices["report"].format_help()
    assert "--engine" in text and "--render-engine" not in text


def test_render_engine_auto_takes_the_rule_of_auto_engine(tmp_path, monkeypatch):
    """``--engine auto`` is resolved by reports.mitsuba.render.auto_engine (here: no
    Mitsuba, so the built-in engine, which renders)."""
    from reports.mitsuba import render as mr
    monkeypatch.setattr(mr, "have_mitsuba", lambda: False)
    assert mr.auto_engine(__import__("brdf").fabric("velvet")) == "builtin"
    out = tmp_path / "x.png"
    assert main(["render", "patch", "velvet", *SMALL, "--engine", "auto", "-o", str(out)]) == 0
    assert out.is_file()
