"""MERL .binary: index, write -> read -> lookup, rotation averaging, missing values, bad files."""

import numpy as np
import pytest

import gonio
from gonio.merl import FILE_SIZE, SCALE, merl_index
from tests._gonio_helpers import Glossy, Lambert, random_dirs


def _standard_index(wi, wo):
    """MERL's BRDFRead.cpp index, transliterated independently (per direction pair)."""
    out = []
    for a, b in zip(wi, wo):
        h = (a + b) / np.linalg.norm(a + b)
        th, ph = np.arccos(h[2]), np.arctan2(h[1], h[0])
        # rotate a by -ph about z, then by -th about y
        c, s = np.cos(-ph), np.sin(-ph)
        a1 = np.array([c * a[0] - s * a[1], s * a[0] + c * a[1], a[2]])
        c, s = np.cos(-th), np.sin(-th)
        d = np.array([c * a1[0] + s * a1[2], a1[1], -s * a1[0] + c * a1[2]])
        td, pd = np.arccos(d[2]), np.arctan2(d[1], d[0])
        ih = 0 if th <= 0 else min(int(np.sqrt(th / (np.pi / 2) * 90 * 90)), 89)
        jd = min(max(int(td / (np.pi / 2) * 90), 0), 89)
        if pd < 0:
            pd += np.pi
        kd = min(max(int(pd / np.pi * 180), 0), 179)
        out.append(kd + 180 * (jd + 90 * ih))
    return np.array(out)


def test_index_matches_reference_transliteration():
    rng = np.random.default_rng(0)
    wi, wo = random_dirs(rng, 200), random_dirs(rng, 200)
    th, _, td, pd = gonio.merl.half_diff(wi, wo)
    np.testing.assert_array_equal(merl_index(th, td, pd), _standard_index(wi, wo))


@pytest.fixture(scope="module")
def glossy_file(tmp_path_factory):
    p = tmp_path_factory.mktemp("merl") / "glossy.binary"
    gonio.write(Glossy(), p, rotations=1)
    return p


def test_write_read_lookup(glossy_file):
    assert glossy_file.stat().st_size == FILE_SIZE
    m = gonio.load_merl(glossy_file)
    rng = np.random.default_rng(1)
    wi, wo = random_dirs(rng, 2000), random_dirs(rng, 2000)
    got, want = m.eval(wi, wo), Glossy().eval(wi, wo)
    # nearest-bin: error bounded by the variation of f over one bin (smooth lobe: a few %)
    rel = np.abs(got - want) / want
    assert np.median(rel) < 0.01 and rel.max() < 0.06
    # at a bin centre the lookup is the stored value exactly
    i, j, k = np.array([0, 10, 50, 80]), np.array([0, 20, 30, 5]), np.array([0, 37, 90, 179])
    ci, co = gonio.merl.merl_directions(i, j, k, phi_h=0.3)
    np.testing.assert_allclose(m.eval(ci, co), Glossy().eval(ci, co), rtol=1e-12)
    # raw file layout: three int32 then red, green, blue float64 blocks scaled by SCALE
    raw = np.fromfile(glossy_file, "<f8", offset=12).reshape(3, -1)
    flat = k + 180 * (j + 90 * i)
    np.testing.assert_allclose(raw[:, flat].T * SCALE, Glossy().eval(ci, co), rtol=1e-12)
    # below-horizon bins are missing (negative) and counted
    assert m.missing_values > 0 and raw.min() < 0
    below = gonio.merl.merl_directions(89, 89, 0)
    assert below[0][2] < 0 or below[1][2] < 0
    assert np.all(raw[:, 180 * (89 + 90 * 89)] < 0)


def test_table_round_trip(glossy_file, tmp_path):
    t = gonio.read(glossy_file, stride=(9, 9, 18))
    assert len(t) == 10 * 10 * 10
    assert t.meta["missing_values"] == np.count_nonzero(~t.valid)
    p = tmp_path / "t.binary"
    gonio.write(t, p)
    back = gonio.read_merl(p, stride=(9, 9, 18))
    np.testing.assert_allclose(back.values, t.values, rtol=1e-12)
    # bins the table did not cover are missing
    assert gonio.load_merl(p).missing_values >= 3 * (90 * 90 * 180 - len(t))


def test_anisotropic_average_over_rotations(tmp_path):
    class Aniso(Lambert):
        def eval(self, wi, wo):
            h = np.asarray(wi) + np.asarray(wo)
            phi_h = np.arctan2(h[..., 1], h[..., 0])
            return super().eval(wi, wo) * (1 + 0.5 * np.cos(2 * phi_h))[..., None]

    p = tmp_path / "a.binary"
    gonio.write_merl(Aniso(), p, rotations=8, chunk_rows=7)
    m = gonio.load_merl(p)
    rng = np.random.default_rng(2)
    wi, wo = random_dirs(rng, 300), random_dirs(rng, 300)
    np.testing.assert_allclose(m.eval(wi, wo), Lambert().eval(wi, wo), rtol=1e-9)


def test_bad_files(tmp_path, glossy_file):
    head = glossy_file.read_bytes()[:4096]
    wrong = tmp_path / "dims.binary"
    wrong.write_bytes(np.array([90, 90, 360], "<i4").tobytes() + head[12:])
    with pytest.raises(gonio.FormatError, match="dims.binary: wrong magic"):
        gonio.load_merl(wrong)
    short = tmp_path / "short.binary"
    short.write_bytes(head)
    with pytest.raises(gonio.FormatError, match="short.binary: wrong size: 4096 bytes"):
        gonio.read(short)
    tiny = tmp_path / "tiny.binary"
    tiny.write_bytes(b"\x5a\x00")
    with pytest.raises(gonio.FormatError, match="tiny.binary: wrong size"):
        gonio.load_merl(tiny)
