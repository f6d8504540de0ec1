"""Native OpenEXR tables: exact float32 round trip, bad files."""

import numpy as np
import pytest

import gonio
from gonio.exr import read_exr, write_exr
from tests._gonio_helpers import random_table


def test_round_trip_exact_at_float32(tmp_path):
    t = random_table(1)
    p = tmp_path / "t.exr"
    gonio.write(t, p)
    back = gonio.read(p)
    f32 = lambda a: np.asarray(a, np.float32)  # noqa: E731
    np.testing.assert_array_equal(f32(back.values), f32(t.values))
    np.testing.assert_array_equal(f32(back.sigma), f32(t.sigma))
    np.testing.assert_array_equal(f32(back.angles), f32(t.angles))
    np.testing.assert_allclose(back.wi, t.wi, atol=1e-6)
    assert back.meta["source"] == "test" and back.meta["instrument"] == {"snr": 50.0}
    # NaN and negative values kept and flagged, and counted
    assert np.isnan(back.values[3, 1]) and back.values[7, 0] == np.float32(-0.5)
    assert back.meta["missing_values"] == 2
    assert np.count_nonzero(~back.valid) == 2
    # writing what was read gives the same channels again
    p2 = tmp_path / "t2.exr"
    gonio.write(back, p2)
    again = gonio.read(p2)
    np.testing.assert_array_equal(again.values, back.values)
    np.testing.assert_array_equal(again.angles.astype(np.float32), back.angles.astype(np.float32))


def test_no_sigma(tmp_path):
    t = random_table(2, sigma=False)
    write_exr(t, tmp_path / "a.exr")
    assert read_exr(tmp_path / "a.exr").sigma is None


def _write_channels(path, channels):
    import OpenEXR
    with OpenEXR.File({"type": OpenEXR.scanlineimage}, channels) as f:
        f.write(str(path))


def test_missing_channel(tmp_path):
    one = np.ones((1, 4), np.float32)
    p = tmp_path / "nochan.exr"
    _write_channels(p, {c: one for c in ("R", "G", "theta_i", "phi_i", "theta_o", "phi_o")})
    with pytest.raises(gonio.FormatError, match=r"nochan.exr.*missing channel.*\bB\b"):
        gonio.read(p)
    p2 = tmp_path / "noangle.exr"
    _write_channels(p2, {c: one for c in "RGB"})
    with pytest.raises(gonio.FormatError, match="noangle.exr.*missing channel.*theta_i"):
        gonio.read(p2)


def test_wrong_magic_and_truncated(tmp_path):
    t = random_table(3)
    p = tmp_path / "good.exr"
    write_exr(t, p)
    data = p.read_bytes()
    bad = tmp_path / "magic.exr"
    bad.write_bytes(b"GIF8" + data[4:])
    with pytest.raises(gonio.FormatError, match="magic.exr.*wrong magic"):
        gonio.read(bad)
    short = tmp_path / "short.exr"
    short.write_bytes(data[: len(data) // 2])
    with pytest.raises(gonio.FormatError, match="short.exr.*(truncated|corrupt)"):
        gonio.read(short)


def test_empty_table_refused(tmp_path):
    t = gonio.Table(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))
    with pytest.raises(ValueError, match="empty"):
        write_exr(t, tmp_path / "e.exr")
    assert list(tmp_path.iterdir()) == []


def test_tables_are_images_of_a_viewable_shape(tmp_path):
    """A sweep is one image row per incidence; scattered pairs a near-square block; the row
    count an int attribute; a file of the old 1 x n layout (rows as a string) still reads."""
    import OpenEXR
    import brdf
    import gonio
    fab = brdf.fabric("velvet")
    sweep = gonio.measure(fab, "full:15", gonio.Instrument(), progress=False)
    gonio.write(sweep, tmp_path / "sweep.exr")
    n_inc = len(np.unique(np.round(sweep.angles[:, :2], 9), axis=0))
    with OpenEXR.File(str(tmp_path / "sweep.exr"), separate_channels=True) as f:
        h, w = f.channels()["R"].pixels.shape
        assert f.header()["microcyl_rows"] == len(sweep)
        assert f.header()["microcyl_layout"] == "incidence rows"
    assert (h, w) == (n_inc, len(sweep) // n_inc)
    rng = np.random.default_rng(0)
    wi = brdf.frames.from_angles(rng.uniform(0, 1.4, 1000), rng.uniform(-3, 3, 1000))
    wo = brdf.frames.from_angles(rng.uniform(0, 1.4, 1000), rng.uniform(-3, 3, 1000))
    scattered = gonio.Table(wi, wo, fab.eval(wi, wo))
    gonio.write(scattered, tmp_path / "pairs.exr")
    with OpenEXR.File(str(tmp_path / "pairs.exr"), separate_channels=True) as f:
        assert f.channels()["R"].pixels.shape == (32, 32)       # ceil(sqrt(1000)) = 32
    for name, t in (("sweep.exr", sweep), ("pairs.exr", scattered)):
        back = gonio.read(tmp_path / name)
        np.testing.assert_allclose(back.values, t.values.astype(np.float32), rtol=0)
        np.testing.assert_allclose(back.wi, t.wi, atol=1e-6)
    # the first writer's layout: one scanline, rows as a string
    a = scattered.angles.astype(np.float32)
    chans = {c: np.ascontiguousarray(scattered.values[:, k].astype(np.float32)[None])
             for k, c in enumerate("RGB")}
    chans.update({c: np.ascontiguousarray(a[:, k][None])
                  for k, c in enumerate(("theta_i", "phi_i", "theta_o", "phi_o"))})
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
              "microcyl_format": "microcyl-table/1", "angle_unit": "radian",
              "microcyl_rows": "1000", "microcyl_meta": "{}"}
    with OpenEXR.File(header, chans) as f:
        f.write(str(tmp_path / "old.exr"))
    old = gonio.read(tmp_path / "old.exr")
    np.testing.assert_array_equal(old.values, gonio.read(tmp_path / "pairs.exr").values)


def test_deeply_nested_metadata_names_the_file(tmp_path):
    import OpenEXR
    chans = {c: np.zeros((1, 2), dtype=np.float32)
             for c in ("R", "G", "B", "theta_i", "phi_i", "theta_o", "phi_o")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
              "microcyl_format": "microcyl-table/1", "angle_unit": "radian",
              "microcyl_rows": "2", "microcyl_meta": "[" * 100_000 + "]" * 100_000}
    with OpenEXR.File(header, chans) as f:
        f.write(str(tmp_path / "deep.exr"))
    with pytest.raises(ValueError, match=r"deep\.exr.*microcyl_meta attribute is nested too "
                                         r"deeply"):
        gonio.read(tmp_path / "deep.exr")
