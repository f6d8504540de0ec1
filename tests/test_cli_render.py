"""Tests of the ``microcyl render`` verb (reports.cmd_render)."""

import time

import numpy as np
import pytest
from PIL import Image

from reports import imageio
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
    (["cylinder", "tweed"], "fabric 'tweed' is unknown"),
    (["cylinder", "velvet", "--width", "1920"], "width=1920 is beyond the limit"),
    (["cylinder", "velvet", "--height", "1080"], "height=1080 is beyond the limit"),
    (["cylinder", "velvet", "--spp", "0"], "spp=0"),
    (["cylinder", "velvet", "--masking", "maybe"], "--masking 'maybe': must be on or off"),
])
def test_bad_input_is_one_line_at_once(tmp_path, capsys, argv, match):
    out = tmp_path / "x.exr"
    t0 = time.perf_counter()
    status = main(["render", *argv, "-o", str(out)])
    line = _one_line_error(capsys, status)
    assert match in line
    assert time.perf_counter() - t0 < 5
    assert list(tmp_path.iterdir()) == []


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
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.exr", "c.png"]
    img = imageio.read_exr(out)
    assert img.shape == (9, 16, 3) and img.dtype == np.float32 and img.max() > 0
    assert np.asarray(Image.open(tmp_path / "c.png")).shape == (9, 16, 3)


@needs_brdf
def test_masking_toggle_changes_the_render(tmp_path):
    import brdf
    from reports.render import render
    on = brdf.fabric("velvet", tangent_samples=4)
    kw = dict(width=16, height=9, spp=1, progress=False)
    a = render("cylinder", on, **kw)
    b = render("cylinder", on.replace(masking=False), **kw)
    assert not np.allclose(a, b)
    assert main(["render", "cylinder", "velvet", "--masking", "off", "--tangent-samples", "4",
                 *SMALL, "-o", str(tmp_path / "m.png")]) == 0
    assert [p.name for p in tmp_path.iterdir()] == ["m.png"]


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
    import reports.render
    monkeypatch.setattr(reports.render, "resolve_fabric", lambda name, **kw: _Interrupting())
    status = main(["render", "cylinder", "velvet", "--width", "200", "--height", "100",
                   "--spp", "1", "--quiet", "--workers", workers, "-o", str(tmp_path / "x.exr")])
    assert status == 130
    assert "interrupted" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
