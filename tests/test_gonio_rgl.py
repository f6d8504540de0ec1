"""RGL tensor files: parsing, bad files, and f_r against Mitsuba 3's `measured` plugin."""

import json
from pathlib import Path

import numpy as np
import pytest

import gonio
from gonio.rgl import read_tensor_file

FIXTURE = Path(__file__).with_name("fixtures") / "rgl_mitsuba.json"


@pytest.fixture(scope="module")
def rgl_dir(shared_data):
    return shared_data / "rgl"


def test_tensor_fields(rgl_dir):
    f = read_tensor_file(rgl_dir / "acrylic_felt_white_rgb.bsdf")
    assert f["rgb"].shape == (1, 8, 3, 32, 32)
    assert f["vndf"].shape == (1, 8, 128, 128)
    np.testing.assert_allclose(f["theta_i"][[0, -1]], [0.0, np.pi / 2], atol=1e-6)
    assert bytes(f["description"]).decode().startswith("White acrylic felt")


def test_agrees_with_mitsuba_fixture(rgl_dir):
    cases = json.loads(FIXTURE.read_text())["cases"]
    assert len(cases) == 36
    by_file = {}
    for c in cases:
        by_file.setdefault(c["file"], []).append(c)
    for name, group in by_file.items():
        brdf = gonio.load_rgl(rgl_dir / name)
        wi = np.array([c["wi"] for c in group])
        wo = np.array([c["wo"] for c in group])
        ref = np.array([c["f_r"] for c in group])
        got = brdf.eval(wi, wo)
        assert got.shape == (len(group), 3)
        assert np.all(ref > 0)
        np.testing.assert_allclose(got, ref, rtol=0.01, err_msg=name)
        # Mitsuba's own convention too: viewer first, f_r * cos(light).
        np.testing.assert_allclose(brdf.eval_mitsuba(wo, wi),
                                   [c["mitsuba_eval"] for c in group], rtol=0.01)


def test_below_horizon_and_broadcast(rgl_dir):
    brdf = gonio.load_rgl(rgl_dir / "acrylic_felt_pink_rgb.bsdf")
    up = np.array([0.0, 0.0, 1.0])
    down = np.array([0.6, 0.0, -0.8])
    assert np.all(brdf.eval(down, up) == 0) and np.all(brdf.eval(up, down) == 0)
    out = brdf.eval(np.tile(up, (4, 5, 1)), up)
    assert out.shape == (4, 5, 3)
    # isotropic: rotating both directions about z leaves f_r unchanged
    wi = np.array([0.5, 0.1, 0.86]); wo = np.array([-0.3, 0.4, 0.866])
    rot = lambda w, a: np.array([w[0] * np.cos(a) - w[1] * np.sin(a),
                                 w[0] * np.sin(a) + w[1] * np.cos(a), w[2]])
    np.testing.assert_allclose(brdf.eval(rot(wi, 1.1), rot(wo, 1.1)), brdf.eval(wi, wo),
                               rtol=1e-4)


def test_bad_files(tmp_path, rgl_dir):
    good = (rgl_dir / "acrylic_felt_white_rgb.bsdf").read_bytes()
    bad = tmp_path / "magic.bsdf"
    bad.write_bytes(b"not_a_tensor" + good[12:])
    with pytest.raises(gonio.FormatError, match="magic.bsdf.*wrong magic"):
        gonio.load_rgl(bad)
    short = tmp_path / "short.bsdf"
    short.write_bytes(good[: len(good) // 2])
    with pytest.raises(gonio.FormatError, match="short.bsdf.*(truncated|wrong size)"):
        gonio.load_rgl(short)
    tiny = tmp_path / "tiny.bsdf"
    tiny.write_bytes(good[:40])
    with pytest.raises(gonio.FormatError, match="tiny.bsdf"):
        gonio.load_rgl(tiny)


def test_eval_of_bad_directions(rgl_dir):
    """NaN, infinite or zero directions give NaN (as brdf.Fabric.eval), not an IndexError;
    non-unit ones are normalized; grazing ones stay finite; bad shapes are a ValueError."""
    felt = gonio.load_rgl(rgl_dir / "acrylic_felt_white_rgb.bsdf")
    wo = np.array([0.0, 0.6, 0.8])
    wi = np.array([[np.nan, 0, 1], [0, 0, np.inf], [0, 0, 0], [0.6, 0, 0.8], [3.0, 0, 4.0],
                   [1.0, 0.0, 1e-200], [0.0, 0.0, -1.0]])
    got = felt.eval(wi, wo)
    assert np.isnan(got[:3]).all() and np.isnan(felt.eval(wo, wi)[:3]).all()
    np.testing.assert_allclose(got[4], got[3], rtol=1e-13)
    assert np.isfinite(got[5]).all() and (got[6] == 0).all()
    assert np.isnan(felt.eval_mitsuba(wi, wo)[:3]).all()
    with pytest.raises(ValueError, match="wi must have shape"):
        felt.eval([0.0, 1.0], wo)
    with pytest.raises(ValueError, match="wi_m and wo_m must broadcast"):
        felt.eval_mitsuba(np.zeros((2, 3)), np.zeros((3, 3)))
