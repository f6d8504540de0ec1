"""ALTA 1-D slices: the MERL pink-felt back-scatter slice, round trip, bad files."""

import numpy as np
import pytest

import gonio


def test_pink_felt_slice(shared_data, tmp_path):
    path = shared_data / "merl-slice" / "pink-felt-1d.alta"
    t = gonio.read(path)
    rows = np.array([[float(x) for x in ln.split()] for ln in path.read_text().splitlines()
                     if ln.strip() and not ln.startswith("#")])
    assert len(t) == rows.shape[0] == 90
    np.testing.assert_array_equal(t.values, rows[:, 1:])
    np.testing.assert_array_equal(t.wi, t.wo)
    ang = t.angles
    np.testing.assert_allclose(np.cos(ang[:, 0]), rows[:, 0], atol=1e-12)
    np.testing.assert_allclose(ang[:, 1], 0.0, atol=1e-12)
    assert t.meta["missing_values"] == 0
    out = tmp_path / "copy.alta"
    gonio.write(t, out)
    back = gonio.read(out)
    np.testing.assert_allclose(back.values, t.values, rtol=1e-14)
    np.testing.assert_allclose(back.wi, t.wi, atol=1e-14)


def test_write_refuses_non_backscatter(tmp_path):
    t = gonio.Table([[0, 0, 1.0]], [[0.6, 0, 0.8]], [[0.1, 0.1, 0.1]])
    with pytest.raises(ValueError, match="wi != wo"):
        gonio.write(t, tmp_path / "x.alta")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("text, pattern", [
    ("#DIM 2 3\n#PARAM_IN COS_TH\n#PARAM_OUT RGB_COLOR\n0.5 1 2 3\n", "#DIM is 2 3"),
    ("#DIM 1 3\n#PARAM_OUT RGB_COLOR\n0.5 1 2 3\n", "#PARAM_IN is missing"),
    ("#DIM 1 3\n#PARAM_IN COS_TH\n#PARAM_OUT RGB_COLOR\n0.5 1 2 3\n0.4 1 2\n", "line 5"),
    ("#DIM 1 3\n#PARAM_IN COS_TH\n#PARAM_OUT RGB_COLOR\n0.5 1 2 q\n", "line 4: not a number"),
    ("#DIM 1 3\n#PARAM_IN COS_TH\n#PARAM_OUT RGB_COLOR\n", "no data"),
    ("#DIM 1 3\n#PARAM_IN COS_TH\n#PARAM_OUT RGB_COLOR\n1.5 1 2 3\n", "outside"),
])
def test_bad_files(tmp_path, text, pattern):
    p = tmp_path / "bad.alta"
    p.write_text(text)
    with pytest.raises(gonio.FormatError, match="bad.alta: .*" + pattern):
        gonio.read(p)
