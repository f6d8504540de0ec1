"""Files from a shared folder opened once, as data (issue 35), as a user meets them: a FIFO in
place of a fit's results.json or fit_config.json or of a table, a deflate bomb in place of
loo.npz, a results.json of 31 MB and a fit_config.json nested too deeply, given to `export`,
`eval`, `info` and `compare`. Each is refused at once with one line naming the file, exit
status 1, no traceback, and no reader hangs or inflates what a file claims."""

import io
import os
import shutil
import struct
import subprocess
import sys
import time
import zlib
from pathlib import Path

import numpy as np
import pytest
from numpy.lib import format as npformat

import gonio
from _fitmodels import fabric_table

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
#: A refusal comes within seconds; a reader that hangs on a FIFO is killed here.
PATIENCE_S = 60


def microcyl(*args, env=None):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)],
                          env=dict(ENV, **(env or {})), capture_output=True, text=True,
                          timeout=PATIENCE_S)


def refused(p, *names):
    """Exit 1, one line on stderr naming each of ``names``, no traceback."""
    err = p.stderr.strip()
    assert p.returncode == 1, (p.returncode, p.stdout[-500:], err[-2000:])
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for n in names:
        assert str(n) in err, f"{n!r} not in {err!r}"
    return err


@pytest.fixture(scope="module")
def fit(tmp_path_factory):
    """A table and a finished short fit of it (with its loo.npz)."""
    d = tmp_path_factory.mktemp("untrusted")
    table, _ = fabric_table("silk_crepe_de_chine", n=60, seed=4)
    gonio.write(table, d / "silk.csv")
    p = microcyl("fit", d / "silk.csv", "--fabric", "silk_crepe_de_chine", "--free",
                 "gamma_s1,kd1", "--tie", "none", "--check-every", "20", "--ensembles", "2",
                 "--max-steps", "40", "--no-plots", "--no-progress", "-o", d / "fit")
    assert p.returncode == 0, p.stderr
    assert (d / "fit" / "loo.npz").is_file()
    return d / "fit"


def _copy_with(fit, tmp_path, name):
    """A copy of the fit whose file ``name`` is removed (for the caller to replace)."""
    out = tmp_path / "copy"
    shutil.copytree(fit, out)
    (out / name).unlink()
    return out


@pytest.mark.parametrize("name", ["results.json", "fit_config.json"])
def test_a_fifo_in_a_fit_folder_is_one_line_at_once(fit, tmp_path, name):
    bad = _copy_with(fit, tmp_path, name)
    os.mkfifo(bad / name)
    for args in (("export", bad, "-o", tmp_path / "x.json"),
                 ("eval", bad, "--wi", "30,0", "--wo", "30,180"),
                 ("compare", bad, fit)):
        t0 = time.monotonic()
        err = refused(microcyl(*args), bad / name)
        assert "FIFO" in err and time.monotonic() - t0 < PATIENCE_S / 2, err
    assert not (tmp_path / "x.json").exists()


@pytest.mark.parametrize("name", ["t.csv", "t.exr", "t.binary", "t.alta", "t.bsdf"])
def test_a_fifo_in_place_of_a_table_is_one_line_at_once(tmp_path, name):
    os.mkfifo(tmp_path / name)
    err = refused(microcyl("info", tmp_path / name), tmp_path / name)
    assert "FIFO" in err


def test_a_link_in_place_of_a_table_is_refused_by_name(tmp_path):
    table, _ = fabric_table("silk_crepe_de_chine", n=20, seed=1)
    gonio.write(table, tmp_path / "real.csv")
    (tmp_path / "t.csv").symlink_to(tmp_path / "real.csv")
    err = refused(microcyl("info", tmp_path / "t.csv"), tmp_path / "t.csv")
    assert "symbolic link" in err


def _deflate_bomb(path, gib: float = 2.0):
    """An .npz whose ``elpd_i`` is a .npy of ``gib`` GiB of zeros, deflated to about 2 MB
    (the deflate of 1 MiB of zeros, repeated: each block ends with a full flush, so every
    block after the first is the same bytes). The directory declares the true size."""
    blocks = int(gib * 1024)
    n = blocks * (1 << 20) // 8
    head = npformat.header_data_from_array_1_0(np.zeros(0))
    head["shape"] = (n,)
    buf = io.BytesIO()
    npformat.write_array_header_1_0(buf, head)
    header = buf.getvalue()
    zeros = bytes(1 << 20)
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    first = c.compress(header) + c.compress(zeros) + c.flush(zlib.Z_FULL_FLUSH)
    block = c.compress(zeros) + c.flush(zlib.Z_FULL_FLUSH)
    assert block == c.compress(zeros) + c.flush(zlib.Z_FULL_FLUSH)
    data = first + block * (blocks - 2) + c.compress(zeros) + c.flush()
    size = len(header) + blocks * (1 << 20)
    crc = 0                                     # only checked after all of it is inflated
    name = b"elpd_i.npy"
    local = struct.pack("<4sHHHHHIIIHH", b"PK\x03\x04", 20, 0, 8, 0, 0x21, crc, len(data),
                        size, len(name), 0) + name
    central = struct.pack("<4sHHHHHHIIIHHHHHII", b"PK\x01\x02", 20, 20, 0, 8, 0, 0x21, crc,
                          len(data), size, len(name), 0, 0, 0, 0, 0, 0) + name
    end = struct.pack("<4sHHHHIIH", b"PK\x05\x06", 0, 0, 1, 1, len(central),
                      len(local) + len(data), 0)
    path.write_bytes(local + data + central + end)
    return size


def test_a_deflate_bomb_loo_npz_is_refused_before_it_is_inflated(fit, tmp_path):
    bad = _copy_with(fit, tmp_path, "loo.npz")
    size = _deflate_bomb(bad / "loo.npz")
    assert (bad / "loo.npz").stat().st_size < 4 << 20 and size > 2 << 30
    # a wrapper process, so that RUSAGE_CHILDREN holds compare's peak alone
    probe = ("import resource, subprocess, sys; "
             "p = subprocess.run(sys.argv[1:], capture_output=True, text=True); "
             "sys.stdout.write(str(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)); "
             "sys.stderr.write(p.stderr); sys.exit(p.returncode)")
    p = subprocess.run([sys.executable, "-c", probe, sys.executable, "-m", "reports",
                        "compare", bad, fit],
                       env=dict(ENV, MICROCYL_MEMORY_LIMIT="100M"), capture_output=True,
                       text=True, timeout=PATIENCE_S)
    err = refused(p, bad / "loo.npz", "elpd_i")
    peak_mib = int(p.stdout) / 1024                      # ru_maxrss: KiB on Linux
    assert peak_mib < 600, (peak_mib, err)               # the bomb inflated is 2048 MiB


def test_a_31mb_results_json_is_refused_by_export_quickly(fit, tmp_path):
    bad = _copy_with(fit, tmp_path, "results.json")
    text = (fit / "results.json").read_text()
    pad = '"padding": [' + ",".join(["0.123456789"] * 2_700_000) + "], "
    (bad / "results.json").write_text("{" + pad + text.lstrip()[1:])
    assert (bad / "results.json").stat().st_size > 31e6
    t0 = time.monotonic()
    err = refused(microcyl("export", bad, "-o", tmp_path / "x.json"), bad / "results.json")
    assert time.monotonic() - t0 < 20 and "MiB" in err, err
    assert not (tmp_path / "x.json").exists()


def test_a_deep_fit_config_given_to_compare_names_the_file(fit, tmp_path):
    bad = _copy_with(fit, tmp_path, "fit_config.json")
    (bad / "fit_config.json").write_text('{"config": ' * 100_000)
    err = refused(microcyl("compare", bad, fit), bad / "fit_config.json")
    assert "nested" in err, err
