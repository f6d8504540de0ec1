"""Faults, each in a subprocess as a user meets it: a render SIGKILLed mid-way leaves no
worker behind; two fits into one folder (the second refused, naming the first's pid); a
temporary file or folder a killed run left is removed by the next run."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

import brdf
import gonio
from analysis.folderlock import FolderBusy, output_lock
from gonio.atomic import make_temporary_folder
from _signals import default_sigint

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(REPO), PYTHONUNBUFFERED="1")


def _cli(*args, **kw):
    return subprocess.Popen([sys.executable, "-m", "reports", *map(str, args)], cwd=REPO,
                            preexec_fn=default_sigint,
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, **kw)


def _wait_for(cond, timeout=60.0, every=0.05):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(every)
    return False


def test_render_workers_exit_with_a_killed_parent(tmp_path):
    proc = _cli("render", "cylinder", "velvet", "--width", "320", "--height", "180", "--spp",
                "64", "--workers", "2", "--quiet", "-o", tmp_path / "r.exr")
    parent = psutil.Process(proc.pid)
    try:
        assert _wait_for(lambda: len(parent.children()) >= 2), "no workers started"
        workers = parent.children()
        time.sleep(0.5)
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
        gone, alive = psutil.wait_procs(workers, timeout=10)
        assert not alive, f"orphaned workers: {[p.pid for p in alive]}"
    finally:
        proc.kill()
        for p in psutil.Process().children(recursive=True):
            if p.pid != proc.pid and p.ppid() in (proc.pid, 1):
                p.kill()
    assert not (tmp_path / "r.exr").exists()


@pytest.fixture(scope="module")
def table_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("faults") / "silk.csv"
    table = gonio.measure(brdf.fabric("silk_crepe_de_chine"), "full:15:30",
                          gonio.Instrument(snr=20, floor=1e-4), seed=3, progress=False)
    gonio.write(table, path)
    return path


def test_a_second_fit_into_the_same_folder_is_refused(table_csv, tmp_path):
    out = tmp_path / "fit"
    args = ("fit", table_csv, "--fabric", "silk_crepe_de_chine", "--free", "kd1,gamma_s1",
            "--max-steps", "100000", "--no-plots", "--no-progress", "-o", out)
    first = _cli(*args)
    try:
        assert _wait_for(lambda: (out / ".microcyl.lock").exists()
                         and (out / ".microcyl.lock").read_text().strip())
        second = _cli(*args)
        _, err = second.communicate(timeout=60)
        assert second.returncode == 1
        assert err.strip() == (f"microcyl fit: error: another fit is running in {out} "
                               f"(pid {first.pid}); wait for it to end or use another output")
    finally:
        first.send_signal(signal.SIGINT)
        first.communicate(timeout=60)
    assert not (out / ".microcyl.lock").exists()     # released at the end


def test_a_lock_of_a_killed_process_is_taken_over(tmp_path):
    code = ("import os, signal, sys; from analysis.folderlock import output_lock\n"
            "with output_lock(sys.argv[1], 'fit'):\n"
            "    os.kill(os.getpid(), signal.SIGKILL)\n")
    subprocess.run([sys.executable, "-c", code, str(tmp_path)], env=ENV, cwd=REPO)
    assert (tmp_path / ".microcyl.lock").exists()    # left behind, its holder dead
    with output_lock(tmp_path, "fit"):
        assert (tmp_path / ".microcyl.lock").read_text() == f"{os.getpid()} fit\n"
        with pytest.raises(FolderBusy, match=f"another fit is running in {tmp_path} "
                                             rf"\(pid {os.getpid()}\)"):
            with output_lock(tmp_path, "fit"):
                pass


def test_a_lock_that_created_its_folder_removes_it_when_the_run_fails(tmp_path):
    """A run refused inside the lock (a fit whose start cannot be evaluated, a batch's bad
    job) leaves no new folder; one that wrote something, or an existing folder, stays."""
    new = tmp_path / "a" / "b"
    with pytest.raises(ValueError, match="refused"):
        with output_lock(new, "fit"):
            assert new.is_dir()
            raise ValueError("refused")
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(KeyboardInterrupt):
        with output_lock(new, "fit"):
            (new / "checkpoint.h5").write_text("steps done")
            raise KeyboardInterrupt
    assert sorted(p.name for p in new.iterdir()) == ["checkpoint.h5"]
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ValueError):
        with output_lock(empty, "fit"):
            raise ValueError("refused")
    assert empty.is_dir() and list(empty.iterdir()) == []
    with output_lock(tmp_path / "ok", "fit"):      # a run that ends well keeps its folder
        pass
    assert (tmp_path / "ok").is_dir()


def _killed_mid_write(path):
    """A process that dies (SIGKILL) inside gonio.atomic_write of ``path``."""
    code = ("import os, signal, sys; from gonio import atomic_write\n"
            "with atomic_write(sys.argv[1]) as f:\n"
            "    f.write(b'half'); f.flush(); os.kill(os.getpid(), signal.SIGKILL)\n")
    subprocess.run([sys.executable, "-c", code, str(path)], env=ENV, cwd=REPO)
    return [p for p in path.parent.iterdir() if p.name.startswith(f".microcyl-{path.name}.")
            and p.name.endswith(".tmp")]


def test_convert_removes_what_a_killed_convert_left(table_csv, tmp_path):
    out = tmp_path / "o.exr"
    stale = _killed_mid_write(out)
    assert stale and not out.exists()
    proc = _cli("convert", table_csv, out)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.exr"]


def test_a_fit_folder_and_a_report_folder_lose_their_stale_temporaries(tmp_path):
    fit_dir = tmp_path / "fit"
    fit_dir.mkdir()
    stale = _killed_mid_write(fit_dir / "checkpoint.h5")
    assert stale
    report_tmp = make_temporary_folder(tmp_path, "report")  # a killed build's
    (report_tmp / "index.html").write_text("half")
    with output_lock(fit_dir, "fit"):
        assert not any(p.exists() for p in stale)
    with output_lock(tmp_path / "report", "report"):
        assert not report_tmp.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fit", "report"]
    assert list(fit_dir.iterdir()) == [] and list((tmp_path / "report").iterdir()) == []


def test_a_second_report_into_the_same_folder_is_refused(tmp_path):
    """`microcyl report` twice into one -o folder at once: the second is refused, naming
    the first's pid; the first writes its report whole."""
    out = tmp_path / "rep"
    args = ("report", "--fabric", "velvet", "--quality", "fast", "-o", out)
    lock = out / ".microcyl.lock"
    first = _cli(*args)
    try:
        assert _wait_for(lambda: lock.exists() and lock.read_text().strip(), timeout=120)
        second = _cli(*args)
        _, err = second.communicate(timeout=120)
        assert second.returncode == 1
        assert err.strip().splitlines()[-1] == (
            f"microcyl report: error: another report is running in {out} (pid {first.pid}); "
            f"wait for it to end or use another output")
    finally:
        _, err = first.communicate(timeout=600)
    assert first.returncode == 0, err
    assert (out / "index.html").is_file() and not lock.exists()
