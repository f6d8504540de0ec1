"""Tests of gonio.measure: cone averages, noise, seeds, rotation, metadata, chunking."""

import dataclasses
import json
import math

import numpy as np
import pytest

import gonio
from gonio import Geometry, Instrument, from_spec, measure
from gonio import geometry as G
from gonio import layouts as L


# ------------------------------------------------------------------ analytic BRDFs of our own

class Lambert:
    """f_r = albedo / pi above the horizon."""

    def __init__(self, albedo=(0.2, 0.5, 0.8)):
        self.albedo = np.asarray(albedo, float)

    def eval(self, wi, wo):
        up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
        return np.where(up[..., None], self.albedo / np.pi, 0.0)


class Affine:
    """f = a + b . wi + c . wo (RGB by three b's), no horizon: for the exactness test."""

    a = np.array([1.0, 2.0, 3.0])
    b = np.array([[0.3, -0.2, 0.5], [0.0, 0.4, -0.1], [0.2, 0.2, 0.2]])   # (channel, xyz)
    c = np.array([[-0.1, 0.6, 0.3], [0.5, 0.0, 0.2], [0.1, -0.3, 0.4]])

    def eval(self, wi, wo):
        return self.a + wi @ self.b.T + wo @ self.c.T


class Phong:
    """Normalized Phong lobe about the mirror direction: smooth, peaked."""

    def __init__(self, k=30.0):
        self.k = k

    def eval(self, wi, wo):
        r = wi * np.array([-1.0, -1.0, 1.0])
        c = np.clip(np.sum(r * wo, axis=-1), 0.0, None)
        up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
        f = np.where(up, (self.k + 2) / (2 * np.pi) * c ** self.k, 0.0)
        return np.repeat(f[..., None], 3, axis=-1) * np.array([1.0, 0.8, 0.6])


class Poly:
    """A smooth BRDF made of + and * only (bitwise independent of the batch size)."""

    def eval(self, wi, wo):
        q = wi[..., 0] * wo[..., 0] + wi[..., 1] * wo[..., 1] + wi[..., 2] * wo[..., 2]
        f = 0.1 + 0.2 * q * q + 0.05 * wi[..., 0]
        return f[..., None] * np.array([1.0, 0.5, 0.25])


class Ward:
    """Anisotropic Ward BRDF with its tangent at azimuth ``rho`` (radians), written directly
    with t = (cos rho, sin rho, 0), not by rotating directions."""

    def __init__(self, ax=0.15, ay=0.45, rho=0.0):
        self.ax, self.ay, self.rho = ax, ay, rho

    def eval(self, wi, wo):
        t = np.array([math.cos(self.rho), math.sin(self.rho), 0.0])
        b = np.array([-math.sin(self.rho), math.cos(self.rho), 0.0])
        h = wi + wo
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        zi, zo = wi[..., 2], wo[..., 2]
        up = (zi > 0) & (zo > 0)
        e = -((h @ t / self.ax) ** 2 + (h @ b / self.ay) ** 2) / h[..., 2] ** 2
        f = np.exp(e) / (4 * np.pi * self.ax * self.ay * np.sqrt(np.abs(zi * zo)) + 1e-300)
        return np.repeat(np.where(up, f, 0.0)[..., None], 3, axis=-1)


# ------------------------------------------------------------------ cone averages

def test_point_instrument_is_the_brdf():
    g = L.full_grid(30)
    t = measure(Phong(), g)
    assert np.array_equal(t.values, Phong().eval(g.wi, g.wo))
    assert t.sigma is None and np.allclose(t.wi, g.wi, rtol=0, atol=1e-15)


def test_lambertian_exact_under_cones():
    g = L.full_grid(20)
    g = g.subset((g.wi[:, 2] > math.cos(math.radians(70))) & (g.wo[:, 2] > 0.4))
    t = measure(Lambert(), g, Instrument(cone_source=8, cone_detector=12))
    assert np.allclose(t.values, np.array([0.2, 0.5, 0.8]) / np.pi, rtol=1e-14, atol=0)


def test_affine_exact_under_cones():
    """Cone averages of wi and wo are (1 + cos a)/2 times the axes, by calculus."""
    g = L.plane("45", 20, theta_i=[0, 40])
    ins = Instrument(cone_source=6.0, cone_detector=15.0, rings=1, azimuths=3)
    t = measure(Affine(), g, ins)
    cs = (1 + math.cos(math.radians(6))) / 2
    cd = (1 + math.cos(math.radians(15))) / 2
    expect = Affine.a + cs * g.wi @ Affine.b.T + cd * g.wo @ Affine.c.T
    assert np.allclose(t.values, expect, rtol=0, atol=1e-14)


def test_cone_average_converges_to_point_value():
    wi = G.directions_from_angles(math.radians(30), 0.0)[None]
    wo = G.directions_from_angles(math.radians(33), math.radians(182))[None]
    g = L.pairs(wi, wo)
    brdf = Phong(40)
    point = brdf.eval(wi, wo)[0, 0]
    errs = []
    for half in (4.0, 2.0, 1.0, 0.5, 0.25):
        v = measure(brdf, g, Instrument(cone_source=half, cone_detector=half)).values[0, 0]
        errs.append(abs(v - point))
    assert all(a > b for a, b in zip(errs, errs[1:]))            # error decreasing
    # second order: halving the cone divides the error by about 4
    assert all(3.0 < a / b < 5.0 for a, b in zip(errs[2:], errs[3:]))
    assert errs[-1] / point < 1e-3


def test_cone_average_is_the_uniform_solid_angle_average():
    """Against a Monte Carlo average with independent, uniform-in-solid-angle cone samples."""
    half_s, half_d = 3.0, 5.0
    wi = G.directions_from_angles(math.radians(40), math.radians(10))
    wo = G.directions_from_angles(math.radians(38), math.radians(195))
    brdf = Phong(60)
    rng = np.random.default_rng(11)
    n = 200_000

    def cap_samples(axis, half):
        c = math.cos(math.radians(half))
        ct = 1 - rng.uniform(0, 1 - c, n)
        ph = rng.uniform(0, 2 * np.pi, n)
        st = np.sqrt(1 - ct ** 2)
        # any orthonormal frame about the axis
        t = np.cross(axis, [0.0, 1.0, 0.0])
        t /= np.linalg.norm(t)
        b = np.cross(axis, t)
        return (st * np.cos(ph))[:, None] * t + (st * np.sin(ph))[:, None] * b + ct[:, None] * axis

    f = brdf.eval(cap_samples(wi, half_s), cap_samples(wo, half_d))[:, 0]
    ins = Instrument(cone_source=half_s, cone_detector=half_d, rings=5, azimuths=12)
    v = measure(brdf, L.pairs(wi[None], wo[None]), ins).values[0, 0]
    assert abs(v - f.mean()) < 5 * f.std() / math.sqrt(n)
    point = brdf.eval(wi, wo)[0]
    assert abs(point - f.mean()) > 10 * f.std() / math.sqrt(n)   # the cones do matter here


# ------------------------------------------------------------------ noise and seeds

def test_noise_statistics_over_many_seeds():
    g = L.plane("warp", 30, theta_i=[0, 60])
    brdf = Phong(5)
    truth = measure(brdf, g).values
    ins = Instrument(snr=20, floor=0.003)
    n = 400
    runs = np.stack([measure(brdf, g, ins, seed=s).values for s in range(n)])
    sigma = np.sqrt((truth / 20) ** 2 + 0.003 ** 2)          # the model, by hand
    t0 = measure(brdf, g, ins, seed=0)
    assert np.allclose(t0.sigma, sigma)
    mean = runs.mean(axis=0)
    var = runs.var(axis=0, ddof=1)
    assert np.all(np.abs(mean - truth) < 5 * sigma / math.sqrt(n))
    assert np.all(np.abs(var - sigma ** 2) < 5 * sigma ** 2 * math.sqrt(2 / (n - 1)))


def test_same_seed_same_bytes_any_chunking():
    g = L.full_grid(30)
    ins = Instrument(cone_source=1, cone_detector=2, snr=30, floor=1e-3)
    a = measure(Poly(), g, ins, seed=5)
    a2 = measure(Poly(), g, ins, seed=5)
    b = measure(Poly(), g, ins, seed=5, chunk=7)
    c = measure(Poly(), g, ins, seed=6)
    assert a.values.tobytes() == a2.values.tobytes()
    assert a.sigma.tobytes() == a2.sigma.tobytes()
    assert a.values.tobytes() == b.values.tobytes()          # chunking changes no byte
    assert a.values.tobytes() != c.values.tobytes()
    d = measure(Poly(), g, ins, seed=np.random.default_rng(5))
    assert d.values.tobytes() == a.values.tobytes()
    assert d.meta["seed"].startswith("numpy.random.Generator") and a.meta["seed"] == 5


def test_measure_leaves_the_geometry_intact():
    g = L.full_grid(30)
    before = g.wi_lab.copy(), g.wo_lab.copy()
    t = measure(Poly(), g)
    assert np.array_equal(g.wi_lab, before[0]) and np.array_equal(g.wo_lab, before[1])
    assert not np.shares_memory(t.wi, g.wi_lab)
    with pytest.raises(ValueError):
        g.wi_lab[0, 0] = 1.0                     # geometry arrays are read-only


def test_negative_values_kept_and_flagged():
    g = L.full_grid(30)
    t = measure(Lambert((0.001, 0.001, 0.001)), g, Instrument(floor=0.01), seed=2)
    neg = t.values < 0
    assert neg.any() and (~neg).any()
    assert np.array_equal(~t.valid, neg)


def test_shot_noise_through_measure():
    g = L.plane("warp", 30, theta_i=[30])
    ins = Instrument(snr=10, noise="shot", snr_reference=0.1)
    t = measure(Lambert(), g, ins, seed=0)
    k = 10 ** 2 / 0.1
    assert np.allclose(t.values * k, np.round(t.values * k))
    assert np.allclose(t.sigma, np.sqrt(np.array([0.2, 0.5, 0.8]) / np.pi * 0.1 / 100))


# ------------------------------------------------------------------ rotation

@pytest.mark.parametrize("r", [0.3, -1.1, math.pi / 2])
def test_geometry_rotation_equals_rotated_brdf(r):
    g = L.full_grid(30)
    ins = Instrument(cone_source=2, cone_detector=3)
    a = measure(Ward(rho=0.0), g.with_rotation(r), ins)
    b = measure(Ward(rho=r), g, ins)
    assert np.allclose(a.values, b.values, rtol=1e-10, atol=1e-12)


def test_rotating_the_sample_90_deg_swaps_warp_and_weft_planes():
    warp = measure(Ward(), L.plane("warp", 10))
    weft_rot = measure(Ward(), L.plane("weft", 10, rotation=math.pi / 2))
    weft = measure(Ward(), L.plane("weft", 10))
    assert np.allclose(warp.values, weft_rot.values, rtol=1e-12)
    assert not np.allclose(warp.values, weft.values, rtol=1e-3)       # it is anisotropic
    # the table's directions are in the sample frame: the rotated weft plane is the warp plane
    assert np.allclose(weft_rot.wi, warp.wi, atol=1e-12)


def test_fabric_rotation_matches_geometry_rotation():
    brdf = pytest.importorskip("brdf")
    if not hasattr(brdf, "fabric"):
        pytest.skip("brdf.fabric not available")
    fab = brdf.fabric("silk_shot", tangent_samples=8)
    g = L.full_grid(30)
    for r in (0.4, math.pi / 2):
        a = measure(fab, g.with_rotation(r))
        b = measure(fab.replace(rotation=r), g)
        assert np.allclose(a.values, b.values, rtol=1e-9, atol=1e-12)
    t = measure(fab, "plane:weft:30", Instrument(snr=40), seed=1)
    assert t.meta["source"]["name"] == "silk_shot"
    assert t.meta["source"]["options"]["tangent_samples"] == 8
    assert len(t.meta["source"]["threads"]) == 2
    assert np.all(np.isfinite(t.values))


# ------------------------------------------------------------------ table, meta, geometry kept

def test_meta_is_plain_and_complete():
    @dataclasses.dataclass
    class Thread:
        eta: float
        offsets: tuple

    class FabricLike(Lambert):
        name = "test_cloth"
        threads = (Thread(1.5, (-20.0, 20.0)), Thread(1.3, (0.0,)))
        options = {"masking": True, "tangent_samples": np.int64(8)}

    g = L.merl(45, rotation=0.2)
    ins = Instrument(cone_detector=1.0, snr=50, floor=1e-4)
    t = measure(FabricLike(), g, ins, seed=3)
    m = t.meta
    assert json.loads(json.dumps(m)) == m
    assert m["units"] == "1/sr" and m["seed"] == 3 and m["quantity"] == "f_r"
    assert m["source"] == {"type": "FabricLike", "name": "test_cloth",
                           "options": {"masking": True, "tangent_samples": 8},
                           "threads": [{"eta": 1.5, "offsets": [-20.0, 20.0]},
                                       {"eta": 1.3, "offsets": [0.0]}]}
    assert m["geometry"]["spec"] == "merl:45" and m["geometry"]["rotation"] == 0.2
    assert m["geometry"]["n"] == len(t) == len(g)
    assert m["instrument"]["cone_detector"] == 1.0 and m["instrument"]["snr"] == 50
    from importlib.metadata import version
    assert m["version"] == version("microcyl")


@pytest.mark.parametrize("spec", ["full:30", "plane:45:15", "merl:9", "rusinkiewicz:30"])
def test_geometry_from_table(spec):
    g = from_spec(spec, rotation=0.7)
    t = measure(Lambert(), g)
    back = Geometry.from_table(t)
    assert back.kind == g.kind and back.rotation == g.rotation and back.params == g.params
    assert np.allclose(back.wi_lab, g.wi_lab) and np.allclose(back.wo_lab, g.wo_lab)
    for k, v in g.coords.items():
        ok = np.ones(len(g), bool)
        if k.startswith("phi"):                       # azimuths: equal modulo 2 pi, where defined
            theta = g.coords["theta" + k[3:]]
            ok = theta > 1e-9
            if k == "phi_d":
                ok &= g.coords["theta_h"] > 1e-9
            d = np.angle(np.exp(1j * (back.coords[k] - v)))
            assert np.allclose(d[ok], 0, atol=1e-9), k
        else:
            assert np.allclose(back.coords[k], v, atol=1e-9), k
    if g.kind == "merl":
        assert np.array_equal(back.index, g.index)


# ------------------------------------------------------------------ chunks, progress, bad input

def test_chunks_bound_each_eval_call():
    sizes = []

    class Recorder(Lambert):
        def eval(self, wi, wo):
            sizes.append(wi.shape[0])
            return super().eval(wi, wo)

    g = L.full_grid(30)
    ins = Instrument(cone_source=1, cone_detector=1)          # 144 evaluations per pair
    measure(Recorder(), g, ins, chunk=1000)
    assert max(sizes) <= 1000 and sum(sizes) == len(g) * 144
    sizes.clear()
    measure(Recorder(), g, chunk=10)                          # point instrument: 10 pairs
    assert max(sizes) == 10 and sum(sizes) == len(g)


def test_progress_bar_and_grey_output(capsys):
    class Grey:
        def eval(self, wi, wo):
            return np.full(wi.shape[:-1], 0.25)

    t = measure(Grey(), L.full_grid(45), progress=True, chunk=5)
    assert np.all(t.values == 0.25) and t.values.shape == (len(t), 3)
    assert "measure" in capsys.readouterr().err


def test_spec_string_geometry():
    t = measure(Lambert(), "plane:weft:30:30")
    assert t.meta["geometry"]["kind"] == "plane" and len(t) == 5


@pytest.mark.parametrize("call, match", [
    (lambda: measure(object(), "full:30"), "eval"),
    (lambda: measure(Lambert(), 42), "geometry must be"),
    (lambda: measure(Lambert(), "full:x"), "geometry spec"),
    (lambda: measure(Lambert(), "full:30", instrument={"snr": 3}), "instrument must be"),
    (lambda: measure(Lambert(), "full:30", seed=-1), "seed"),
    (lambda: measure(Lambert(), "full:30", seed=1.5), "seed"),
    (lambda: measure(Lambert(), "full:30", seed=True), "seed"),
    (lambda: measure(Lambert(), "full:30", chunk=0), "chunk"),
])
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_bad_brdf_output_shape():
    class Wrong:
        def eval(self, wi, wo):
            return np.zeros((wi.shape[0], 2))

    with pytest.raises(ValueError, match=r"Wrong.eval returned shape"):
        measure(Wrong(), "full:45")


def test_public_names():
    for name in ("measure", "Geometry", "Instrument", "full_grid", "plane", "rusinkiewicz",
                 "merl_grid", "pairs", "pairs_from_angles", "Table"):
        assert name in gonio.__all__ and hasattr(gonio, name)


def test_measured_merl_file_agrees_with_the_fabric_written_at_bin_centres(tmp_path):
    """``measure`` on the MERL layout (no noise, no cone) and ``gonio.write`` of the fabric
    itself give the same file to round-off, read back here with the MERL layout computed
    independently: int32 (90, 90, 180), then R, G, B float64 blocks scaled by 1/1500,
    1.15/1500 and 1.66/1500, entry k + 180 (j + 90 i)."""
    import brdf
    import gonio
    from gonio.merl import write_merl
    fab = brdf.fabric("silk_crepe_de_chine")
    table = gonio.measure(fab, "merl:6", gonio.Instrument(), seed=0, progress=False)
    gonio.write(table, tmp_path / "measured.binary")
    write_merl(fab, tmp_path / "fabric.binary", rotations=1)

    def read(path):
        raw = path.read_bytes()
        assert np.frombuffer(raw[:12], "<i4").tolist() == [90, 90, 180]
        v = np.frombuffer(raw[12:], "<f8").reshape(3, -1)
        scale = np.array([1.0, 1.15, 1.66])[:, None] / 1500.0
        return np.where(v >= 0, v * scale, -1.0)

    got, want = read(tmp_path / "measured.binary"), read(tmp_path / "fabric.binary")
    i, j, k = np.meshgrid(np.arange(0, 90, 6), np.arange(0, 90, 6), np.arange(0, 180, 6),
                          indexing="ij")
    flat = (k + 180 * (j + 90 * i)).ravel()
    above = np.all(want[:, flat] >= 0, axis=0)           # bin centre above the horizon
    assert above.mean() > 0.4
    np.testing.assert_allclose(got[:, flat[above]], want[:, flat[above]], rtol=1e-12)
    assert np.all(got[:, flat[~above]] == -1.0)
    others = np.setdiff1d(np.arange(got.shape[1]), flat)
    assert np.all(got[:, others] == -1.0)                # nothing lands outside its own bin
    assert got.max() < 1e3
