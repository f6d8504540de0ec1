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
