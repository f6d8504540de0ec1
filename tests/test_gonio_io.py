"""gonio.read / gonio.write dispatch on the suffix; conversions between formats."""

import numpy as np
import pytest

import gonio
from tests._gonio_helpers import random_table


def test_unknown_suffix_lists_known(tmp_path):
    t = random_table(0)
    with pytest.raises(ValueError, match=r"unknown table format '.txt'.*\.exr.*\.csv.*\.binary"):
        gonio.write(t, tmp_path / "t.txt")
    (tmp_path / "t.json").write_text("{}")
    with pytest.raises(ValueError, match=r"unknown table format '.json'; known: .exr"):
        gonio.read(tmp_path / "t.json")
    with pytest.raises(FileNotFoundError):
        gonio.read(tmp_path / "absent.exr")


def test_exr_csv_exr(tmp_path):
    t = random_table(3)
    gonio.write(t, tmp_path / "a.exr")
    gonio.write(gonio.read(tmp_path / "a.exr"), tmp_path / "b.csv")
    back = gonio.read(tmp_path / "b.csv")
    ok = np.isfinite(t.values)
    np.testing.assert_allclose(back.values[ok], t.values[ok], rtol=1e-6)
    assert back.meta["source"] == "test"


def test_rgl_as_table(shared_data):
    t = gonio.read(shared_data / "rgl" / "acrylic_felt_white_rgb.bsdf", step=15)
    brdf = gonio.load_rgl(shared_data / "rgl" / "acrylic_felt_white_rgb.bsdf")
    np.testing.assert_allclose(t.values, brdf.eval(t.wi, t.wo))
    assert len(t) == 7 * 6 * 24 and t.meta["missing_values"] == 0


def test_write_needs_table(tmp_path):
    with pytest.raises(ValueError, match="holds a Table"):
        gonio.write(object(), tmp_path / "x.exr")
    with pytest.raises(ValueError, match="Table or an object with eval"):
        gonio.write(object(), tmp_path / "x.binary")


def test_read_refuses_an_option_its_format_does_not_take(tmp_path, shared_data):
    """Each option is checked against the file's format by name, before the file is read
    (even a missing file is refused for its option first)."""
    t = random_table(1)
    gonio.write(t, tmp_path / "t.csv")
    gonio.write(t, tmp_path / "t.exr")
    cases = [(tmp_path / "t.csv", {"stride": 2}, r"stride applies to a MERL \.binary only, "
                                                 r"not to t\.csv"),
             (tmp_path / "t.exr", {"sample": 3}, r"sample applies to a CUReT abrdf\.dat only"),
             (tmp_path / "t.csv", {"step": 5}, r"step applies to an RGL \.bsdf only"),
             (tmp_path / "none.alta", {"stride": 2}, r"stride applies to a MERL"),
             (tmp_path / "t.csv", {"colour": 1}, r"unknown option 'colour' for t\.csv; its "
                                                 r"reader takes none"),
             (shared_data / "curet" / "abrdf.dat", {"sample": 44, "step": 5},
              r"step applies to an RGL \.bsdf only, not to abrdf\.dat")]
    for path, options, message in cases:
        with pytest.raises(ValueError, match=message):
            gonio.read(path, **options)
    with pytest.raises(ValueError, match=r"unknown option 'strid' for x\.binary; its reader "
                                         r"takes stride, keep_missing"):
        gonio.read(tmp_path / "x.binary", strid=2)
    assert len(gonio.read(shared_data / "curet" / "abrdf.dat", sample=44)) == 205
