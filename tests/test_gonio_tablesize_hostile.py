"""gonio.tablesize, gonio.rgl, gonio.exr and gonio.csvtable against hostile table files: each
is refused in one line naming the file before it is parsed (under a low memory limit, with
a small peak memory, where the file would take much more), and every table that is read
takes no more memory than its estimate said (issue 35, items 3, 5b and 10b)."""

import json
import os
import random
import struct
import subprocess
import sys
import tracemalloc
from pathlib import Path

import numpy as np
import OpenEXR
import pytest

import brdf
import gonio
from analysis.measurejob import measure_estimate
from gonio.io import table_kind
from gonio.rgl import read_tensor_file
from gonio.table import MAX_META_BYTES
from gonio.tablesize import check_table, estimate_table, text_estimate
from reports.cli import main

ROOT = Path(__file__).resolve().parents[1]
ENV = dict({k: v for k, v in os.environ.items() if k != "MICROCYL_MEMORY_LIMIT"},
           PYTHONPATH=str(ROOT), COLUMNS="100", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
HEADER = b"theta_i,phi_i,theta_o,phi_o,value"
ROW = b"30,0,30,180,0.1"
#: Runs a command and prints its exit status, stderr and peak RSS (KiB): the wrapper has no
#: other child, so RUSAGE_CHILDREN's maximum is the command's alone.
_PEAK = ("import json, resource, subprocess, sys\n"
         "p = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
         "print(json.dumps([p.returncode, p.stderr, "
         "resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss]))")


def _run(*args, limit=None, cwd=None):
    """``microcyl ARGS`` in a subprocess: (exit status, stderr, peak RSS in MiB)."""
    env = dict(ENV, **({"MICROCYL_MEMORY_LIMIT": limit} if limit else {}))
    out = subprocess.run([sys.executable, "-c", _PEAK, sys.executable, "-m", "reports",
                          *map(str, args)], env=env, capture_output=True, text=True,
                         timeout=300, cwd=cwd)
    rc, err, kib = json.loads(out.stdout)
    return rc, err, kib / 1024


def _one_line(rc, err, start):
    assert rc == 1, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(start), lines[0]
    return lines[0]


@pytest.fixture(scope="module")
def baseline(tmp_path_factory):
    """Peak RSS (MiB) of ``microcyl info`` of a one-row table: what the command line takes
    before a table's size matters."""
    p = tmp_path_factory.mktemp("base") / "t.csv"
    p.write_bytes(HEADER + b"\n" + ROW + b"\n")
    rc, err, peak = _run("info", p)
    assert rc == 0, err
    return peak


def _tracemalloc_peak(fn):
    fn()                                    # imports and caches made once, not counted
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


# -- line ends: every one the readers split on -------------------------------------------

def test_every_line_end_of_str_splitlines_is_counted(tmp_path):
    """The estimate's lines are the reader's (str.splitlines of the decoded text) for
    random texts of every line end, split across the scan's chunks too."""
    ends = [c for c in map(chr, range(0x3000)) if len(f"a{c}b".splitlines()) == 2]
    assert "\r" in ends and "\x85" in ends and "\u2028" in ends      # the reference set
    alphabet = ends + ["\r\n", "a", "1", ",", "#", " ", "é", "\U0001F600"]
    rng = random.Random(7)
    p = tmp_path / "t.csv"
    for _ in range(300):
        text = "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 60)))
        p.write_bytes(text.encode())
        assert text_estimate(p).rows == len(text.splitlines()), repr(text)


def test_a_file_of_cr_line_ends_is_counted_line_by_line(tmp_path):
    p = tmp_path / "t.csv"
    p.write_bytes(HEADER + b"\r" + (ROW + b"\r") * 999 + ROW)
    assert estimate_table(p, "csv").basis == "1,001 lines of 5 fields"
    alta = tmp_path / "t.alta"
    alta.write_bytes(b"#DIM 1 3\r#PARAM_IN COS_TH\r#PARAM_OUT RGB_COLOR\r"
                     + b"0.5 0.1 0.1 0.1\r" * 500)
    assert estimate_table(alta, "alta").basis == "503 lines of 4 fields"
    assert len(gonio.read(alta)) == 500


def test_a_cr_table_too_large_is_refused_before_it_is_parsed(tmp_path, baseline):
    """A 4 MB CSV of \\r line ends (250,000 rows, about 300 MB to parse) under a 150 MB
    limit: refused at once; it was counted as one line and parsed."""
    p = tmp_path / "cr.csv"
    p.write_bytes(HEADER + b"\r" + (ROW + b"\r") * 250_000)
    rc, err, peak = _run("info", p, limit="150M")
    _one_line(rc, err, "microcyl info: error: reading cr.csv (250,001 lines of 5 fields) "
                       "would take about ")
    assert peak < baseline + 60, (peak, baseline)


def test_a_cr_table_that_is_read_takes_no_more_than_its_estimate(tmp_path):
    p = tmp_path / "cr.csv"
    p.write_bytes(HEADER + b"\r" + (ROW + b"\r") * 20_000)
    est = estimate_table(p, "csv")
    assert _tracemalloc_peak(lambda: gonio.read(p)) <= est.nbytes


# -- metadata: capped and counted --------------------------------------------------------

def _meta_csv(path, nbytes):
    """A table whose header and row come first, then one comment line of about ``nbytes``
    of JSON (``[[],[],...]``, many objects for few bytes)."""
    path.write_bytes(HEADER + b"\n" + ROW + b"\n# junk: [" + b"[]," * (nbytes // 3) + b"[]]\n")
    return path


def test_csv_metadata_over_the_cap_is_refused_before_it_is_parsed(tmp_path, baseline):
    p = _meta_csv(tmp_path / "meta.csv", 6_000_000)
    rc, err, peak = _run("info", p, limit="100M")
    # the bytes from the # to the line's end: "# junk: [" and 2,000,000 "[]," and "[]]"
    line = _one_line(rc, err, f"microcyl info: error: {p}: the # comment lines: "
                              f"{9 + 6_000_000 + 3:,} bytes, more than the ")
    assert line.endswith(f"{MAX_META_BYTES:,} a table's metadata may hold (microcyl writes "
                         "a few KB)")
    assert peak < baseline + 50, (peak, baseline)
    with pytest.raises(gonio.FormatError, match=r"meta.csv: line 3: the metadata so far: "
                                                r"[0-9,]+ bytes, more than the 1,048,576"):
        gonio.read_csv(p)                       # the parser's own check, without gonio.read


def test_csv_metadata_under_the_cap_is_counted(tmp_path):
    p = _meta_csv(tmp_path / "meta.csv", MAX_META_BYTES - 4096)
    est = estimate_table(p, "csv")
    assert est.rows == 3
    assert _tracemalloc_peak(lambda: gonio.read(p)) <= est.nbytes
    assert len(gonio.read(p).meta["junk"]) > 300_000


def _exr(path, meta=None, parts=1, deep_samples=0):
    """A microcyl table as OpenEXR, with its microcyl_meta replaced by ``meta``; or as
    ``parts`` parts; or as a 4 x 4 deep image of ``deep_samples`` samples a pixel."""
    if deep_samples:
        column = np.zeros(deep_samples, np.float32)
        pixels = np.empty((4, 4), dtype=object)
        for i in range(16):
            pixels.flat[i] = column          # one array for every pixel: cheap to write
        header = {"type": OpenEXR.deepscanline, "compression": OpenEXR.ZIPS_COMPRESSION}
        with OpenEXR.File(header, {"R": pixels}) as f:
            f.write(str(path))
        return path
    t = gonio.Table([[0, 0, 1.0]], [[0.6, 0, 0.8]], [0.25], meta={"source": "x"})
    gonio.write(t, path)
    with OpenEXR.File(str(path), separate_channels=True) as f:
        header = dict(f.header())
        channels = {k: v.pixels for k, v in f.channels().items()}
    if meta is not None:
        header["microcyl_meta"] = meta
    if parts > 1:
        part = [OpenEXR.Part(dict(header, name=f"p{j}"),
                             {k: OpenEXR.Channel(v) for k, v in channels.items()}, f"p{j}")
                for j in range(parts)]
        with OpenEXR.File(part) as f:
            f.write(str(path))
        return path
    with OpenEXR.File(header, {k: OpenEXR.Channel(v) for k, v in channels.items()}) as f:
        f.write(str(path))
    return path


def test_exr_metadata_over_the_cap_is_refused_before_it_is_parsed(tmp_path, baseline):
    p = _exr(tmp_path / "meta.exr", json.dumps({"junk": [[]] * 1_500_000}))
    rc, err, peak = _run("info", p, limit="100M")
    _one_line(rc, err, f"microcyl info: error: {p}: the microcyl_meta attribute: "
                       "6,000,010 bytes, more than the 1,048,576 a table's metadata")
    assert peak < baseline + 100, (peak, baseline)
    with pytest.raises(gonio.FormatError, match="meta.exr: the microcyl_meta attribute"):
        gonio.read_exr(p)


def test_exr_metadata_under_the_cap_is_counted(tmp_path):
    p = _exr(tmp_path / "meta.exr", json.dumps({"junk": [[]] * 250_000}))
    est = estimate_table(p, "exr")
    assert _tracemalloc_peak(lambda: gonio.read(p)) <= est.nbytes


def test_a_deep_exr_is_refused_before_its_pixels_are_read(tmp_path, baseline):
    """16 pixels of 4,000,000 samples each: a 260 KB file that took 500 MB to read."""
    p = _exr(tmp_path / "deep.exr", deep_samples=4_000_000)
    rc, err, peak = _run("info", p, limit="100M")
    _one_line(rc, err, f"microcyl info: error: {p}: a deep OpenEXR image (deepscanline); "
                       "a microcyl table is one flat scanline or tiled image")
    assert peak < baseline + 60, (peak, baseline)


def test_a_multi_part_exr_is_refused_by_name(tmp_path):
    p = _exr(tmp_path / "two.exr", parts=2)
    for read in (gonio.read, gonio.read_exr, lambda q: check_table(q, "exr")):
        with pytest.raises(gonio.FormatError, match=r"two.exr: a multi-part OpenEXR file "
                                                    r"\(2 parts\)"):
            read(p)


# -- RGL: the field table checked on every load ----------------------------------------------

_CODES = {np.dtype("u1"): 1, np.dtype("<u4"): 5, np.dtype("<f4"): 10, np.dtype("<f8"): 11}


def _tensor_bytes(fields, offsets=None):
    """A tensor file (Dupuy and Jakob's layout, written here from its description): the
    header, then each field 8-byte aligned; ``offsets`` overrides where fields point."""
    head = b"tensor_file\0" + bytes([1, 0]) + struct.pack("<I", len(fields))
    size = len(head) + sum(13 + len(n) + 8 * np.ndim(a) for n, a in fields.items())
    start = (size + 7) // 8 * 8
    data, place = b"", {}
    for name, a in fields.items():
        a = np.ascontiguousarray(a)
        place[name] = start + len(data)
        data += a.tobytes() + b"\0" * (-a.nbytes % 8)
    place.update(offsets or {})
    for name, a in fields.items():
        a = np.asarray(a)
        head += (struct.pack("<H", len(name)) + name.encode()
                 + struct.pack("<HBQ", a.ndim, _CODES[a.dtype], place[name])
                 + struct.pack(f"<{a.ndim}Q", *a.shape))
    return head + b"\0" * (start - len(head)) + data, place


@pytest.fixture(scope="module")
def felt(shared_data):
    """The white felt's fields (copies)."""
    fields = read_tensor_file(shared_data / "rgl" / "acrylic_felt_white_rgb.bsdf")
    return {k: np.array(v) for k, v in fields.items()}


@pytest.fixture(scope="module")
def aliasing(felt, tmp_path_factory):
    """The felt with ``rgb`` and ``luminance`` pointing at the bytes of ``vndf``."""
    _, place = _tensor_bytes(felt)
    data, _ = _tensor_bytes(felt, {"rgb": place["vndf"], "luminance": place["vndf"]})
    p = tmp_path_factory.mktemp("alias") / "alias.bsdf"
    p.write_bytes(data)
    return p


def test_aliasing_fields_are_refused_on_every_load(aliasing, felt, tmp_path):
    copy = tmp_path / "copy.bsdf"                   # the same fields, each in bytes of its own
    copy.write_bytes(_tensor_bytes(felt)[0])
    w = np.array([[0.3, 0.1, 0.9]]) / np.linalg.norm([0.3, 0.1, 0.9])
    np.testing.assert_array_equal(gonio.load_rgl(copy).eval(w, w[:, [1, 0, 2]]),
                                  gonio.RGLBRDF(felt).eval(w, w[:, [1, 0, 2]]))
    message = r"alias.bsdf: fields '(luminance|rgb|vndf)' and '(luminance|rgb|vndf)' overlap"
    for load in (gonio.load_rgl, read_tensor_file, gonio.read,
                 lambda p: check_table(p, "rgl"), lambda p: estimate_table(p, "rgl")):
        with pytest.raises(gonio.FormatError, match=message):
            load(aliasing)


@pytest.mark.parametrize("argv", [
    ["info", "{f}"],
    ["eval", "{f}", "--wi", "30,0", "--wo", "30,180"],
    ["render", "patch", "{f}", "-o", "{d}/r.png"],
    ["plot", "table", "{f}", "--fabric", "velvet", "-o", "{d}/p.png"],
    ["reciprocity", "{f}", "--no-felts", "-n", "100"],
    ["reciprocity", "velvet", "--data", "{d}", "-n", "100"],
    ["sanity", "{f}"],
], ids=lambda a: "-".join(a[:2]))
def test_every_verb_that_loads_an_rgl_file_refuses_an_aliasing_one(argv, aliasing, tmp_path,
                                                                   capsys):
    (tmp_path / "rgl").mkdir()
    (tmp_path / "rgl" / "acrylic_felt_white_rgb.bsdf").write_bytes(aliasing.read_bytes())
    args = [a.format(f=aliasing, d=tmp_path) for a in argv]
    assert main(args) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert err.startswith(f"microcyl {argv[0]}: error: ")
    assert "alias.bsdf" in err or "acrylic_felt_white_rgb.bsdf" in err
    assert "overlap" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rgl"]


def test_fields_inside_the_header_or_past_the_file_are_refused(felt, tmp_path):
    p = tmp_path / "x.bsdf"
    p.write_bytes(_tensor_bytes(felt, {"jacobian": 20})[0])
    with pytest.raises(gonio.FormatError, match=r"x.bsdf: field 'jacobian' starts at byte 20, "
                                                r"inside the header"):
        gonio.load_rgl(p)
    data, place = _tensor_bytes(felt)
    p.write_bytes(data[:place["rgb"] + 100])
    with pytest.raises(gonio.FormatError, match=r"x.bsdf: wrong size: field 'rgb'"):
        gonio.load_rgl(p)


@pytest.mark.parametrize("change, message", [
    ({"phi_i": np.zeros(3, np.float32)}, r"field 'phi_i' must increase strictly"),
    ({"theta_i": np.zeros(0, np.float32)}, r"field 'theta_i' must be a non-empty list"),
    ({"ndf": np.ones((1, 1), np.float32), "sigma": np.ones((1, 1), np.float32)},
     r"field '(ndf|sigma)' is a 1 x 1 grid"),
    ({"vndf": np.ones((1, 8, 1, 1), np.float32)}, r"field 'vndf' is a 1 x 1 grid"),
    ({"theta_i": np.float32([0, 0.5, 0.4, 0.6, 0.7, 0.8, 0.9, 1.0])},
     r"field 'theta_i' must increase strictly"),
    ({"theta_i": np.float32([0, 0.5, 1, 1.5, 2, 2.5, 3, np.nan])},
     r"field 'theta_i' must increase strictly"),
    ({"jacobian": np.zeros(0, np.uint8)}, r"field 'jacobian' is empty"),
], ids=["equal-phi", "empty-theta", "1x1-ndf", "1x1-vndf", "unordered", "nan", "no-jacobian"])
def test_damaged_rgl_files_are_refused_in_one_line_naming_the_field(change, message, felt,
                                                                    tmp_path, capsys):
    fields = dict(felt, **change)
    if "phi_i" in change:                   # the grids follow phi_i's count
        n = len(change["phi_i"])
        fields["vndf"] = np.repeat(felt["vndf"], n, axis=0)
        fields["rgb"] = np.repeat(felt["rgb"], n, axis=0)
    p = tmp_path / "damaged.bsdf"
    p.write_bytes(_tensor_bytes(fields)[0])
    with pytest.raises(gonio.FormatError, match=r"damaged.bsdf: " + message):
        gonio.load_rgl(p)
    assert main(["eval", str(p), "--wi", "30,0", "--wo", "30,180"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "damaged.bsdf" in err and "Traceback" not in err


def test_an_rgl_file_too_large_to_load_is_refused_from_its_header(tmp_path, felt, monkeypatch):
    p = tmp_path / "felt.bsdf"
    p.write_bytes(_tensor_bytes(felt)[0])
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "1M")
    with pytest.raises(ValueError, match=r"^loading felt.bsdf \(11 fields, 6\d\d,\d\d\d bytes\) "
                                         r"would take about .* the limit is 1.0 MB"):
        gonio.load_rgl(p)


# -- the real tables: read within their estimates ------------------------------------------

@pytest.mark.parametrize("name, options", [
    ("rgl/acrylic_felt_white_rgb.bsdf", {"step": 5}),
    ("rgl/acrylic_felt_pink_rgb.bsdf", {"step": 5}),
    ("rgl/acrylic_felt_purple_rgb.bsdf", {"step": 10}),
    ("curet/abrdf.dat", {"sample": 44}),
    ("merl-slice/pink-felt-1d.alta", {}),
])
def test_every_real_table_is_read_within_its_estimate(name, options, shared_data):
    """Not too strict: the estimate is at least the peak of reading (tracemalloc) and at
    most 20 times it; the RGL files load."""
    path = shared_data / name
    if path.suffix == ".bsdf":
        assert gonio.load_rgl(path).isotropic
    est = estimate_table(path, table_kind(path), **options)
    peak = _tracemalloc_peak(lambda: gonio.read(path, **options))
    assert peak <= est.nbytes <= 20 * peak, (peak, est)


# -- tangent control points: the budget of tangent samples ---------------------------------

def test_a_curve_lists_at_most_as_many_control_points_as_tangent_samples():
    n = brdf.MAX_TANGENT_SAMPLES
    t = brdf.fabric("velvet").threads[0]
    ok = t.replace(offsets=tuple(np.linspace(-30, 30, n)), lengths=(1.0,) * (n - 1))
    assert len(ok.offsets) == n
    with pytest.raises(ValueError, match=rf"^offsets must list at most {n} tangent offsets "
                                         r"\(control points\) per curve.*; got 4,097$"):
        t.replace(offsets=tuple(np.linspace(-30, 30, n + 1)), lengths=(1.0,) * n)


def test_a_fabric_json_of_36000_control_points_is_refused_in_one_line(tmp_path):
    k = 36_000
    doc = {"type": "microcylinder", "fabric": "velvet"}
    for j in (1, 2):
        doc[f"offsets{j}"] = ", ".join(["-30", "30"] * (k // 2))
        doc[f"lengths{j}"] = ", ".join(["1"] * (k - 1))
    fab = tmp_path / "fab.json"
    fab.write_text(json.dumps(doc))
    rc, err, _ = _run("render", "patch", fab, "-o", tmp_path / "r.png")
    line = _one_line(rc, err, "microcyl render: error: ")
    assert "fab.json" in line and line.endswith("got 36,000")
    assert not (tmp_path / "r.png").exists()


def test_measure_counts_control_points_as_tangent_samples():
    """Under tangent_sampling=control_points, a curve of 64 control points costs as 64
    tangent samples do under midpoint sampling."""
    velvet = brdf.fabric("velvet")
    many = tuple(t.replace(offsets=tuple(np.linspace(-30, 30, 64)), lengths=(1.0,) * 63)
                 for t in velvet.threads)
    spec = "plane:0:10:30"
    points = brdf.Fabric(many, **dict(velvet.options, tangent_sampling="control_points"))
    samples = brdf.Fabric(many, **dict(velvet.options, tangent_samples=64))
    assert measure_estimate(spec, gonio.Instrument(), points)[2] == pytest.approx(
        measure_estimate(spec, gonio.Instrument(), samples)[2])
