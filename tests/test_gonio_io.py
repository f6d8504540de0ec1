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
