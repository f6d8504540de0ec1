"""CSV tables: round trip to printed precision, grey files, bad rows with line numbers, names
in any case, delimiters, radians mistaken for degrees, float32 data."""

import warnings

import numpy as np
import pytest

import gonio
from gonio.exr import from_angles
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


# Tables as people write them (issue 27): names in any case, semicolons and tabs, radians
# mistaken for degrees, float32 data written with the digits it holds.

RGB = "theta_i,phi_i,theta_o,phi_o,r,g,b,sigma_r,sigma_g,sigma_b"
GREY = "theta_i,phi_i,theta_o,phi_o,value,sigma"
ROWS = {RGB: ["30,0,45,180,0.1,0.2,0.3,0.01,0.02,0.03", "60,90,20,-90,0.4,0.5,0.6,0.04,0.05,0.06"],
        GREY: ["30,0,45,180,0.1,0.01", "60,90,20,-90,0.4,0.04"]}


def _check_hand_table(t, grey=False):
    """The two rows of ROWS, read: angles in degrees, values and sigma as written."""
    np.testing.assert_allclose(np.degrees(t.angles), [[30, 0, 45, 180], [60, 90, 20, -90]],
                               atol=1e-9)
    values = [[0.1] * 3, [0.4] * 3] if grey else [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]
    np.testing.assert_allclose(t.values, values, rtol=1e-15)
    np.testing.assert_allclose(t.sigma, np.asarray(values) / 10, rtol=1e-12)


@pytest.mark.parametrize("name", RGB.split(",") + ["value", "sigma"])
@pytest.mark.parametrize("case", [str.upper, str.title])
def test_every_column_name_is_read_in_any_case(tmp_path, name, case):
    """``R,G,B`` is ``r,g,b``: each name the reader knows, in upper and title case."""
    header = GREY if name in ("value", "sigma") else RGB
    names = [case(c) if c == name else c for c in header.split(",")]
    assert case(name) != name
    p = tmp_path / "t.csv"
    p.write_text(",".join(names) + "\n" + "\n".join(ROWS[header]) + "\n")
    _check_hand_table(gonio.read(p), grey=header == GREY)


@pytest.mark.parametrize("sep", [";", "\t", ", "])
def test_semicolon_and_tab_delimiters_are_found_in_the_header(tmp_path, sep):
    p = tmp_path / "t.csv"
    p.write_text("# source: \"sheet\"\n" + "\n".join([RGB.upper()] + ROWS[RGB]).replace(",", sep)
                 + "\n")
    t = gonio.read(p)
    _check_hand_table(t)
    assert t.meta["source"] == "sheet"


@pytest.mark.parametrize("text, pattern", [
    ("theta_i|phi_i|theta_o|phi_o|value\n30|0|30|0|0.1\n",
     r"line 1: found '\|' between the column names; expected comma, semicolon or tab"),
    ("# c\ntheta_i phi_i theta_o phi_o value\n30 0 30 0 0.1\n",
     r"line 2: found ' ' between the column names; expected comma, semicolon or tab"),
    ("theta_i,phi_i;theta_o,phi_o,value\n30,0,30,0,0.1\n",
     r"line 1: the header holds both comma and semicolon"),
    ("theta_i;phi_i;theta_o;phi_o;value\n30;0;30;0;0.1\n30,0,30,0,0.1\n",
     r"line 3: expected 5 columns .*got 1; the header is split on semicolons, this row "
     r"holds commas"),
    ("theta_i;phi_i;theta_o;phi_o;value\n30;0;30;0;0,1\n",
     r"line 2: '0,1' is not a number .*, in column value; a decimal comma\? write 0.1"),
])
def test_an_unknown_delimiter_is_named(tmp_path, text, pattern):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(gonio.FormatError, match="bad.csv: " + pattern):
        gonio.read(p)


RADIANS = ("theta_i,phi_i,theta_o,phi_o,value\n0.5236,0,0.7854,3.1416,0.1\n"
           "1.0472,1.5708,0.3491,-1.5708,0.2\n")


def test_angles_in_radians_are_read_as_degrees_with_a_warning(tmp_path):
    """Every theta at most pi and every phi at most 2 pi: radians, most likely. The table is
    still read in degrees (the warning changes no number); a pairs file warns the same."""
    p = tmp_path / "rad.csv"
    p.write_text(RADIANS)
    with pytest.warns(gonio.TableWarning, match=r"rad\.csv: every angle is within the range "
                                                r"of radians.*read in degrees"):
        t = gonio.read(p)
    np.testing.assert_allclose(np.degrees(t.angles[0]), [0.5236, 0, 0.7854, 3.1416], atol=1e-9)
    with pytest.warns(gonio.TableWarning, match=r"rad\.csv"):
        gonio.from_spec(f"pairs:{p}")


@pytest.mark.parametrize("rows", [
    "30,0,45,180,0.1",                     # degrees
    "3,0,3,180,0.1",                       # near the normal, but an azimuth of 180
    "0,0,0,0,0.1",                         # all zero: the same in any unit
    "1.5,0,3.2,0,0.1",                     # theta_o above pi
    "1.5,0,1.5,6.3,0.1",                   # phi_o above 2 pi
])
def test_tables_in_degrees_do_not_warn(tmp_path, rows):
    p = tmp_path / "deg.csv"
    p.write_text("theta_i,phi_i,theta_o,phi_o,value\n" + rows + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error", gonio.TableWarning)
        gonio.read(p)


def _exr_table(tmp_path, deg, values, sigma=None):
    """A table of angles (degrees) and values written to OpenEXR (float32) and read back."""
    a = np.radians(np.asarray(deg, dtype=np.float64))
    t = gonio.Table(from_angles(a[:, 0], a[:, 1]), from_angles(a[:, 2], a[:, 3]), values,
                    sigma, {"source": "float32"})
    gonio.write(t, tmp_path / "t.exr")
    return gonio.read(tmp_path / "t.exr")


def _angles32(t):
    """A table's angles as float32, an azimuth of float32 pi (above pi, so made -pi + 2e-7
    by its direction) turned back to +pi."""
    a = t.angles
    a[:, 1::2] = np.where(a[:, 1::2] < -np.pi + 1e-6, a[:, 1::2] + 2 * np.pi, a[:, 1::2])
    return a.astype(np.float32)


def test_float32_data_is_written_with_the_digits_it_holds(tmp_path):
    """EXR -> CSV: ``15``, not ``15.0000004`` (float32 widened and printed to 9 digits), and
    the CSV read back gives the same float32 angles and values."""
    deg = [[15, 0, 30, 180], [45, 90, 60, -90], [0, 0, 75, 135], [10, -45, 20.5, 10]]
    values = [[0.1, 0.2, 0.3], [1.5, 0.7, 1e-5], [3.3, 2, 1], [0.25, 0.125, 1e3]]
    exr = _exr_table(tmp_path, deg, values)
    gonio.write(exr, tmp_path / "t.csv")
    rows = [ln for ln in (tmp_path / "t.csv").read_text().splitlines()
            if not ln.startswith("#")]
    assert rows == ["theta_i,phi_i,theta_o,phi_o,r,g,b", "15,0,30,180,0.1,0.2,0.3",
                    "45,90,60,-90,1.5,0.7,1e-05", "0,0,75,135,3.3,2,1",
                    "10,-45,20.5,10,0.25,0.125,1000"]
    back = gonio.read(tmp_path / "t.csv")
    assert np.array_equal(_angles32(back), _angles32(exr))
    assert np.array_equal(back.values.astype(np.float32), exr.values.astype(np.float32))
    # digits given: as many as asked for
    gonio.write(exr, tmp_path / "d.csv", digits=9)
    assert "\n15.0000004,0,30.0000008,-179.999995,0.100000001," in \
        (tmp_path / "d.csv").read_text()


def test_random_float32_tables_round_trip_exactly(tmp_path):
    """20000 random float32 angles and values (sigma too) through EXR and CSV: every float32
    comes back, no number printed with more than 9 digits."""
    rng = np.random.default_rng(27)
    n = 20_000
    deg = np.column_stack([rng.uniform(0, 89, n), rng.uniform(-180, 180, n),
                           rng.uniform(0, 89, n), rng.uniform(-180, 180, n)])
    values = rng.lognormal(-2, 3, (n, 3))
    exr = _exr_table(tmp_path, deg, values, values / 7)
    gonio.write(exr, tmp_path / "t.csv")
    back = gonio.read(tmp_path / "t.csv")
    assert np.array_equal(_angles32(back), _angles32(exr))
    assert np.array_equal(back.values.astype(np.float32), exr.values.astype(np.float32))
    assert np.array_equal(back.sigma.astype(np.float32), exr.sigma.astype(np.float32))
    text = (tmp_path / "t.csv").read_text().splitlines()[3:]
    digits = [len(f.split("e")[0].replace("-", "").replace(".", "").lstrip("0"))
              for row in text[:2000] for f in row.split(",")]
    assert max(digits) <= 9


def test_float64_data_keeps_nine_digits(tmp_path):
    """A float64 table (measured, computed) is written to 9 digits as before."""
    t = gonio.Table([[0, 0, 1.0]], [[0.6, 0, 0.8]], [[1 / 3, 0.1, 2 / 3]])
    gonio.write(t, tmp_path / "t.csv")
    assert (tmp_path / "t.csv").read_text().splitlines()[-1] == \
        "0,0,36.8698976,0,0.333333333,0.1,0.666666667"


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
