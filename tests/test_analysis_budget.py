"""analysis.budget: pair counts of geometry specs without building them, the memory limit
(the least of MemAvailable, RLIMIT_AS, the cgroup's limit and MICROCYL_MEMORY_LIMIT), table
sizes estimated before parsing, and the refusals of work too large for the limit (measure,
info, fit, geometry layouts, tangent samples)."""

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import brdf
import gonio
from analysis.budget import check_memory, memory_limit, spec_pairs
from gonio import memory
from gonio.geomspec import from_spec
from gonio.merl import FILE_SIZE as MERL_FILE_SIZE
from gonio.rgl import read_tensor_field, read_tensor_file
from gonio.tablesize import check_table, estimate_table, text_estimate
from reports.cli import main

ROOT = Path(__file__).resolve().parents[1]
ENV = dict({k: v for k, v in os.environ.items() if k != "MICROCYL_MEMORY_LIMIT"},
           PYTHONPATH=str(ROOT), COLUMNS="100", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
GB = 1 << 30


def _cli(*args, env=None, **kw):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)],
                          env=dict(ENV, **(env or {})), capture_output=True, text=True,
                          timeout=120, **kw)


def _one_line_refusal(proc, start):
    assert proc.returncode == 1, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert lines[0].startswith(start), lines[0]
    return lines[0]


# -- pair counts ---------------------------------------------------------------------------

@pytest.mark.parametrize("spec", ["full:30", "full:45:90", "full:20:40:30:60", "rus:30",
                                  "rus:30:90:45:120", "merl:9", "merl:30", "plane:warp:5",
                                  "plane:weft:30:0,30", "plane:17.5:7"])
def test_spec_pairs_counts_what_from_spec_builds(spec):
    g = from_spec(spec)
    assert spec_pairs(spec) == len(g) + g.info.get("dropped_below_horizon", 0)


def test_spec_pairs_of_files_or_malformed_specs_is_none():
    for spec in ("pairs:x.csv", "full:x", "full:-1", "full:nan", "sphere:3", "plane:warp:0"):
        assert spec_pairs(spec) is None
    assert spec_pairs("full:1e-300") == float("inf")
    # plane: 6 incidences x theta_o = k step in (-90, 90): 2 x 89,999,999,999 + 1 each
    assert spec_pairs("plane:warp:1e-9") == 6 * (2 * 89_999_999_999 + 1)


# -- the memory limit: the least of its sources --------------------------------------------

@pytest.fixture
def sources(monkeypatch):
    """Every source of the limit replaced; set one with ``sources(name, value)``."""
    monkeypatch.delenv(memory.ENV, raising=False)
    for name in ("meminfo_available", "address_space_left", "cgroup_memory_left"):
        monkeypatch.setattr(memory, name, lambda: None)

    def set_source(name, value):
        if name == "env":
            monkeypatch.setenv(memory.ENV, value)
        else:
            monkeypatch.setattr(memory, name, lambda: value)
    return set_source


def test_limit_is_80_percent_of_memavailable(sources):
    sources("meminfo_available", 10 * GB)
    assert memory_limit() == (8 * GB, "80% of MemAvailable, the memory available")


def test_limit_follows_rlimit_as_when_it_is_the_least(sources):
    sources("meminfo_available", 20 * GB)
    sources("address_space_left", (5 * GB, 8 * GB))        # 8 GB ulimit, 3 GB used
    limit, how = memory_limit()
    assert limit == 4 * GB
    assert how == "80% of the address space left under ulimit -v, RLIMIT_AS 8.0 GB"
    with pytest.raises(ValueError, match=r"^work would take about 4.5 GB of memory; the limit "
                                         r"is 4.0 GB \(80% of the address space left under "
                                         r"ulimit -v, RLIMIT_AS 8.0 GB\); do less$"):
        check_memory("work", 4.5 * GB, "do less")


def test_limit_follows_the_cgroup_when_it_is_the_least(sources):
    sources("meminfo_available", 20 * GB)
    sources("address_space_left", (15 * GB, 16 * GB))
    sources("cgroup_memory_left", (10 * GB, 12 * GB))
    assert memory_limit() == (8 * GB, "80% of the memory left in the cgroup, memory.max 12.0 GB")


def test_limit_from_the_environment_only_lowers_it(sources):
    sources("meminfo_available", 10 * GB)
    sources("env", "2G")
    assert memory_limit() == (2 * GB, "MICROCYL_MEMORY_LIMIT")
    with pytest.raises(ValueError, match=r"^work would take about 3.0 GB of memory; the limit "
                                         r"is 2.0 GB \(MICROCYL_MEMORY_LIMIT\); do less$"):
        check_memory("work", 3 * GB, "do less")
    check_memory("work", 1 * GB, "do less")
    sources("env", "64G")                       # more than the machine has: the machine's
    assert memory_limit() == (8 * GB, "80% of MemAvailable, the memory available")
    sources("env", "500M")
    assert memory_limit()[0] == 500 << 20


def test_a_bad_environment_limit_is_refused_by_name(sources):
    sources("env", "lots")
    with pytest.raises(ValueError, match=r"^MICROCYL_MEMORY_LIMIT='lots' is not a size"):
        memory_limit()


def _fake_cgroup(monkeypatch, tmp_path, proc_line, files):
    proc = tmp_path / "proc_cgroup"
    proc.write_text(proc_line + "\n")
    for rel, text in files.items():
        (tmp_path / "fs" / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "fs" / rel).write_text(text)
    monkeypatch.setattr(memory, "PROC_CGROUP", proc)
    monkeypatch.setattr(memory, "CGROUP_ROOT", tmp_path / "fs")


def test_cgroup_v2_memory_max_is_read_relative_to_the_process_cgroup(monkeypatch, tmp_path):
    _fake_cgroup(monkeypatch, tmp_path, "0::/user.slice/job", {
        "memory.max": "max\n",
        "user.slice/memory.max": "max\n",
        "user.slice/job/memory.max": str(4 * GB),
        "user.slice/job/memory.current": str(GB + (256 << 20)),
        "user.slice/job/memory.stat": f"anon 1\ninactive_file {256 << 20}\n",
        "other/memory.max": "1024",                    # not this process's cgroup
    })
    assert memory.cgroup_memory_left() == (3 * GB, 4 * GB)


def test_cgroup_v2_limit_of_an_ancestor_counts(monkeypatch, tmp_path):
    _fake_cgroup(monkeypatch, tmp_path, "0::/a/b", {
        "a/memory.max": str(2 * GB), "a/memory.current": str(GB),
        "a/b/memory.max": "max", "a/b/memory.current": str(GB // 2),
    })
    assert memory.cgroup_memory_left() == (GB, 2 * GB)


def test_cgroup_v1_limit_in_bytes(monkeypatch, tmp_path):
    _fake_cgroup(monkeypatch, tmp_path, "4:memory:/docker/abc\n0::/", {
        "memory/memory.limit_in_bytes": "9223372036854771712",      # the root: no limit
        "memory/docker/abc/memory.limit_in_bytes": str(6 * GB),
        "memory/docker/abc/memory.usage_in_bytes": str(2 * GB),
        "memory/docker/abc/memory.stat": f"cache 5\ntotal_inactive_file {GB}\n",
    })
    assert memory.cgroup_memory_left() == (5 * GB, 6 * GB)


def test_no_cgroup_limit_is_none(monkeypatch, tmp_path):
    _fake_cgroup(monkeypatch, tmp_path, "4:memory:/\n0::/", {
        "memory/memory.limit_in_bytes": "9223372036854771712", "memory.max": "max"})
    assert memory.cgroup_memory_left() is None


def test_address_space_left_subtracts_what_the_process_holds(monkeypatch):
    monkeypatch.setattr(memory.resource, "getrlimit", lambda which: (8 * GB, 8 * GB))
    left, soft = memory.address_space_left()
    assert soft == 8 * GB
    vm = int(Path("/proc/self/status").read_text().split("VmSize:")[1].split()[0]) * 1024
    assert abs((8 * GB - left) - vm) < 256 << 20


_PRINT_LIMIT = ("from gonio.memory import memory_limit; import json; "
                "print(json.dumps(memory_limit()))")


def _limit_under(rlimit):
    def preexec():
        resource.setrlimit(resource.RLIMIT_AS, (rlimit, rlimit))
    out = subprocess.run([sys.executable, "-c", _PRINT_LIMIT], env=ENV, capture_output=True,
                         text=True, timeout=60, preexec_fn=preexec, check=True)
    return json.loads(out.stdout)


def test_a_real_ulimit_v_sets_the_limit():
    if memory.meminfo_available() is None or memory.meminfo_available() < 6 * GB:
        pytest.skip("needs MemAvailable above the ulimit tried")
    small, how = _limit_under(3 * GB)
    large, _ = _limit_under(4 * GB)
    assert "ulimit -v, RLIMIT_AS 3.0 GB" in how
    assert 0 < small < 0.8 * 3 * GB
    assert large - small == pytest.approx(0.8 * GB, rel=0.05)   # follows the ulimit


# -- tables sized before they are parsed ---------------------------------------------------

def _csv(path, rows, comment=True, end="\n"):
    head = "# source: \"big\"\n" if comment else ""
    path.write_text(head + "theta_i,phi_i,theta_o,phi_o,value\n"
                    + "30,0,30,180,0.1\n" * (rows - 1) + "30,0,30,180,0.1" + end)
    return path


def test_text_estimate_counts_lines_and_fields(tmp_path):
    e = text_estimate(_csv(tmp_path / "t.csv", 10, end=""))
    assert e.rows == 12 and e.basis == "12 lines of 5 fields"
    assert text_estimate(_csv(tmp_path / "u.csv", 10, comment=False)).rows == 11
    (tmp_path / "e.csv").write_bytes(b"")
    assert text_estimate(tmp_path / "e.csv").rows == 0


@pytest.mark.parametrize("sep", [",", ";", "\t"])
def test_csv_fields_are_counted_on_the_delimiter_of_the_header(tmp_path, sep):
    """A semicolon or tab file's fields counted as the reader splits them (a semicolon file
    was one field a line)."""
    p = tmp_path / "t.csv"
    p.write_text(_csv(tmp_path / "t.csv", 3).read_text().replace(",", sep))
    assert estimate_table(p, "csv").basis == "5 lines of 5 fields"


def test_a_million_rows_are_counted_in_well_under_a_second(tmp_path):
    p = _csv(tmp_path / "big.csv", 1_000_000)
    t0 = time.perf_counter()
    e = estimate_table(p, "csv")
    assert time.perf_counter() - t0 < 1.0
    assert e.rows == 1_000_002
    # a parse costs several hundred bytes a row (about 740 measured for 5 fields)
    assert 500 * e.rows < e.nbytes < 2000 * e.rows


@pytest.mark.parametrize("verb", ["info", "fit"])
def test_a_table_too_large_is_refused_before_it_is_parsed(verb, tmp_path):
    table = _csv(tmp_path / "big.csv", 200_000)
    args = ([verb, table] if verb == "info"
            else [verb, table, "--fabric", "velvet", "-o", tmp_path / "fit"])
    t0 = time.perf_counter()
    proc = _cli(*args, env={"MICROCYL_MEMORY_LIMIT": "20M"})
    line = _one_line_refusal(proc, f"microcyl {verb}: error: reading big.csv (200,002 lines "
                                   f"of 5 fields) would take about ")
    assert "the limit is 20.0 MB (MICROCYL_MEMORY_LIMIT)" in line
    assert time.perf_counter() - t0 < 15           # the parse alone takes longer
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.csv"]


def test_a_fit_too_large_for_its_evaluations_is_refused_before_reading(tmp_path):
    table = _csv(tmp_path / "big.csv", 200_000)
    # reading: about 200 MB; the fit's default 8 free parameters take 18 walkers, and their
    # batched evaluations 18 x 200,002 x 100 B a thread: more than the limit
    proc = _cli("fit", table, "--fabric", "velvet", "-o", tmp_path / "fit",
                env={"MICROCYL_MEMORY_LIMIT": "250M"})
    _one_line_refusal(proc, "microcyl fit: error: fitting big.csv (about 200,002 rows) with 18 "
                            "walkers (--walkers) would take about ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.csv"]


def test_an_exr_is_sized_from_its_header(tmp_path, monkeypatch):
    n = 1000
    t = gonio.Table(np.tile([0, 0, 1.0], (n, 1)), np.tile([0.6, 0, 0.8], (n, 1)),
                    np.full((n, 3), 0.1), None, {})
    p = tmp_path / "t.exr"
    gonio.write(t, p)
    e = estimate_table(p, "exr")
    assert e.rows == 32 * 32                     # the near-square block of 1000 rows
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "100K")
    with pytest.raises(ValueError, match=r"^reading t.exr \(the image size in the OpenEXR "
                                         r"header\) would take about .* the limit is 100.0 KB"):
        gonio.read(p)
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "10M")
    assert len(gonio.read(p)) == n


def test_a_merl_file_is_sized_from_its_stride(tmp_path, monkeypatch):
    p = tmp_path / "m.binary"
    with open(p, "wb") as fh:                  # a valid header, zeros (a sparse file)
        fh.write(np.array([90, 90, 180], "<i4").tobytes())
        fh.truncate(MERL_FILE_SIZE)
    assert estimate_table(p, "merl").rows == 1_458_000
    assert estimate_table(p, "merl", stride=10).rows == 9 * 9 * 18
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "200M")
    with pytest.raises(ValueError, match=r"^reading m.binary \(the MERL layout and the stride\)"
                                         r" would take .*; use a larger stride \(--stride\)$"):
        gonio.read(p)
    assert len(gonio.read(p, stride=10)) == 9 * 9 * 18


def test_an_rgl_file_is_sized_from_its_header(shared_data):
    path = shared_data / "rgl" / "acrylic_felt_white_rgb.bsdf"
    whole = read_tensor_file(path)
    np.testing.assert_array_equal(read_tensor_field(path, "theta_i"), whole["theta_i"])
    assert read_tensor_field(path, "no such field") is None
    n_i = int(np.count_nonzero(whole["theta_i"] < np.radians(89.9)))
    e = estimate_table(path, "rgl", step=10)
    assert e.rows == n_i * 9 * 36
    assert len(gonio.read(path, step=10)) <= e.rows


def test_curet_and_alta_are_sized_from_their_lines(shared_data, monkeypatch):
    curet = shared_data / "curet" / "abrdf.dat"
    e = estimate_table(curet, "curet")
    assert e.rows == 61 + 205                   # abrdf.dat's samples and table.txt's rows
    assert e.basis == "61 lines of 206 fields and 205 lines of 5 fields"
    alta = shared_data / "merl-slice" / "pink-felt-1d.alta"
    lines = alta.read_bytes().splitlines()
    first = next(ln for ln in lines if ln.strip() and not ln.startswith(b"#"))
    e = estimate_table(alta, "alta")
    assert (e.rows, e.basis) == (len(lines), f"{len(lines):,} lines of {len(first.split())} "
                                             f"fields")
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "10K")
    for path, options in ((curet, {"sample": 44}), (alta, {})):
        with pytest.raises(ValueError, match=rf"^reading {path.name} \(.* lines of"):
            gonio.read(path, **options)


def test_a_pairs_file_too_large_is_refused(tmp_path, monkeypatch):
    p = tmp_path / "p.csv"
    p.write_text("theta_i,phi_i,theta_o,phi_o\n" + "30,0,30,180\n" * 20_000)
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "1M")
    with pytest.raises(ValueError, match=r"^reading p.csv \(20,001 lines of 4 fields\)"):
        from_spec(f"pairs:{p}")
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "100M")
    assert check_table(p, "csv").rows == 20_001
    assert len(from_spec(f"pairs:{p}")) == 20_000


# -- geometry steps and tangent samples: one rule on every path ----------------------------

def test_measure_with_a_plane_too_fine_is_refused_in_one_line(tmp_path):
    proc = _cli("measure", "velvet", "--geometry", "plane:warp:1e-9", "-o", tmp_path / "a.csv")
    _one_line_refusal(proc, "microcyl measure: error: --geometry plane:warp:1e-9 (1.08e+12 "
                            "pairs) would take about ")
    assert list(tmp_path.iterdir()) == []


def test_every_layout_is_checked_against_the_memory_limit(monkeypatch):
    with pytest.raises(ValueError, match=r"^plane: the steps give 1,079,999,999,994 "):
        gonio.plane("warp", 1e-9)
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "1M")
    for build, kind in ((lambda: gonio.full_grid(10), "full_grid"),
                        (lambda: gonio.plane("warp", 0.01), "plane"),
                        (lambda: gonio.rusinkiewicz(10), "rusinkiewicz"),
                        (lambda: gonio.merl_grid(2), "merl"),
                        (lambda: from_spec("full:10"), "full_grid")):
        with pytest.raises(memory.MemoryLimitError,
                           match=rf"^{kind}: [0-9,]+ direction pairs would take about "
                                 r".*MICROCYL_MEMORY_LIMIT\); use coarser"):
            build()


@pytest.mark.parametrize("n", [0, 4097, 10**12, True])
def test_tangent_samples_are_capped_on_every_path(n):
    with pytest.raises(ValueError, match=r"^tangent_samples must be an integer in 1\.\.4096; "):
        brdf.fabric("velvet", tangent_samples=n)
    with pytest.raises(ValueError, match=r"tangent_samples must be an integer in 1\.\.4096"):
        brdf.fabric("velvet").threads[0].curve.samples(n)
    assert brdf.fabric("velvet", tangent_samples=4096).options["tangent_samples"] == 4096


def test_a_fabric_json_with_too_many_tangent_samples_is_refused_in_one_line(tmp_path):
    fab = tmp_path / "fab.json"
    fab.write_text(json.dumps({"type": "microcylinder", "fabric": "velvet",
                               "tangent_samples": 10**12}))
    proc = _cli("render", "patch", fab, "-o", tmp_path / "r.png")
    line = _one_line_refusal(proc, "microcyl render: error: ")
    assert line.endswith("tangent_samples must be an integer in 1..4096; got 1000000000000")
    assert not (tmp_path / "r.png").exists()


@pytest.mark.parametrize("argv, start", [
    (["measure", "velvet", "--geometry", "full:0.5", "-o", "x.exr"],
     "microcyl measure: error: --geometry full:0.5 (1.66e+10 pairs) would take about 6.0 TB"),
    (["fit", "t.csv", "--fabric", "velvet", "--ensembles", "100000", "-o", "f"],
     "microcyl fit: error: --ensembles must be an integer in 2..64"),
])
def test_too_large_work_is_refused_before_it_starts(argv, start, tmp_path, monkeypatch,
                                                    capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MICROCYL_MEMORY_LIMIT", "4G")
    assert main(argv) == 1
    assert capsys.readouterr().err.startswith(start)
    assert list(tmp_path.iterdir()) == []
