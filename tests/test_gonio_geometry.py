"""Tests of gonio.geometry: layouts, counts, angle ranges, conversions, spec parser."""

import math
import re

import numpy as np
import pytest

import gonio
from gonio import geometry as G
from gonio import layouts as L
from gonio.geometry import Geometry
from gonio.geomspec import from_spec


def _unit(rng, n, upper=True):
    w = rng.standard_normal((n, 3))
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    if upper:
        w[:, 2] = np.abs(w[:, 2]) + 1e-3
        w /= np.linalg.norm(w, axis=1, keepdims=True)
    return w


# ------------------------------------------------------------------ Rusinkiewicz, by MERL's code

def _rotate_vector(v, axis, angle):
    """Transliteration of MERL BRDFRead.cpp rotate_vector (Rodrigues)."""
    v, axis = np.asarray(v, float), np.asarray(axis, float)
    c, s = math.cos(angle), math.sin(angle)
    return v * c + axis * (v @ axis) * (1 - c) + np.cross(axis, v) * s


def _merl_std_to_half_diff(theta_in, fi_in, theta_out, fi_out):
    """Transliteration of MERL's std_coords_to_half_diff_coords (one pair, scalars)."""
    vin = np.array([math.sin(theta_in) * math.cos(fi_in), math.sin(theta_in) * math.sin(fi_in),
                    math.cos(theta_in)])
    vout = np.array([math.sin(theta_out) * math.cos(fi_out),
                     math.sin(theta_out) * math.sin(fi_out), math.cos(theta_out)])
    half = (vin + vout) / np.linalg.norm(vin + vout)
    theta_half = math.acos(half[2])
    fi_half = math.atan2(half[1], half[0])
    normal, bi_normal = np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])
    temp = _rotate_vector(vin, normal, -fi_half)
    diff = _rotate_vector(temp, bi_normal, -theta_half)
    theta_diff = math.acos(diff[2])
    fi_diff = math.atan2(diff[1], diff[0])
    return theta_half, fi_half, theta_diff, fi_diff


def test_half_diff_matches_merl_reference_code():
    rng = np.random.default_rng(3)
    wi, wo = _unit(rng, 50), _unit(rng, 50)
    th, ph, td, pd = G.directions_to_half_diff(wi, wo)
    for k in range(50):
        ti, pi_ = math.acos(wi[k, 2]), math.atan2(wi[k, 1], wi[k, 0])
        to, po = math.acos(wo[k, 2]), math.atan2(wo[k, 1], wo[k, 0])
        ref = _merl_std_to_half_diff(ti, pi_, to, po)
        assert np.allclose([th[k], ph[k], td[k], pd[k]], ref, atol=1e-10)


def test_half_diff_definitions_independent():
    rng = np.random.default_rng(4)
    wi, wo = _unit(rng, 200), _unit(rng, 200)
    th, ph, td, pd = G.directions_to_half_diff(wi, wo)
    h = (wi + wo) / np.linalg.norm(wi + wo, axis=1, keepdims=True)
    assert np.allclose(np.cos(th), h[:, 2])                       # theta_h: h from n
    assert np.allclose(np.cos(td), np.sum(wi * h, axis=1))        # theta_d: wi from h
    assert np.allclose(np.arctan2(h[:, 1], h[:, 0]), ph)


def test_half_diff_round_trips():
    rng = np.random.default_rng(5)
    wi, wo = _unit(rng, 500), _unit(rng, 500)
    wi2, wo2 = G.half_diff_to_directions(*G.directions_to_half_diff(wi, wo))
    assert np.allclose(wi2, wi, atol=1e-12) and np.allclose(wo2, wo, atol=1e-12)
    # angles -> directions -> angles, away from the degenerate theta = 0
    th = rng.uniform(0.05, 1.5, 300)
    ph = rng.uniform(-3.1, 3.1, 300)
    td = rng.uniform(0.05, 1.5, 300)
    pd = rng.uniform(-3.1, 3.1, 300)
    back = G.directions_to_half_diff(*G.half_diff_to_directions(th, ph, td, pd))
    for a, b in zip(back, (th, ph, td, pd)):
        assert np.allclose(a, b, atol=1e-10)


def test_half_diff_to_directions_bisects():
    wi, wo = G.half_diff_to_directions(0.4, 1.1, 0.7, 2.0)
    h = G.directions_from_angles(0.4, 1.1)
    s = (wi + wo) / np.linalg.norm(wi + wo)
    assert np.allclose(s, h)
    assert math.isclose(float(wi @ h), math.cos(0.7))


# ------------------------------------------------------------------ plane

def test_plane_round_trip_and_signs():
    rng = np.random.default_rng(6)
    ti, to = rng.uniform(-1.5, 1.5, (2, 100))
    for az in (0.0, math.pi / 4, math.pi / 2, 2.0):
        wi, wo = G.plane_to_directions(ti, to, az)
        a, b = G.directions_to_plane(wi, wo, az)
        assert np.allclose(a, ti) and np.allclose(b, to)
    wi, wo = G.plane_to_directions(0.5, 0.5, 0.0)
    assert np.allclose(wo, wi * [-1, -1, 1])             # theta_o = theta_i: mirror direction
    wi, wo = G.plane_to_directions(0.5, -0.5, 0.3)
    assert np.allclose(wo, wi)                           # theta_o = -theta_i: back-scatter
    with pytest.raises(ValueError, match="off the plane"):
        G.directions_to_plane(wi, [[0.0, 1.0, 1.0]], 0.0)


def test_plane_layouts():
    g = L.plane("warp", 5)
    assert len(g) == 6 * 35 and g.info["dropped_below_horizon"] == 0
    to = np.degrees(g.coords["theta_o"])
    assert to.min() == pytest.approx(-85) and to.max() == pytest.approx(85)
    assert np.allclose(g.wi[:, 1], 0) and np.allclose(g.wo[:, 1], 0)   # all in the xz plane
    w = L.plane("weft", 10, theta_i=[40])
    assert np.allclose(w.wi[:, 0], 0) and np.allclose(w.wo[:, 0], 0)
    assert np.allclose(w.wi[0], [0, math.sin(math.radians(40)), math.cos(math.radians(40))])
    d = L.plane("45", 10, theta_i=[40])
    assert np.allclose(d.wi[:, 0], d.wi[:, 1])
    # in standard angles, phi_o = phi_i + 180 on the specular side
    ti, pi_, to, po = G.angles_from_directions(d.wi) + G.angles_from_directions(d.wo)
    spec = d.coords["theta_o"] > 0
    assert np.allclose(np.mod(po[spec] - pi_[spec], 2 * np.pi), np.pi)


# ------------------------------------------------------------------ full grid

def test_full_grid_counts_and_ranges():
    g = L.full_grid(10)
    per_side = 1 + 8 * 36                # theta 0..80, one direction at theta = 0
    assert len(g) == per_side ** 2 == 83521
    for side in ("i", "o"):
        t = np.degrees(g.coords[f"theta_{side}"])
        p = np.degrees(g.coords[f"phi_{side}"])
        assert t.min() == 0 and t.max() == pytest.approx(80)
        assert p.min() == 0 and p.max() == pytest.approx(350)
        assert np.all(p[t == 0] == 0)
    # no duplicate directions on one side
    side = np.unique(np.round(g.wi, 9), axis=0)
    assert len(side) == per_side
    # coordinates describe the directions
    assert np.allclose(g.wi, G.directions_from_angles(g.coords["theta_i"], g.coords["phi_i"]))
    g2 = L.full_grid(30, 90, theta_o_step=45, phi_o_step=180)
    assert len(g2) == (1 + 2 * 4) * (1 + 1 * 2)


# ------------------------------------------------------------------ Rusinkiewicz and MERL grids

def test_rusinkiewicz_grid_counts_and_horizon():
    g = L.rusinkiewicz(30, 90, 30, 90)
    th, ph, td, pd = np.meshgrid(np.radians([0, 30, 60]), np.radians([0, 90, 180, 270]),
                                 np.radians([0, 30, 60]), np.radians([0, 90, 180, 270]),
                                 indexing="ij")
    wi, wo = G.half_diff_to_directions(th.ravel(), ph.ravel(), td.ravel(), pd.ravel())
    up = (wi[:, 2] > 1e-9) & (wo[:, 2] > 1e-9)
    assert g.info["n_layout"] == 144
    assert len(g) == up.sum() and g.info["dropped_below_horizon"] == 144 - up.sum()
    assert np.all(g.wi[:, 2] > 0) and np.all(g.wo[:, 2] > 0)
    assert np.allclose(g.wi, wi[up])
    back = G.directions_to_half_diff(g.wi, g.wo)
    nondeg = (g.coords["theta_h"] > 0) & (g.coords["theta_d"] > 0)
    assert np.allclose(back[0], g.coords["theta_h"], atol=1e-12)
    assert np.allclose(back[2], g.coords["theta_d"], atol=1e-12)
    dphi = np.angle(np.exp(1j * (back[3] - g.coords["phi_d"])))
    assert np.allclose(dphi[nondeg], 0, atol=1e-10)


def test_merl_layout_matches_reference_index():
    g = L.merl()
    assert g.info["n_layout"] == 90 * 90 * 180
    assert len(g) + g.info["dropped_below_horizon"] == 1_458_000
    assert np.all(np.diff(g.index) > 0) and g.index.max() < 1_458_000  # unique, in order
    assert np.all(g.coords["phi_h"] == 0)
    # MERL's reference lookup (BRDFRead.cpp), transliterated, finds each entry again
    th, _, td, pd = G.directions_to_half_diff(g.wi, g.wo)
    i_td = np.floor(td / (np.pi / 2) * 90).astype(int)
    pdm = np.where(pd < 0, pd + np.pi, pd)
    i_pd = np.floor(pdm / np.pi * 360 / 2).astype(int)
    i_th_exact = np.sqrt(th / (np.pi / 2) * 90 * 90)
    i_th = np.floor(i_th_exact).astype(int)
    expect_th, rest = np.divmod(g.index, 90 * 180)
    expect_td, expect_pd = np.divmod(rest, 180)
    assert np.array_equal(i_td, expect_td) and np.array_equal(i_pd, expect_pd)
    assert np.array_equal(i_th, expect_th)
    # theta_h sits at the centre ((i + 1/2) / 90)^2 * 90 deg of its bin, not on its edge
    assert np.allclose(i_th_exact, expect_th + 0.5, atol=1e-6)


def test_merl_stride():
    g = L.merl(3)
    assert g.info["n_layout"] == 30 * 30 * 60
    ith, rest = np.divmod(g.index, 90 * 180)
    itd, ipd = np.divmod(rest, 180)
    assert np.all(ith % 3 == 0) and np.all(itd % 3 == 0) and np.all(ipd % 3 == 0)
    with pytest.raises(ValueError, match="stride"):
        L.merl(0)


# ------------------------------------------------------------------ pairs, horizon, rotation

def test_pairs_drop_below_horizon():
    wi = [[0, 0, 1], [1, 0, 0], [0, 0, -1], [1, 0, 1]]
    wo = [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 1, 1]]
    g = L.pairs(wi, wo)
    assert len(g) == 2 and g.info["dropped_below_horizon"] == 2
    assert g.index.tolist() == [0, 3]
    assert np.allclose(np.degrees(g.coords["theta_i"]), [0, 45])
    assert np.allclose(np.degrees(g.coords["phi_o"]), [0, 90])
    with pytest.raises(ValueError, match="shape"):
        L.pairs([[0, 0, 1]], [[0, 0, 1], [0, 0, 1]])
    with pytest.raises(ValueError, match="non-zero"):
        L.pairs([[0, 0, 0]], [[0, 0, 1]])


def test_pairs_from_angles_units():
    a = L.pairs_from_angles([30], [45], [60], [200])
    b = L.pairs_from_angles(np.radians([30]), np.radians([45]), np.radians([60]),
                            np.radians([200]), degrees=False)
    assert np.allclose(a.wi, b.wi) and np.allclose(a.wo, b.wo)
    assert math.isclose(a.wi[0, 2], math.cos(math.radians(30)))
    with pytest.raises(ValueError, match="same length"):
        L.pairs_from_angles([1, 2], [1, 2, 3], [1], [1])


def test_rotation_turns_directions_by_minus_rotation():
    g = L.plane("warp", 30, theta_i=[45])
    r = L.plane("warp", 30, theta_i=[45], rotation=math.pi / 2)
    assert np.allclose(r.wi_lab, g.wi_lab)
    # the sample's warp points at lab azimuth 90 deg, so a lab direction along +x is along
    # the sample's -y
    assert np.allclose(r.wi[0], [0, -math.sin(math.pi / 4), math.cos(math.pi / 4)])
    assert np.allclose(g.with_rotation(math.pi / 2).wi, r.wi)
    assert g.with_rotation(0.3).coords["theta_o"] is not None
    with pytest.raises(ValueError, match="rotation"):
        g.with_rotation(float("nan"))


def test_subset_keeps_coordinates():
    g = L.full_grid(45)
    s = g.subset(g.coords["theta_i"] > 0)
    assert len(s) == np.sum(g.coords["theta_i"] > 0)
    assert np.all(s.coords["theta_i"] > 0)
    assert np.allclose(s.wi, G.directions_from_angles(s.coords["theta_i"], s.coords["phi_i"]))


# ------------------------------------------------------------------ spec parser

@pytest.mark.parametrize("spec, kind, n", [
    ("full:30", "full", 625),
    ("full:30:90", "full", 81),
    ("full:30:90:45:180", "full", 9 * 3),
    ("plane:warp:5", "plane", 210),
    ("plane:weft:30", "plane", 30),
    ("plane:45:30:10,20", "plane", 10),
    ("plane:120:30:10", "plane", 5),
    ("rusinkiewicz:30:90:30:90", "rusinkiewicz", None),
    ("merl:30", "merl", None),
    ("  MERL:30 ", "merl", None),
])
def test_from_spec_good(spec, kind, n):
    g = from_spec(spec, rotation=0.25)
    assert g.kind == kind and g.rotation == 0.25
    if n is not None:
        assert len(g) == n
    # the spec of the result rebuilds the same layout
    again = from_spec(g.spec)
    assert np.array_equal(again.wi_lab, g.wi_lab) and np.array_equal(again.wo_lab, g.wo_lab)


def test_from_spec_plane_azimuths():
    assert np.allclose(from_spec("plane:weft:30:30").wi_lab,
                       L.plane(90, 30, theta_i=[30]).wi_lab)


@pytest.mark.parametrize("spec, match", [
    ("", "non-empty"),
    ("sphere:3", "unknown kind 'sphere'"),
    ("full", "1, 2 or 4"),
    ("full:0", r"theta_step must be in \(0, 90\]"),
    ("full:abc", "'abc' is not a number"),
    ("full:10:10:10", "1, 2 or 4"),
    ("full:100", "theta_step"),
    ("plane:north:5", "north"),
    ("plane:warp", "WHICH:STEP"),
    ("plane:warp:5:95", "theta_i"),
    ("rusinkiewicz:5:5", "1 or 4"),
    ("merl:0", "stride"),
    ("merl:x", "stride 'x'"),
    ("merl:2:3", "at most"),
    ("pairs:", "file name"),
])
def test_from_spec_bad(spec, match):
    with pytest.raises(ValueError, match=match) as exc:
        from_spec(spec)
    msg = str(exc.value)
    assert "\n" not in msg
    if spec:
        assert msg.startswith(f"geometry spec {spec!r}") and "full:STEP" in msg


def test_from_spec_pairs_file(tmp_path):
    f = tmp_path / "p.csv"
    f.write_text("# CUReT-like list\ntheta_i,phi_i,theta_o,phi_o,extra\n"
                 "30,0,30,180,x\n0,0,45,90,y\n95,0,10,0,z\n")
    g = from_spec(f"pairs:{f}")
    assert len(g) == 2 and g.info["dropped_below_horizon"] == 1
    assert np.allclose(g.wo[1], [0, math.sin(math.radians(45)), math.cos(math.radians(45))])
    assert g.spec == f"pairs:{f}"
    bad = tmp_path / "bad.csv"
    bad.write_text("theta_i,phi_i,theta_o,phi_o\n10,0,10,0\n10,0,ten,0\n")
    with pytest.raises(ValueError, match="line 3"):
        from_spec(f"pairs:{bad}")
    nohead = tmp_path / "nohead.csv"
    nohead.write_text("theta_i,phi_i,theta_o\n10,0,10\n")
    with pytest.raises(ValueError, match="phi_o"):
        from_spec(f"pairs:{nohead}")
    with pytest.raises(OSError, match="cannot read"):
        from_spec(f"pairs:{tmp_path / 'missing.csv'}")


def test_describe_is_plain():
    import json
    d = L.merl(45, rotation=0.5).describe()
    assert json.loads(json.dumps(d)) == d
    assert d["rotation_deg"] == pytest.approx(math.degrees(0.5))


@pytest.mark.parametrize("spec, words", [
    ("full:3_0", "step '3_0' is not a number"), ("full:nan", "step 'nan' is not a number"),
    ("plane:warp:5:3_0", "theta_i '3_0' is not a number"),
    ("merl:\u0663", "stride .* is not a positive integer"),
    ("plane:\u0661\u0660:5", "plane .* is not warp"),
])
def test_spec_numbers_are_strict(spec, words):
    with pytest.raises(ValueError, match=f"geometry spec {re.escape(repr(spec))}: {words}"):
        gonio.from_spec(spec)


def test_pairs_file_angles_are_checked(tmp_path):
    p = tmp_path / "p.csv"
    p.write_text("theta_i,phi_i,theta_o,phi_o,note\n30,0,30,180,x\n200,0,30,180,y\n")
    with pytest.raises(ValueError, match=r"p.csv: line 3: theta_i = 200 is outside"):
        gonio.from_spec(f"pairs:{p}")
    p.write_text("\ufefftheta_i,phi_i,theta_o,phi_o\n30,0,3_0,180\n")
    with pytest.raises(ValueError, match=r"p.csv: line 2: '3_0' is not a number.*theta_o"):
        gonio.from_spec(f"pairs:{p}")
