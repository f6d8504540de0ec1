"""A hostile checkpoint.h5 is read as data, never as a file system (issue 35): built with
h5py from a real short fit's checkpoint, each is refused in one line naming the file and the
reason, before any value is read, by the resume (`microcyl fit` run again), by `plan FITDIR`
and by FitFolder.read_checkpoint, through gonio.safeh5.read_h5. Each test fails on the code
before it (which opened checkpoint.h5 by name and read every dataset under ensemble_K)."""

import os
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from analysis.fit import FitFolder
from gonio.safeh5 import H5Data, H5Group, read_h5
from test_cli_state_files import FIT, _copy, fit, microcyl, refused  # noqa: F401 (fixture)

ROOT = Path(__file__).resolve().parents[1]
CKPT = "checkpoint.h5"


def resume(folder, table, *extra, env=None, timeout=300):
    """`microcyl fit` run again on ``folder`` (a resume to 60 steps)."""
    return subprocess.run([sys.executable, "-m", "reports", "fit", str(table), *FIT,
                           "--max-steps", "60", "--no-progress", "--no-plots", "-o",
                           str(folder), *extra], env=env or _env(), capture_output=True,
                          text=True, timeout=timeout)


def _env(**more):
    return dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100", **more)


def _secret(tmp_path, ref) -> tuple[Path, bytes]:
    """A file outside the fit folder holding valid chain values no fit wrote (the chain
    plus 1e-7): what a hostile checkpoint tries to copy into the fit's folder."""
    with h5py.File(ref / CKPT, "r") as f:
        chain = f["ensemble_0/chain"][()]
    data = (chain + 1e-7).astype("<f8").tobytes()
    path = tmp_path / "secret.bin"
    path.write_bytes(data)
    return path, data


def _replace(path, name, make):
    """Replace dataset ``name`` of the HDF5 file by what ``make(f, name, old)`` creates."""
    with h5py.File(path, "r+") as f:
        old = f[name][()]
        del f[name]
        make(f, name, old)


def _external_storage(tmp_path, bad):
    secret, data = _secret(tmp_path, bad)
    _replace(bad / CKPT, "ensemble_0/chain", lambda f, n, old: f.create_dataset(
        n, shape=old.shape, dtype="<f8", external=[(str(secret), 0, len(data))]))
    return data, "external raw storage"


def _external_link(tmp_path, bad):
    secret, data = _secret(tmp_path, bad)
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as o, h5py.File(bad / CKPT, "r") as f:
        o["chain"] = np.frombuffer(data, "<f8").reshape(f["ensemble_0/chain"].shape)
    _replace(bad / CKPT, "ensemble_0/chain",
             lambda f, n, old: f.__setitem__(n, h5py.ExternalLink(str(other), "/chain")))
    return data, "external link"


def _virtual(tmp_path, bad):
    secret, data = _secret(tmp_path, bad)
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as o, h5py.File(bad / CKPT, "r") as f:
        shape = f["ensemble_0/chain"].shape
        o["chain"] = np.frombuffer(data, "<f8").reshape(shape)

    def make(f, n, old):
        layout = h5py.VirtualLayout(shape=shape, dtype="<f8")
        layout[...] = h5py.VirtualSource(str(other), "chain", shape=shape)
        f.create_virtual_dataset(n, layout)
    _replace(bad / CKPT, "ensemble_0/chain", make)
    return data, "virtual"


def _symlink(tmp_path, bad):
    """checkpoint.h5 a symbolic link to a checkpoint elsewhere holding the secret chain."""
    secret, data = _secret(tmp_path, bad)
    elsewhere = tmp_path / "elsewhere.h5"
    os.replace(bad / CKPT, elsewhere)
    with h5py.File(elsewhere, "r+") as f:
        f["ensemble_0/chain"][...] = np.frombuffer(data, "<f8").reshape(
            f["ensemble_0/chain"].shape)
    os.symlink(elsewhere, bad / CKPT)
    return data, "symbolic link"


@pytest.mark.parametrize("plant", [_external_storage, _external_link, _virtual, _symlink])
def test_data_from_outside_the_file_is_refused_and_never_copied(fit, tmp_path, plant):
    """A chain whose bytes lie in another file: refused in one line naming the file and
    the reason; the other file's bytes reach neither the fit folder nor the plan."""
    bad = _copy(fit, tmp_path)
    data, why = plant(tmp_path, bad)
    before = {p.name: p.stat().st_mtime_ns for p in bad.iterdir()}
    err = refused(resume(bad, fit / "silk.csv"), bad / CKPT)
    assert why in err, err
    after = {p.name: p.stat().st_mtime_ns for p in bad.iterdir()}
    assert after == before                          # nothing written: refused before work
    for p in bad.iterdir():
        if p.is_file() and not p.is_symlink():
            assert data[:64] not in p.read_bytes(), p
    plan = tmp_path / "plan.csv"
    err = refused(microcyl("plan", bad, "--budget", 4, "--candidates", "full:30:60",
                           "--draws", 2, "--snr", 20, "-o", plan, "--no-progress"),
                  bad / CKPT)
    assert why in err and not plan.exists(), err


def _soft_link(f):
    del f["ensemble_1/chain"]
    f["ensemble_1/chain"] = h5py.SoftLink("/ensemble_0/chain")


def _hard_link_repeat(f):
    del f["ensemble_1"]
    f["ensemble_1"] = f["ensemble_0"]              # one node under two names


def _hard_link_dataset(f):
    del f["ensemble_1/accepted"]
    f["ensemble_1/accepted"] = f["ensemble_0/accepted"]


def _extra_entry(f):
    f["ensemble_0/rng/notes"] = np.zeros(3)


def _wrong_walkers(f):
    for k in (0, 1):
        g = f[f"ensemble_{k}"]
        for name in ("chain", "log_prob", "accepted"):
            a = g[name][()]
            del g[name]
            g[name] = np.concatenate([a, a[..., :1] if name == "accepted" else a[:, :1]],
                                     axis=-1 if name == "accepted" else 1)


def _enum_accepted(f):
    a = f["ensemble_0/accepted"][()]
    del f["ensemble_0/accepted"]
    f.create_dataset("ensemble_0/accepted", data=a.astype("i1"),
                     dtype=h5py.enum_dtype({"a": 0, "b": 1}, basetype="i1"))


def _long_double_chain(f):
    a = f["ensemble_0/chain"][()]
    del f["ensemble_0/chain"]
    f["ensemble_0/chain"] = a.astype(np.longdouble)


def _attribute_on_dataset(f):
    f["ensemble_0/chain"].attrs["note"] = "x"


def _array_attribute(f):
    f["ensemble_0/rng"].attrs["pos"] = np.arange(3)


@pytest.mark.parametrize("change, field, why", [
    (_soft_link, "ensemble_1.chain", "soft link"),
    (_hard_link_repeat, "ensemble_1", "hard link to a node reached before"),
    (_hard_link_dataset, "ensemble_1.accepted", "hard link to a node reached before"),
    (_extra_entry, "ensemble_0.rng", "at most 1 entry (keys)"),
    (_wrong_walkers, "ensemble_0.accepted", "shape (6,); got shape (7,)"),
    (_enum_accepted, "ensemble_0.accepted", "enum"),
    (_long_double_chain, "ensemble_0.chain", "16 bytes"),
    (_attribute_on_dataset, "ensemble_0.chain.attrs", "no attribute"),
    (_array_attribute, "ensemble_0.rng.attr:pos", "a single value")])
def test_a_structure_the_fit_does_not_write_is_refused_before_reading(fit, tmp_path, change,
                                                                       field, why):
    """Links, repeated nodes, entries, shapes and kinds not written by the fit (its walkers
    and free parameters from fit_config.json): one line naming the file and the field."""
    bad = _copy(fit, tmp_path)
    with h5py.File(bad / CKPT, "r+") as f:
        change(f)
    with pytest.raises(ValueError) as exc:
        FitFolder(bad).read_checkpoint()
    msg = str(exc.value)
    assert len(msg.splitlines()) == 1 and msg.startswith(f"{bad / CKPT}: {field} "), msg
    assert why in msg, msg


def test_the_resume_names_a_soft_link(fit, tmp_path):
    bad = _copy(fit, tmp_path)
    with h5py.File(bad / CKPT, "r+") as f:
        _soft_link(f)
    refused(resume(bad, fit / "silk.csv"), bad / CKPT, "ensemble_1.chain", "soft link")


def test_hard_link_fan_out_is_refused_at_once(fit, tmp_path):
    """3 levels of 60 hard links (216,000 paths, a few KB): refused without visiting them."""
    bad = _copy(fit, tmp_path)
    with h5py.File(bad / CKPT, "r+") as f:
        leaf = f.create_group("ensemble_0/proposal/fan")
        leaf["v"] = np.zeros(1)
        for level in range(3):
            g = f.create_group(f"ensemble_0/proposal/level{level}")
            for i in range(60):
                g[f"l{i}"] = leaf
            leaf = g
        for name in ("fan", "level0", "level1"):
            del f[f"ensemble_0/proposal/{name}"]     # the top level alone is linked in
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="ensemble_0.proposal") as exc:
        FitFolder(bad).read_checkpoint()
    assert time.perf_counter() - t0 < 2.0
    assert str(exc.value).startswith(f"{bad / CKPT}: "), exc.value


_RSS = """import resource, subprocess, sys
p = subprocess.run(sys.argv[1:], capture_output=True, text=True, timeout=300)
sys.stderr.write(p.stderr)
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
sys.exit(p.returncode)
"""


@pytest.mark.parametrize("values, chunks, why", [
    (2.5e8, True, "chunked storage"),                  # the layout the fit never writes
    (2.5e8, None, "memory"),                           # contiguous: the declared size
    (1e11, None, "memory")])
def test_an_unwritten_huge_chain_is_refused_without_allocating(fit, tmp_path, values,
                                                                chunks, why):
    """A chain declaring ``values`` values (a few KB on disk): the resume under
    MICROCYL_MEMORY_LIMIT=100M exits with one line, its peak memory far below the
    2 GB (or 800 GB) a read would take."""
    bad = _copy(fit, tmp_path)
    steps = int(values // 12)                           # 6 walkers x 2 parameters
    for k in (0, 1):
        _replace(bad / CKPT, f"ensemble_{k}/chain", lambda f, n, old: f.create_dataset(
            n, shape=(steps, 6, 2), dtype="<f8", chunks=chunks and (1024, 6, 2)))
        _replace(bad / CKPT, f"ensemble_{k}/log_prob", lambda f, n, old: f.create_dataset(
            n, shape=(steps, 6), dtype="<f8", chunks=chunks and (1024, 6)))
    assert (bad / CKPT).stat().st_size < 200_000
    cmd = [sys.executable, "-m", "reports", "fit", str(fit / "silk.csv"), *FIT,
           "--max-steps", "60", "--no-progress", "--no-plots", "-o", str(bad)]
    p = subprocess.run([sys.executable, "-c", _RSS, *cmd], capture_output=True, text=True,
                       timeout=300, env=_env(MICROCYL_MEMORY_LIMIT="100M"))
    refused(p, bad / CKPT, "ensemble_0.chain" if chunks else "", why)
    assert "MemoryError" not in p.stderr
    peak_kib = int(p.stdout.split()[-1])
    assert peak_kib < 500 << 10, f"peak RSS {peak_kib} KiB"       # the read: 2 GB or more


def test_a_fifo_checkpoint_is_one_line_at_once(fit, tmp_path):
    """A FIFO in place of checkpoint.h5: the resume exits with one line within seconds
    (it used to block opening it, holding the folder's lock, forever)."""
    bad = _copy(fit, tmp_path)
    (bad / CKPT).unlink()
    os.mkfifo(bad / CKPT)
    t0 = time.perf_counter()
    try:
        p = resume(bad, fit / "silk.csv", timeout=90)
    except subprocess.TimeoutExpired:
        pytest.fail("the resume blocked on the FIFO")
    refused(p, bad / CKPT, "FIFO")
    assert time.perf_counter() - t0 < 60
    with pytest.raises(ValueError, match="FIFO"):
        FitFolder(bad).read_checkpoint()


def test_read_h5_counts_nodes_and_attributes(tmp_path):
    """The generic reader: an attribute the layout does not name, and a dataset under a
    group where the layout has a group, are refused by field."""
    p = tmp_path / "a.h5"
    with h5py.File(p, "w") as f:
        f["g"] = np.zeros(2)
        f.attrs["extra"] = 1
    layout = H5Group({"g": H5Group({})})
    with pytest.raises(ValueError, match=r"a\.h5: g must be a group; got a dataset"):
        read_h5(p, layout, what="a test file")
    assert read_h5(p, H5Group({"g": H5Data((2,))}, attrs={"extra": "int"}),
                   what="a test file")["g"].tolist() == [0, 0]
    with h5py.File(p, "r+") as f:
        del f["g"]
        f.create_group("g")
    with pytest.raises(ValueError, match=r"a\.h5: attrs must be at most 0 attributes"):
        read_h5(p, layout, what="a test file")


def test_checkpoint_h5_has_one_reader():
    """Only gonio/safeh5.py opens an HDF5 file for reading; analysis/fit/checkpoint.py
    writes one (through atomic_write) and reads through it. Any other h5py.File in the
    package sources would be a second reader of checkpoint.h5."""
    opened = {}
    for path in ROOT.glob("*/**/*.py"):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in ("tests", "bench", "docs", ".venv"):
            continue
        n = sum("h5py.File(" in line for line in path.read_text().splitlines()
                if not line.lstrip().startswith((">>>", "...")))     # doctests write files
        if n:
            opened[str(rel)] = n
    assert opened == {"gonio/safeh5.py": 1, "analysis/fit/checkpoint.py": 1}, opened
    text = (ROOT / "analysis" / "fit" / "checkpoint.py").read_text()
    assert 'h5py.File(fh, "w")' in text and "read_h5(" in text
