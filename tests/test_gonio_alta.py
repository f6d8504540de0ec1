"""ALTA 1-D slices: the MERL pink-felt back-scatter slice, round trip, bad files."""

import json

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
        gonio.write(t, tmp_path / "x.alta", param="COS_TH")
    assert not list(tmp_path.iterdir())
    gonio.write(t, tmp_path / "x.alta")           # the default for wi != wo: SPHERICAL
    assert gonio.read(tmp_path / "x.alta").meta["alta_param"] == "SPHERICAL_TL_PL_TV_PV"


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


# --- 4-D tables --------------------------------------------------------------------------

import math

import brdf

FOUR = ["SPHERICAL_TL_PL_TV_PV", "RUSIN_TH_PH_TD_PD", "CARTESIAN"]


@pytest.fixture(scope="module")
def velvet():
    return gonio.measure(brdf.fabric("velvet"), "full:30", gonio.Instrument(snr=50), seed=0,
                         progress=False)


def _kept(t):
    return np.all(t.valid, axis=1) & np.all(np.isfinite(t.sigma), axis=1)


def _isotropic_rows(t):
    """The table with each pair turned about n so that phi_h = 0 (ALTA's angles)."""
    from brdf.frames import rotate_z
    from gonio.alta_params import phi_h
    ph = phi_h(t.wi, t.wo)[:, None]
    return t.replace(wi=rotate_z(t.wi, -ph[:, 0]), wo=rotate_z(t.wo, -ph[:, 0]))


@pytest.mark.parametrize("param", FOUR + ["RUSIN_TH_TD_PD"])
def test_round_trip(velvet, tmp_path, param):
    t = _isotropic_rows(velvet) if param == "RUSIN_TH_TD_PD" else velvet
    out = tmp_path / "t.alta"
    gonio.write(t, out, param=param)
    back = gonio.read(out)
    k = _kept(t)
    assert back.meta["alta_param"] == param and len(back) == int(k.sum())
    np.testing.assert_allclose(back.values, t.values[k], rtol=1e-12)
    np.testing.assert_allclose(back.sigma, t.sigma[k], rtol=1e-12)
    np.testing.assert_allclose(back.wi, t.wi[k], atol=1e-9)
    np.testing.assert_allclose(back.wo, t.wo[k], atol=1e-9)
    assert f"{int((~k).sum())} rows with a missing value" in out.read_text()


def test_missing_rows_left_out(tmp_path):
    t = gonio.Table([[0, 0, 1.0], [0.6, 0, 0.8]], [[0.6, 0, 0.8]] * 2,
                    [[0.1, np.nan, 0.1], [0.2, 0.3, 0.4]])
    gonio.write(t, tmp_path / "m.alta")
    text = (tmp_path / "m.alta").read_text()
    assert "nan" not in text and "# 1 rows with a missing value" in text
    assert len(gonio.read(tmp_path / "m.alta")) == 1


def test_isotropic_refused(velvet, tmp_path):
    with pytest.raises(ValueError, match="RUSIN_TH_TD_PD.*phi_h != 0"):
        gonio.write(velvet, tmp_path / "x.alta", param="RUSIN_TH_TD_PD")
    assert not list(tmp_path.iterdir())
    iso = velvet.replace(meta={**velvet.meta, "isotropic": True})
    gonio.write(iso, tmp_path / "x.alta", param="RUSIN_TH_TD_PD")   # rotated to phi_h = 0


@pytest.mark.parametrize("text, pattern", [
    ("#DIM 4 3\n#PARAM_IN STEREOGRAPHIC\n#PARAM_OUT RGB_COLOR\n1 2 3 4 1 2 3\n",
     "#PARAM_IN is STEREOGRAPHIC"),
    ("#DIM 4 3\n#PARAM_IN SPHERICAL_TL_PL_TV_PV\n#PARAM_OUT RGB_COLOR\n#FORMAT binary\n",
     "binary ALTA files"),
    ("#DIM 3 3\n#PARAM_IN SPHERICAL_TL_PL_TV_PV\n#PARAM_OUT RGB_COLOR\n1 2 3 4 1 2 3\n",
     "#DIM is 3 3, expected 4 3"),
])
def test_bad_4d_files(tmp_path, text, pattern):
    p = tmp_path / "bad.alta"
    p.write_text(text)
    with pytest.raises(gonio.FormatError, match="bad.alta: .*" + pattern):
        gonio.read(p)


# An independent reader, transliterated from ALTA (belcour/alta, not microcyl's code):
# - _alta_parse_header: sources/core/args.h, arguments::parse_header ('#KEY value' lines,
#   '# ' lines are comments);
# - _alta_load_text: sources/core/data_storage.cpp, load_data_from_text and
#   read_confidence_interval after commit 302c046 (2017): x then y, then for #VS 2 two
#   distances read for channel i == 0 only: [y - a, y + b]; other channels get --dt 0.1;
# - _alta_to_cartesian: sources/core/params.cpp, params::to_cartesian, and params.h,
#   half_to_cartesian / rotate_binormal / rotate_normal (Eigen AngleAxis, right-handed).
#   The CARTESIAN vector is [V, L].

def _alta_parse_header(lines):
    header = {}
    for line in lines:
        if not line.startswith("#"):
            break
        rest = line[1:]
        if rest[:1] != " " and rest.split():
            key = rest.split()[0]
            header[key] = rest[len(key):].lstrip().split("\r")[0]
    return header


def _alta_load_text(text):
    lines = text.splitlines()
    header = _alta_parse_header(lines)
    dim_x, dim_y = (int(v) for v in header["DIM"].split()[:2])
    vs = int(header.get("VS", "0") or 0)
    rows = []
    for line in lines:
        if not line or line.lstrip(" \t")[:1] == "#":
            continue
        tok = [float(v) for v in line.split()]
        x, y = tok[:dim_x], tok[dim_x:dim_x + dim_y]
        lo, hi = [], []
        for i in range(dim_y):
            if i == 0 and vs == 2:
                min_dt, max_dt = -tok[dim_x + dim_y], tok[dim_x + dim_y + 1]
            else:
                min_dt, max_dt = -0.1, 0.1
            lo.append(y[i] + min_dt)
            hi.append(y[i] + max_dt)
        rows.append(x + y + lo + hi)
    return header, dim_x, dim_y, np.array(rows)


def _rot(axis, a, v):
    c, s = math.cos(a), math.sin(a)
    x, y, z = v
    if axis == "y":
        return [c * x + s * z, y, -s * x + c * z]
    return [c * x - s * y, s * x + c * y, z]


def _alta_half_to_cartesian(th, ph, td, pd):
    half = [math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)]
    out = [math.sin(td) * math.cos(pd), math.sin(td) * math.sin(pd), math.cos(td)]
    out = _rot("z", ph, _rot("y", th, out))
    dot = sum(o * h for o, h in zip(out, half))
    return out + [-out[k] + 2.0 * dot * half[k] for k in range(3)]


def _alta_to_cartesian(name, v):
    if name == "SPHERICAL_TL_PL_TV_PV":
        return [math.cos(v[3]) * math.sin(v[2]), math.sin(v[3]) * math.sin(v[2]),
                math.cos(v[2]), math.cos(v[1]) * math.sin(v[0]),
                math.sin(v[1]) * math.sin(v[0]), math.cos(v[0])]
    if name == "RUSIN_TH_PH_TD_PD":
        return _alta_half_to_cartesian(v[0], v[1], v[2], v[3])
    if name == "RUSIN_TH_TD_PD":
        return _alta_half_to_cartesian(v[0], 0.0, v[1], v[2])
    if name == "COS_TH":
        return _alta_half_to_cartesian(math.acos(v[0]), 0.0, 0.0, 0.0)
    assert name == "CARTESIAN"
    return list(v[:6])


@pytest.mark.parametrize("param", FOUR + ["RUSIN_TH_TD_PD"])
def test_alta_reference_reader(velvet, tmp_path, param):
    t = _isotropic_rows(velvet) if param == "RUSIN_TH_TD_PD" else velvet
    out = tmp_path / "t.alta"
    gonio.write_alta(t, out, param=param)
    header, dim_x, dim_y, rows = _alta_load_text(out.read_text())
    assert header["PARAM_IN"] == param and header["PARAM_OUT"] == "RGB_COLOR"
    assert (dim_y, header["VS"]) == (3, "2")
    k = _kept(t)
    cart = np.array([_alta_to_cartesian(param, r[:dim_x]) for r in rows])
    np.testing.assert_allclose(cart[:, 0:3], t.wo[k], atol=1e-9)       # V = wo
    np.testing.assert_allclose(cart[:, 3:6], t.wi[k], atol=1e-9)       # L = wi
    y = rows[:, dim_x:dim_x + 3]
    np.testing.assert_allclose(y, t.values[k], rtol=1e-12)
    np.testing.assert_allclose(rows[:, dim_x + 3], t.values[k, 0] - t.sigma[k, 0], rtol=1e-9)
    np.testing.assert_allclose(rows[:, dim_x + 6], t.values[k, 0] + t.sigma[k, 0], rtol=1e-9)


def test_alta_reference_reader_slice(shared_data, tmp_path):
    t = gonio.read(shared_data / "merl-slice" / "pink-felt-1d.alta")
    gonio.write(t, tmp_path / "s.alta")
    header, dim_x, _, rows = _alta_load_text((tmp_path / "s.alta").read_text())
    assert (header["PARAM_IN"], dim_x, "VS" in header) == ("COS_TH", 1, False)
    cart = np.array([_alta_to_cartesian("COS_TH", r[:1]) for r in rows])
    np.testing.assert_allclose(cart[:, 3:6], t.wi, atol=1e-9)
    np.testing.assert_allclose(cart[:, 0:3], t.wo, atol=1e-9)


SPH = "#DIM 4 3\n#PARAM_IN SPHERICAL_TL_PL_TV_PV\n#PARAM_OUT RGB_COLOR\n"


@pytest.mark.parametrize("text, pattern", [
    (SPH + "4 0 0.5 3 1 2 3\n",
     r"line 4: theta_l = 4 is outside \[0, 3.14159\] .*coordinate 1"),
    (SPH + "0.5 0 0.5 7 1 2 3\n", r"line 4: phi_v = 7 is outside \[-6.28319, 6.28319\]"),
    (SPH + "0.5 0 0.5 3_0 1 2 3\n", r"line 4: not a number .*'3_0' is not a number"),
    (SPH + "0.5 nan 0.5 3 1 2 3\n", r"line 4: not a number .*'nan'"),
    (SPH + "0.5 0 0.5 3 1 2 infinity\n", r"line 4: not a number .*'infinity'"),
    ("#DIM 6 3\n#PARAM_IN CARTESIAN\n#PARAM_OUT RGB_COLOR\n0 0 0 0 0 1 1 2 3\n",
     "line 4: a zero vector"),
    ("#DIM 6 3\n#PARAM_IN CARTESIAN\n#PARAM_OUT RGB_COLOR\n0 0 2 0 0 1 1 2 3\n",
     r"line 4: V.z = 2 is outside \[-1, 1\]"),
    ("#DIM 1 3\n#PARAM_IN COS_TH\n#PARAM_OUT RGB_COLOR\n0.5 1 2 3\n1.5 1 2 3\n",
     r"line 5: COS_TH = 1.5 is outside \[0, 1\]"),
])
def test_strict_numbers_and_coordinate_ranges(tmp_path, text, pattern):
    p = tmp_path / "bad.alta"
    p.write_text(text)
    with pytest.raises(gonio.FormatError, match="bad.alta: " + pattern):
        gonio.read_alta(p)



def test_header_source_is_json_and_old_headers_still_read(tmp_path):
    """The source comes first as ``# source: JSON`` (it was the Python repr of a measured
    table's dict, ``# {'type': ...}``); files with the old first line still read."""
    source = {"type": "Fabric", "name": "linen_plain", "note": "it's \"quoted\"",
              "snr": float("nan")}
    t = gonio.Table([[0, 0, 1.0], [0.6, 0, 0.8]], [[0.6, 0, 0.8]] * 2,
                    [[0.1, 0.2, 0.1], [0.2, 0.3, 0.4]], meta={"source": source})
    gonio.write(t, tmp_path / "t.alta")
    first = (tmp_path / "t.alta").read_text().splitlines()[0]
    assert first.startswith("# source: {")
    assert json.loads(first.removeprefix("# source: ")) == dict(source, snr=None)
    back = gonio.read(tmp_path / "t.alta")
    assert back.meta["comments"][0] == first[2:] and len(back) == 2
    old = tmp_path / "old.alta"
    old.write_text("# {'type': 'Fabric', 'name': 'velvet'}\n" + SPH + "0.5 0 0.5 3 0.1 0.2 0.3\n")
    assert gonio.read(old).meta["comments"][0] == "{'type': 'Fabric', 'name': 'velvet'}"

def test_values_may_be_nan_or_inf_and_byte_order_mark(tmp_path):
    p = tmp_path / "t.alta"
    p.write_bytes(b"\xef\xbb\xbf" + (SPH + "0.5 0 0.5 3 NaN inf -1e-3\n").encode())
    t = gonio.read_alta(p)
    assert np.isnan(t.values[0, 0]) and t.values[0, 1] == np.inf and t.values[0, 2] == -1e-3


def test_write_refuses_a_table_without_rows_to_keep(tmp_path):
    t = gonio.Table([[0, 0, 1.0]], [[0.6, 0, 0.8]], [[np.nan, 1, 1]])
    with pytest.raises(ValueError, match="every one of the table's 1 rows has a missing"):
        gonio.write_alta(t, tmp_path / "t.alta")
    with pytest.raises(ValueError, match="digits must be an integer >= 1"):
        gonio.write_alta(t, tmp_path / "t.alta", digits=2.5)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("param", ["SPHERICAL_TL_PL_TV_PV", "RUSIN_TH_PH_TD_PD"])
def test_directions_near_the_normal_round_trip(tmp_path, param):
    """A direction 1e-8 rad off the normal came back on it (theta from arccos(z), whose
    z = 1 - 5e-17 rounds to 1); now to the last digits (Rusinkiewicz: to 1e-12, where
    phi_h is taken as 0)."""
    wo = np.array([[1e-8, 0.0, 1.0], [3e-9, -4e-9, 1.0], [0.0, 0.0, 1.0]])
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    wi = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0, 1e-10, 1.0]])
    t = gonio.Table(wi, wo, np.full((3, 3), 0.25))
    gonio.write(t, tmp_path / "t.alta", param=param)
    back = gonio.read(tmp_path / "t.alta")
    atol = 1e-15 if param.startswith("SPHERICAL") else 1e-12
    np.testing.assert_allclose(back.wo, t.wo, rtol=0, atol=atol)
    np.testing.assert_allclose(back.wi, t.wi, rtol=0, atol=atol)
    assert back.wo[0, 0] > 0.99e-8 and np.array_equal(back.values, t.values)
