"""CSV tables: round trip to printed precision, grey files, bad rows with line numbers."""

import numpy as np
import pytest

import gonio
from tests._gonio_helpers import random_table


def test_round_trip_to_printed_precision(tmp_path):
    t = random_table(4)
    p = tmp_path / "t.csv"
    gonio.write(t, p, digits=9)
    back = gonio.read(p)
    ok = np.isfinite(t.values)
    np.testing.assert_allclose(back.values[ok], t.values[ok], rtol=1e-8)
    assert np.isnan(back.values[3, 1]) and back.values[7, 0] == -0.5
    np.testing.assert_allclose(back.sigma, t.sigma, rtol=1e-8)
    np.testing.assert_allclose(back.wi, t.wi, atol=1e-8)
    np.testing.assert_allclose(back.wo, t.wo, atol=1e-8)
    assert back.meta["instrument"] == {"snr": 50.0} and back.meta["seed"] == 4
    assert back.meta["missing_values"] == 2
    header = [ln for ln in p.read_text().splitlines() if not ln.startswith("#")][0]
    assert header == "theta_i,phi_i,theta_o,phi_o,r,g,b,sigma_r,sigma_g,sigma_b"
    # fewer digits, coarser agreement, still the printed precision
    gonio.write(t, p, digits=4)
    np.testing.assert_allclose(gonio.read(p).values[ok], t.values[ok], rtol=6e-4)


def test_grey_and_hand_written(tmp_path):
    t = random_table(5, grey=True, sigma=False)
    p = tmp_path / "g.csv"
    gonio.write(t, p)
    assert "theta_i,phi_i,theta_o,phi_o,value" in p.read_text()
    p2 = tmp_path / "hand.csv"
    p2.write_text("# a hand-made file\n# lab: \"my lab\"\n\n"
                  "theta_i, phi_i, theta_o, phi_o, value, sigma\n"
                  "0,0,0,0,0.3,0.01\n"
                  "60,0,60,180,0.5,0.02\n"
                  "30,90,45,-90,,0.02\n")
    h = gonio.read(p2)
    assert len(h) == 3 and h.meta["lab"] == "my lab"
    np.testing.assert_allclose(h.values[:2], [[0.3] * 3, [0.5] * 3])
    assert np.all(np.isnan(h.values[2])) and h.meta["missing_values"] == 3
    np.testing.assert_allclose(h.wi[1], [np.sqrt(3) / 2, 0, 0.5], atol=1e-12)
    np.testing.assert_allclose(h.wo[1], [-np.sqrt(3) / 2, 0, 0.5], atol=1e-12)
    np.testing.assert_allclose(h.sigma[:, 0], [0.01, 0.02, 0.02])


@pytest.mark.parametrize("text, pattern", [
    ("theta_i,phi_i,theta_o,phi_o,r,g,b\n0,0,0,0,1,2,3\n0,0,0,0,1,2\n",
     r"line 3: expected 7 columns"),
    ("# c\ntheta_i,phi_i,theta_o,phi_o,r,g,b\n0,0,0,0,1,2,3\n\n0,0,x,0,1,2,3\n",
     r"line 5: 'x' is not a number"),
    ("theta_i,phi_i,theta_o,phi_o,r,g,b\n0,0,nan,0,1,2,3\n", r"line 2: angles"),
    ("theta_i,phi_i,theta_o,phi_o,red,g,b\n0,0,0,0,1,2,3\n", r"line 1: unknown column"),
    ("theta_i,phi_i,theta_o,r,g,b\n0,0,0,1,2,3\n", r"line 1: missing column.*phi_o"),
    ("theta_i,phi_i,theta_o,phi_o,r,g\n0,0,0,0,1,2\n", r"line 1: missing column.*\bb\b"),
    ("# only comments\n", r"no header"),
    ("theta_i,phi_i,theta_o,phi_o,value\n", r"no data rows"),
])
def test_bad_files(tmp_path, text, pattern):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(gonio.FormatError, match="bad.csv: " + pattern):
        gonio.read(p)


def test_binary_garbage(tmp_path):
    p = tmp_path / "bin.csv"
    p.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(gonio.FormatError, match="bin.csv"):
        gonio.read(p)


HEAD = "theta_i,phi_i,theta_o,phi_o,r,g,b\n"


@pytest.mark.parametrize("row, pattern", [
    ("200,0,30,180,1,2,3", r"line 2: theta_i = 200 is outside \[0, 180\] degrees"),
    ("30,0,-1,180,1,2,3", r"line 2: theta_o = -1 is outside"),
    ("30,400,30,180,1,2,3", r"line 2: phi_i = 400 is outside \[-360, 360\]"),
    ("3_0,0,30,180,1,2,3", r"line 2: '3_0' is not a number .*, in column theta_i"),
    ("30,0,30,180,1,2_0,3", r"line 2: '2_0' is not a number .*, in column g"),
    ("30,0,30,180,1,2,infinity", r"line 2: 'infinity' is not a number"),
    ("30,0,inf,180,1,2,3", r"line 2: angles must be finite numbers; got 'inf', in column theta_o"),
    ("30,0,1e400,180,1,2,3", r"line 2: theta_o = 1e400 is outside"),
    ("30,0,\u0663\u0660,180,1,2,3", r"line 2: '\u0663\u0660' is not a number"),
    ("30,0,0x1e,180,1,2,3", r"line 2: '0x1e' is not a number"),
])
def test_strict_numbers_and_angle_ranges(tmp_path, row, pattern):
    """Only decimal numbers; nan/inf only as values; angles within their ranges (the file, the
    line and the column are named)."""
    p = tmp_path / "bad.csv"
    p.write_text(HEAD + row + "\n", encoding="utf-8")
    with pytest.raises(gonio.FormatError, match="bad.csv: " + pattern):
        gonio.read_csv(p)


def test_values_may_be_nan_inf_or_empty_and_spaces_are_stripped(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text(HEAD + " 30 , -10 ,+45., .5e1 ,NaN,-inf,\n90,359.5,180,-360,1E-3,Inf,+inf\n")
    t = gonio.read_csv(p)
    np.testing.assert_allclose(np.degrees(t.angles[0]), [30, -10, 45, 5], atol=1e-12)
    assert np.isnan(t.values[0, 0]) and t.values[0, 1] == -np.inf and np.isnan(t.values[0, 2])
    assert t.values[1, 0] == 1e-3 and np.all(t.values[1, 1:] == np.inf)


def test_byte_order_mark_is_read(tmp_path):
    """A spreadsheet's UTF-8 byte-order mark before the header (or a comment) is not part of
    the first column's name."""
    row = "30,0,30,180,1,2,3\n"
    for text in (HEAD + row, "# source: \"sheet\"\n" + HEAD + row):
        p = tmp_path / "bom.csv"
        p.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
        t = gonio.read_csv(p)
        assert len(t) == 1 and t.values[0].tolist() == [1, 2, 3]
    assert t.meta["source"] == "sheet"


def test_empty_table_is_refused_before_writing(tmp_path):
    empty = gonio.Table(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))
    for suffix in (".csv", ".alta", ".exr"):
        with pytest.raises(ValueError, match="empty"):
            gonio.write(empty, tmp_path / f"e{suffix}")
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="digits must be an integer >= 1; got 0"):
        gonio.write_csv(random_table(1), tmp_path / "t.csv", digits=0)


def test_deeply_nested_metadata_is_one_line_naming_file_and_line(tmp_path):
    p = tmp_path / "deep.csv"
    p.write_text("# source: " + "[" * 100_000 + "]" * 100_000 + "\n"
                 "theta_i,phi_i,theta_o,phi_o,value\n0,0,0,0,0.3\n")
    with pytest.raises(ValueError, match=r"deep\.csv.*line 1: metadata 'source' is nested "
                                         r"too deeply"):
        gonio.read(p)
