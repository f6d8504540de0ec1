"""CUReT: all 61 samples load with 205 rows and the angles of table.txt."""

import numpy as np
import pytest

import brdf
import gonio


def test_all_samples(shared_data):
    folder = shared_data / "curet"
    # independent parse of the two files
    geo = np.loadtxt(folder / "table.txt")
    raw = np.loadtxt(folder / "abrdf.dat")
    assert geo.shape == (205, 5) and raw.shape == (61, 206)
    for sample in range(1, 62):
        t = gonio.read_curet(folder, sample)
        assert len(t) == 205
        np.testing.assert_allclose(t.values, np.repeat(raw[sample - 1, 1:, None], 3, 1))
        assert t.meta["units"] == "relative" and t.meta["curet_sample"] == sample
    ang = t.angles
    # table.txt: theta_v, phi_v (viewer = wo), theta_i, phi_i (light = wi)
    np.testing.assert_allclose(ang[:, 2], geo[:, 1], atol=1e-9)
    np.testing.assert_allclose(ang[:, 0], geo[:, 3], atol=1e-9)
    wrap = lambda a: np.angle(np.exp(1j * a))  # noqa: E731
    sin_o, sin_i = np.sin(geo[:, 1]) > 1e-9, np.sin(geo[:, 3]) > 1e-9
    np.testing.assert_allclose(wrap(ang[sin_o, 3] - geo[sin_o, 2]), 0, atol=1e-9)
    np.testing.assert_allclose(wrap(ang[sin_i, 1] - geo[sin_i, 4]), 0, atol=1e-9)
    # row 2 by hand: viewer at 0.981748 rad, light at 1.374447 rad, both at phi = 0
    np.testing.assert_allclose(t.wo[1], [np.sin(0.981748), 0, np.cos(0.981748)], atol=1e-12)
    np.testing.assert_allclose(t.wi[1], [np.sin(1.374447), 0, np.cos(1.374447)], atol=1e-12)
    assert np.all(t.wi[:, 2] > 0) and np.all(t.wo[:, 2] > 0)


def test_read_dispatch_and_bad_sample(shared_data, tmp_path):
    t = gonio.read(shared_data / "curet" / "abrdf.dat", sample=44)
    assert t.meta["curet_sample"] == 44
    with pytest.raises(ValueError, match="sample"):
        gonio.read(shared_data / "curet" / "abrdf.dat")
    for bad in (0, 62, 1.5):
        with pytest.raises(ValueError, match="1..61"):
            gonio.read_curet(shared_data / "curet", bad)
    # a truncated abrdf.dat
    (tmp_path / "table.txt").write_text((shared_data / "curet" / "table.txt").read_text())
    lines = (shared_data / "curet" / "abrdf.dat").read_text().splitlines()
    (tmp_path / "abrdf.dat").write_text("\n".join(lines[:30]) + "\n")
    with pytest.raises(gonio.FormatError, match=r"abrdf.dat: wrong size: 30 rows"):
        gonio.read_curet(tmp_path, 1)
    lines[4] = lines[4][: len(lines[4]) // 2]
    (tmp_path / "abrdf.dat").write_text("\n".join(lines) + "\n")
    with pytest.raises(gonio.FormatError, match=r"abrdf.dat: line 5: expected 206"):
        gonio.read_curet(tmp_path, 1)


def test_old_names_warn_and_give_the_same_table(shared_data):
    import warnings
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        old = gonio.load_curet(shared_data / "curet", 7)
    assert any(issubclass(x.category, DeprecationWarning) and "read_curet" in str(x.message)
               for x in w)
    new = gonio.read_curet(shared_data / "curet", 7)
    np.testing.assert_array_equal(old.values, new.values)


def test_azimuths_are_in_one_frame_and_sense(shared_data):
    """The shiny polyester's brightest value is at an exact mirror pair (phi_v = phi_i + 180
    degrees, theta_v = theta_i): both azimuths measured from one axis in one sense, as read
    (a wrong sign of one of them would put it elsewhere)."""
    t = gonio.read_curet(shared_data / "curet", 2)
    k = int(np.argmax(t.values[:, 0]))
    mirror = t.wi[k] * np.array([-1.0, -1.0, 1.0])
    np.testing.assert_allclose(t.wo[k], mirror, atol=1e-6)
    assert t.wi[k, 0] ** 2 + t.wi[k, 1] ** 2 > 0.5        # away from the normal: phi matters


def _mirror_swap_pairs(t):
    """(k, j): configuration j is k mirrored in x -> -x with light and view exchanged; k the
    one whose half vector leans to -x."""
    m = np.array([-1.0, 1.0, 1.0])
    h = t.wi + t.wo
    out = []
    for k in range(len(t.wi)):
        d = np.linalg.norm(t.wo - t.wi[k] * m, axis=1) + np.linalg.norm(t.wi - t.wo[k] * m, axis=1)
        j = int(np.argmin(d))
        if d[j] < 0.02 and k < j:
            out.append((k, j) if h[k, 0] < h[j, 0] else (j, k))
    return np.array(out)


def test_left_right_is_light_against_view_and_the_values_are_reciprocal(shared_data):
    """The docstring's account of CUReT's geometry, and the reason the left/right residual
    pattern of the microcylinder's fits is its non-reciprocity (docs/guide/measured.rst)."""
    t = gonio.read_curet(shared_data / "curet", 44)
    ti, tv = np.arccos(t.wi[:, 2]), np.arccos(t.wo[:, 2])
    h = t.wi + t.wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    left, right = h[:, 0] <= -np.sin(np.radians(5)), h[:, 0] >= np.sin(np.radians(5))
    assert (left.sum(), right.sum()) == (93, 84)
    assert np.all(tv[left] > ti[left]) and np.all(ti[right] > tv[right])
    phase = np.degrees(np.arccos(np.sum(t.wi * t.wo, axis=1)))
    np.testing.assert_allclose(np.sort(np.unique(np.round(phase, 1))), 22.5 * np.arange(1, 8))
    pairs = _mirror_swap_pairs(t)
    assert len(pairs) == 31
    # no cos(theta_i) factor in the values: the log ratio of a pair does not follow it
    data = np.loadtxt(shared_data / "curet" / "abrdf.dat")[:, 1:]
    k, j = pairs.T
    x = np.log(t.wi[k, 2] / t.wi[j, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        y = np.log(data[:, k] / data[:, j])
    ok = np.all(np.isfinite(y), axis=1)
    slopes = (y[ok] @ x) / (x @ x)
    assert abs(np.median(slopes)) < 0.1            # 1 were the values f_r cos(theta_i)
    # linen's pairs agree within 10% on average; the linen preset's differ by a factor 2.3
    v = t.values[:, 0]
    assert abs(np.mean(np.log(v[k] / v[j]))) < 0.1
    f = brdf.fabric("linen_plain").eval(t.wi, t.wo).mean(axis=-1)
    assert np.mean(np.log(f[k] / f[j])) < -0.8
